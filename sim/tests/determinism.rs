//! Determinism and independence of effects: every effect off gives the truth
//! exactly; toggling one effect leaves every other effect's contribution
//! bit-identical; the same seed gives the same samples.

use triad_sim::chips::source::SampleSource;
use triad_sim::effects::bias_instability::BiasInstabilityParams;
use triad_sim::effects::temperature_dependence::TemperatureDependence;
use triad_sim::motion::{Axis, Environment, Motion};
use triad_sim::optics::fibre_optic::{FibreOpticParams, Loop};
use triad_sim::optics::ring_laser::{Dither, RingLaserParams};
use triad_sim::scenes::scene::{GaussMarkovParams, Scene, TriadEffects};
use triad_sim::scenes::simulator::{Contributions, Simulator};
use triad_sim::scenes::temperature_profile::TemperatureProfile;

fn motions() -> [Motion; 4] {
    [
        Motion::Static {
            attitude: [0.1, -0.2, 0.3],
        },
        Motion::RateTable {
            axis: Axis::MinusY,
            rate: 0.5,
        },
        Motion::Tumble {
            positions: 24,
            dwell: 0.05,
            transition: 0.05,
        },
        Motion::Vibration {
            attitude: [0.0; 3],
            direction: [1.0, 1.0, 0.0],
            amplitude: 3.0,
            frequency: 7.0,
        },
    ]
}

fn every_effect(gyro: bool) -> TriadEffects {
    TriadEffects {
        white_noise: Some([0.01, 0.02, 0.03]),
        gauss_markov: Some(GaussMarkovParams {
            sigma: [0.01; 3],
            correlation_time: [10.0, 20.0, 30.0],
        }),
        random_walk: Some([0.001; 3]),
        bias_instability: Some([BiasInstabilityParams::with_default_band(0.002); 3]),
        constant_bias: Some([0.1, -0.2, 0.3]),
        turn_on_bias: Some([0.05; 3]),
        scale_misalignment: Some([[1e-3, 2e-4, -1e-4], [3e-4, -2e-3, 1e-4], [0.0, 5e-4, 5e-4]]),
        turn_on_scale: Some([1e-3; 3]),
        temperature: Some(TemperatureDependence {
            reference: 25.0,
            bias_per_degree: [1e-3; 3],
            scale_per_degree: [1e-5; 3],
        }),
        g_sensitivity: gyro.then_some([[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]),
        ring_laser: None,
        fibre_optic: gyro.then_some(FibreOpticParams {
            turns: 1000.0,
            coil_area: 3e-3,
            wavelength: 1550e-9,
            readout: Loop::Open,
            reference: 25.0,
            area_per_degree: 1e-6,
            wavelength_per_degree: 1e-5,
        }),
        increment_quantisation: Some([2e-3; 3]),
        output_lsb: Some([1e-3; 3]),
        saturation: Some([if gyro { 10.0 } else { 5.0 }; 3]),
    }
}

fn scene(motion: Motion) -> Scene {
    Scene {
        rate_hz: 200.0,
        motion,
        environment: Environment {
            gravity: 9.81,
            latitude: Some(0.9),
        },
        temperature: TemperatureProfile::Ramp {
            from: 10.0,
            to: 40.0,
            start: 1.0,
            duration: 3.0,
        },
        accel: TriadEffects::NONE,
        gyro: TriadEffects::NONE,
    }
}

#[test]
fn every_effect_off_measures_the_truth_exactly() {
    for motion in motions() {
        let mut sim = Simulator::new(&scene(motion), 1).unwrap();
        for _ in 0..2000 {
            let s = sim.step();
            assert_eq!(s.measured, s.truth, "{motion:?} at t = {}", s.t);
        }
    }
}

/// How many effects [`without`] turns off, one by one.
const EFFECTS: usize = 14;

/// Turns off one effect (by index) of a full effect set.
fn without(mut e: TriadEffects, which: usize) -> TriadEffects {
    match which {
        0 => e.white_noise = None,
        1 => e.gauss_markov = None,
        2 => e.random_walk = None,
        3 => e.bias_instability = None,
        4 => e.constant_bias = None,
        5 => e.turn_on_bias = None,
        6 => e.scale_misalignment = None,
        7 => e.turn_on_scale = None,
        8 => e.temperature = None,
        9 => e.g_sensitivity = None,
        10 => e.output_lsb = None,
        11 => e.increment_quantisation = None,
        12 => e.fibre_optic = None,
        _ => e.saturation = None,
    }
    e
}

/// The contributions of the effects still on, with those of `which` zeroed.
fn mask(c: &Contributions, which: usize) -> Contributions {
    let mut c = *c;
    match which {
        0 => c.white_noise = [0.0; 3],
        1 => c.gauss_markov = [0.0; 3],
        2 => c.random_walk = [0.0; 3],
        3 => c.bias_instability = [0.0; 3],
        5 => c.turn_on_bias = [0.0; 3],
        7 => c.turn_on_scale = [0.0; 3],
        _ => {}
    }
    c
}

#[test]
fn toggling_one_effect_leaves_the_others_bit_identical() {
    let mut full = scene(motions()[2]);
    full.accel = every_effect(false);
    full.gyro = every_effect(true);
    for which in 0..EFFECTS {
        let mut reduced = full;
        reduced.accel = without(full.accel, which);
        reduced.gyro = without(full.gyro, which);
        let mut a = Simulator::new(&full, 99).unwrap();
        let mut b = Simulator::new(&reduced, 99).unwrap();
        for _ in 0..3000 {
            let sa = a.step();
            let sb = b.step();
            assert_eq!(sa.truth, sb.truth);
            // Bit-identical: compare as bits, not with a tolerance.
            let bits = |c: &Contributions| {
                [
                    c.white_noise,
                    c.gauss_markov,
                    c.random_walk,
                    c.bias_instability,
                    c.turn_on_bias,
                    c.turn_on_scale,
                ]
                .map(|v| v.map(f64::to_bits))
            };
            assert_eq!(
                bits(&mask(a.accel_contributions(), which)),
                bits(b.accel_contributions()),
                "accel, effect {which} off"
            );
            assert_eq!(
                bits(&mask(a.gyro_contributions(), which)),
                bits(b.gyro_contributions()),
                "gyro, effect {which} off"
            );
        }
    }
}

#[test]
fn the_toggled_effect_does_change_the_output() {
    // The other side of the independence test: each effect, when on, does
    // something (so the test above is not passing on effects that are inert).
    let mut full = scene(motions()[2]);
    full.accel = every_effect(false);
    full.gyro = every_effect(true);
    for which in 0..EFFECTS {
        let mut reduced = full;
        reduced.accel = without(full.accel, which);
        reduced.gyro = without(full.gyro, which);
        let mut a = Simulator::new(&full, 5).unwrap();
        let mut b = Simulator::new(&reduced, 5).unwrap();
        let differs = (0..3000).any(|_| a.step().measured != b.step().measured);
        assert!(differs, "effect {which} has no effect");
    }
}

#[test]
fn a_ring_laser_leaves_the_other_effects_bit_identical() {
    // Its dither draws from its own stream: naming it changes the output,
    // not another effect's contribution. (It replaces the fibre-optic
    // optics and the angle quantisation of the full set: one optics, and
    // it counts its fringes itself.)
    let mut gyro = every_effect(true);
    gyro.fibre_optic = None;
    gyro.increment_quantisation = None;
    let mut with = scene(motions()[2]);
    with.gyro = TriadEffects {
        ring_laser: Some(RingLaserParams {
            area: 1.5e-3,
            path_length: 0.18,
            wavelength: 632.8e-9,
            lock_in: 1e-3,
            dither: Some(Dither {
                peak_rate: 1.7,
                frequency: 400.0,
            }),
        }),
        ..gyro
    };
    let mut without = with;
    without.gyro.ring_laser = None;
    let mut a = Simulator::new(&with, 8).unwrap();
    let mut b = Simulator::new(&without, 8).unwrap();
    let mut differs = false;
    for _ in 0..3000 {
        let (sa, sb) = (a.step(), b.step());
        differs |= sa.measured != sb.measured;
        assert_eq!(a.gyro_contributions(), b.gyro_contributions());
    }
    assert!(differs, "the ring laser changed nothing");
}

#[test]
fn same_seed_same_samples_other_seed_other_samples() {
    let mut s = scene(motions()[0]);
    s.accel = every_effect(false);
    s.gyro = every_effect(true);
    let mut a = Simulator::new(&s, 42).unwrap();
    let mut b = Simulator::new(&s, 42).unwrap();
    let mut c = Simulator::new(&s, 43).unwrap();
    let mut differ = false;
    for _ in 0..1000 {
        let (sa, sb, sc) = (a.step(), b.step(), c.step());
        assert_eq!(
            sa.measured.specific_force.map(f64::to_bits),
            sb.measured.specific_force.map(f64::to_bits)
        );
        assert_eq!(
            sa.measured.angular_rate.map(f64::to_bits),
            sb.measured.angular_rate.map(f64::to_bits)
        );
        differ |= sa.measured != sc.measured;
    }
    assert!(differ);
}

#[test]
fn sample_source_serves_measured_and_truth_source_serves_truth() {
    let mut s = scene(motions()[1]);
    s.gyro = every_effect(true);
    let mut reference = Simulator::new(&s, 8).unwrap();
    let mut measured = Simulator::new(&s, 8).unwrap();
    let mut truth = Simulator::new(&s, 8).unwrap().into_truth_source();
    for _ in 0..500 {
        let r = reference.step();
        assert_eq!(measured.next_sample(), r.measured);
        assert_eq!(truth.next_sample(), r.truth);
    }
}

#[test]
fn time_is_index_times_period_without_drift() {
    // t = k·Ts exactly (a product, not a running sum): after 10⁶ samples at
    // 1 kHz the time is 999.999 s to the last bit of the product.
    let mut sim = Simulator::new(&scene(motions()[0]), 0).unwrap();
    let ts = sim.sample_period();
    let mut last = 0.0;
    for _ in 0..1_000_000 {
        last = sim.step_truth().t;
    }
    assert_eq!(last, 999_999.0 * ts);
}
