//! True motion: gravity and Earth rate at rest, the rate table, the tumble's
//! positions and transitions, vibration, temperature profiles.

// Index loops over matrix rows and columns read like the formulas they check.
#![allow(clippy::needless_range_loop)]

use triad::units::EARTH_RATE;
use triad_sim::motion::rotation;
use triad_sim::motion::{tumble_position, Axis, Environment, Motion, Trajectory};
use triad_sim::scenes::temperature_profile::TemperatureProfile;

const G: f64 = 9.80665;

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[test]
fn level_static_measures_g_up_and_earth_rate() {
    let lat = 0.8;
    let env = Environment {
        gravity: G,
        latitude: Some(lat),
    };
    let k = Trajectory::new(&Motion::Static { attitude: [0.0; 3] }, &env).at(123.0);
    assert_eq!(k.specific_force, [0.0, 0.0, G]);
    let w = k.angular_rate;
    assert!(w[0].abs() < 1e-20);
    assert!((w[1] - EARTH_RATE * lat.cos()).abs() < 1e-18);
    assert!((w[2] - EARTH_RATE * lat.sin()).abs() < 1e-18);
}

#[test]
fn tilted_static_keeps_the_magnitudes() {
    let env = Environment {
        gravity: 9.81,
        latitude: Some(-0.3),
    };
    let k = Trajectory::new(
        &Motion::Static {
            attitude: [0.4, -1.1, 2.0],
        },
        &env,
    )
    .at(0.0);
    assert!((norm(k.specific_force) - 9.81).abs() < 1e-12);
    assert!((norm(k.angular_rate) - EARTH_RATE).abs() < 1e-18);
    // Pitch θ alone: f = g·(−sin θ, 0, cos θ) in the body frame (z-y-x angles).
    let k = Trajectory::new(
        &Motion::Static {
            attitude: [0.0, 0.5, 0.0],
        },
        &Environment::default(),
    )
    .at(0.0);
    assert!((k.specific_force[0] + G * 0.5f64.sin()).abs() < 1e-12);
    assert!((k.specific_force[2] - G * 0.5f64.cos()).abs() < 1e-12);
}

#[test]
fn rate_table_turns_about_the_chosen_axis() {
    let rate = 0.7;
    let t = Trajectory::new(
        &Motion::RateTable {
            axis: Axis::MinusX,
            rate,
        },
        &Environment::default(),
    );
    for time in [0.0, 1.0, 17.3] {
        let k = t.at(time);
        assert!((k.specific_force[0] + G).abs() < 1e-12 && k.specific_force[1].abs() < 1e-12);
        assert!((k.angular_rate[0] + rate).abs() < 1e-15 && k.angular_rate[1] == 0.0);
    }
    // With the Earth rate, the table rate adds to it along the axis and the
    // horizontal Earth rate turns in the body frame.
    let env = Environment {
        gravity: G,
        latitude: Some(0.9),
    };
    let t = Trajectory::new(
        &Motion::RateTable {
            axis: Axis::PlusZ,
            rate,
        },
        &env,
    );
    let (a, b) = (t.at(0.0), t.at(2.0));
    assert!((a.angular_rate[2] - rate - EARTH_RATE * 0.9f64.sin()).abs() < 1e-15);
    let h = |w: [f64; 3]| (w[0] * w[0] + w[1] * w[1]).sqrt();
    assert!((h(a.angular_rate) - EARTH_RATE * 0.9f64.cos()).abs() < 1e-18);
    assert!((h(b.angular_rate) - h(a.angular_rate)).abs() < 1e-18);
    assert!((a.angular_rate[0] - b.angular_rate[0]).abs() > 1e-6 * EARTH_RATE);
}

#[test]
fn six_position_tumble_puts_each_axis_up_and_down_once() {
    let mut seen = Vec::new();
    let t = Trajectory::new(
        &Motion::Tumble {
            positions: 6,
            dwell: 10.0,
            transition: 2.0,
        },
        &Environment::default(),
    );
    for i in 0..6 {
        let k = t.at(12.0 * i as f64 + 5.0);
        assert_eq!(k.angular_rate, [0.0; 3], "at rest during the dwell");
        let f = k.specific_force;
        let axis = (0..3)
            .find(|&a| (f[a].abs() - G).abs() < 1e-12)
            .expect("one axis carries g");
        for b in 0..3 {
            if b != axis {
                assert!(f[b].abs() < 1e-12);
            }
        }
        seen.push((axis, f[axis] > 0.0));
    }
    seen.sort();
    assert_eq!(
        seen,
        vec![
            (0, false),
            (0, true),
            (1, false),
            (1, true),
            (2, false),
            (2, true)
        ]
    );
}

#[test]
fn tumble_transitions_end_at_the_next_position() {
    // Integrate the body rate through each transition (midpoint rule on the
    // rotation, 2000 steps) and compare the gravity direction at the end with
    // the next position's; and |f| stays g throughout.
    for n in [6u8, 12, 24] {
        let (dwell, transition) = (1.0, 2.0);
        let t = Trajectory::new(
            &Motion::Tumble {
                positions: n,
                dwell,
                transition,
            },
            &Environment::default(),
        );
        let leg = dwell + transition;
        for i in 0..n as usize {
            let start = leg * i as f64 + dwell;
            let mut r = tumble_position(i);
            let steps = 2000;
            let h = transition / steps as f64;
            for s in 0..steps {
                let k = t.at(start + (s as f64 + 0.5) * h);
                assert!((norm(k.specific_force) - G).abs() < 1e-9);
                let w = k.angular_rate;
                let angle = norm(w) * h;
                if angle > 0.0 {
                    r = rotation::mul(&r, &rotation::exp(&rotation::normalise(w), angle));
                }
            }
            let next = tumble_position((i + 1) % n as usize);
            let f_int = rotation::mul_transpose_vec(&r, &[0.0, 0.0, G]);
            let f_next = rotation::mul_transpose_vec(&next, &[0.0, 0.0, G]);
            for a in 0..3 {
                assert!(
                    (f_int[a] - f_next[a]).abs() < 1e-9,
                    "n = {n}, leg {i}: {f_int:?} vs {f_next:?}"
                );
            }
            let f_model = t.at(leg * (i + 1) as f64 - 1e-9).specific_force;
            for a in 0..3 {
                assert!((f_model[a] - f_next[a]).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn cube_rotations_are_24_distinct_proper_rotations() {
    let mut all = Vec::new();
    for i in 0..24 {
        let r = tumble_position(i);
        let rtr = rotation::transpose_mul(&r, &r);
        for a in 0..3 {
            for b in 0..3 {
                assert_eq!(rtr[a][b], if a == b { 1.0 } else { 0.0 });
            }
        }
        let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        assert_eq!(det, 1.0);
        all.push(r.map(|row| row.map(|x| x as i8)));
    }
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 24);
}

#[test]
fn log_inverts_exp_including_half_turns() {
    for i in 0..24 {
        for j in 0..24 {
            let m = rotation::transpose_mul(&tumble_position(i), &tumble_position(j));
            let (axis, angle) = rotation::log(&m);
            let back = rotation::exp(&axis, angle);
            for a in 0..3 {
                for b in 0..3 {
                    assert!(
                        (back[a][b] - m[a][b]).abs() < 1e-12,
                        "{i}→{j}: angle {angle}"
                    );
                }
            }
        }
    }
}

#[test]
fn vibration_shakes_along_the_direction() {
    let t = Trajectory::new(
        &Motion::Vibration {
            attitude: [0.0; 3],
            direction: [0.0, 3.0, 4.0],
            amplitude: 2.0,
            frequency: 5.0,
        },
        &Environment::default(),
    );
    // At a quarter period the shake is at its peak: 2·(0, 0.6, 0.8).
    let k = t.at(0.05);
    assert!(k.specific_force[0].abs() < 1e-12);
    assert!((k.specific_force[1] - 1.2).abs() < 1e-12);
    assert!((k.specific_force[2] - G - 1.6).abs() < 1e-12);
    assert_eq!(t.at(0.0).specific_force, [0.0, 0.0, G]);
}

#[test]
fn temperature_ramp_holds_ramps_and_holds() {
    let p = TemperatureProfile::Ramp {
        from: -10.0,
        to: 50.0,
        start: 100.0,
        duration: 600.0,
    };
    assert_eq!(p.at(0.0), -10.0);
    assert_eq!(p.at(100.0), -10.0);
    assert_eq!(p.at(400.0), 20.0);
    assert_eq!(p.at(700.0), 50.0);
    assert_eq!(p.at(1e6), 50.0);
    assert_eq!(TemperatureProfile::Constant(21.5).at(5.0), 21.5);
}
