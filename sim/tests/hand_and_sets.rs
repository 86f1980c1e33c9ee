//! The motions and profile of simulated units' scripts: hand rotations
//! (static poses in random orientations, smooth turns about arbitrary axes
//! that end at the next pose), the six-run rate-table set, soaks; and a
//! unit's turn-on errors held across records.

use triad::model::Triad;
use triad_sim::effects::turn_on::fix_turn_on;
use triad_sim::motion::hand_poses::{hand_poses, MIN_SEPARATION};
use triad_sim::motion::rotation;
use triad_sim::motion::{Environment, Motion, Trajectory, RATE_TABLE_SET_AXES};
use triad_sim::scenes::scene::{Scene, TriadEffects};
use triad_sim::scenes::simulator::Simulator;
use triad_sim::scenes::temperature_profile::TemperatureProfile;

const G: f64 = 9.80665;

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn angle_between(a: [f64; 3], b: [f64; 3]) -> f64 {
    let c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (norm(a) * norm(b));
    c.clamp(-1.0, 1.0).acos()
}

/// The shipped script's hand motion (scenes/scripts/hand-rotations.toml).
const HAND: Motion = Motion::Hand {
    poses: 24,
    seed: 1,
    dwell: 5.0,
    turn: 2.0,
};

#[test]
fn hand_poses_are_still_for_their_dwell_and_point_gravity_apart() {
    for seed in 1..20u64 {
        let motion = Motion::Hand {
            poses: 24,
            seed,
            dwell: 5.0,
            turn: 2.0,
        };
        let t = Trajectory::new(&motion, &Environment::default());
        let mut directions: Vec<[f64; 3]> = Vec::new();
        for i in 0..24 {
            let start = 7.0 * i as f64;
            let first = t.at(start);
            // Every 10 ms of the dwell: no rotation, the same specific force.
            for k in 0..500 {
                let s = t.at(start + k as f64 * 0.01);
                assert_eq!(s.angular_rate, [0.0; 3], "seed {seed} pose {i}");
                assert_eq!(s.specific_force, first.specific_force);
            }
            assert!((norm(first.specific_force) - G).abs() < 1e-9);
            directions.push(first.specific_force);
        }
        let mut nearest = f64::INFINITY;
        for (i, a) in directions.iter().enumerate() {
            for b in &directions[..i] {
                nearest = nearest.min(angle_between(*a, *b));
            }
        }
        // Gravity is kept 20° from every earlier pose's whenever one of 64
        // draws allows; 24 distinct directions at least 10° apart either way.
        assert!(nearest > MIN_SEPARATION / 2.0, "seed {seed}: {nearest}");
    }
}

#[test]
fn hand_turns_are_smooth_about_arbitrary_axes_and_end_at_the_next_pose() {
    let t = Trajectory::new(&HAND, &Environment::default());
    let poses = hand_poses(1, 24);
    let mut axes: Vec<[f64; 3]> = Vec::new();
    for i in 0..24 {
        let start = 7.0 * i as f64 + 5.0;
        // The rate is zero at both ends of the turn, and the integrated
        // rotation (midpoint rule, 4000 steps) lands on the next pose.
        let near_ends = [t.at(start + 1e-6), t.at(start + 2.0 - 1e-6)];
        for k in near_ends {
            assert!(norm(k.angular_rate) < 1e-9, "pose {i}");
        }
        let mid = t.at(start + 1.0).angular_rate;
        axes.push(rotation::normalise(mid));
        let mut r = poses[i];
        let steps = 4000;
        let h = 2.0 / steps as f64;
        for s in 0..steps {
            let w = t.at(start + (s as f64 + 0.5) * h).angular_rate;
            if norm(w) > 0.0 {
                r = rotation::mul(&r, &rotation::exp(&rotation::normalise(w), norm(w) * h));
            }
        }
        let next = poses[(i + 1) % 24];
        for a in 0..3 {
            for b in 0..3 {
                assert!((r[a][b] - next[a][b]).abs() < 1e-6, "turn {i}");
            }
        }
        // Peak rate 2·angle/turn ≤ π rad/s.
        assert!(norm(mid) <= std::f64::consts::PI + 1e-12);
    }
    // Not about the body axes only: most turn axes are oblique.
    let oblique = axes
        .iter()
        .filter(|a| a.iter().all(|c| c.abs() < 0.95))
        .count();
    assert!(oblique >= 12, "{oblique} of 24 turn axes oblique");
}

#[test]
fn the_rate_table_set_turns_each_axis_up_both_ways() {
    let rate = 30f64.to_radians();
    let t = Trajectory::new(
        &Motion::RateTableSet {
            rate,
            run: 60.0,
            rest: 10.0,
        },
        &Environment::default(),
    );
    for (k, axis) in RATE_TABLE_SET_AXES.iter().enumerate() {
        let (a, s) = axis.index_sign();
        let start = 70.0 * k as f64;
        let rest = t.at(start + 5.0);
        assert_eq!(rest.angular_rate, [0.0; 3]);
        assert!(
            (rest.specific_force[a] - s * G).abs() < 1e-12,
            "run {k} at rest"
        );
        for u in [10.0, 30.0, 69.9] {
            let run = t.at(start + u);
            let mut expected = [0.0; 3];
            expected[a] = s * rate;
            assert_eq!(run.angular_rate, expected, "run {k} at {u} s");
            assert!((run.specific_force[a] - s * G).abs() < 1e-9);
        }
    }
}

#[test]
fn soaks_hold_each_level_in_turn() {
    let p = TemperatureProfile::Soak {
        levels: [-10.0, 25.0, 60.0, 0.0],
        count: 3,
        hold: 300.0,
    };
    assert_eq!(
        [0.0, 299.9, 300.0, 599.0, 600.0, 1e6].map(|t| p.at(t)),
        [-10.0, -10.0, 25.0, 25.0, 60.0, 60.0]
    );
}

/// A unit with every turn-on error: fixed from one seed, records of it
/// differ in their noise only.
#[test]
fn fixed_turn_on_errors_are_the_units_and_the_noise_the_records() {
    let effects = TriadEffects {
        white_noise: Some([1e-3; 3]),
        turn_on_bias: Some([1e-2; 3]),
        turn_on_scale: Some([1e-3; 3]),
        ..TriadEffects::NONE
    };
    let unit = |seed| fix_turn_on(&effects, Triad::Gyro, Some(1e-3), seed);
    let (a, b) = (unit(1), unit(2));
    assert_eq!(a, unit(1));
    assert_ne!(a.constant_bias, b.constant_bias);
    assert_ne!(a.scale_misalignment, b.scale_misalignment);
    // The turn-on bias and scale are the ones a scene run with that seed draws.
    let scene = |gyro| Scene {
        gyro,
        ..Scene::new(100.0, Motion::Static { attitude: [0.0; 3] })
    };
    let no_noise = TriadEffects {
        white_noise: None,
        ..effects
    };
    let drawn = Simulator::new(&scene(no_noise), 1).unwrap().step().measured;
    let fixed = fix_turn_on(&no_noise, Triad::Gyro, None, 1);
    let held = Simulator::new(&scene(fixed), 99).unwrap().step().measured;
    assert_eq!(drawn, held);
    // Two records of unit a: the same errors, other noise.
    let r1 = Simulator::new(&scene(a), 10).unwrap().step().measured;
    let r2 = Simulator::new(&scene(a), 11).unwrap().step().measured;
    assert_ne!(r1.angular_rate, r2.angular_rate);
}
