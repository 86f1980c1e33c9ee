//! The fibre-optic gyro: its Sagnac phase from the coil, the open loop's
//! sin(ΔΦ) against a rate sweep (most sensitive at zero, ambiguous beyond
//! ±π/2), the closed loop's linear response, and the scale factor's
//! temperature dependence, alone and through the simulator.

use triad_sim::motion::{Axis, Motion};
use triad_sim::optics::fibre_optic::{FibreOpticParams, Loop, SPEED_OF_LIGHT};
use triad_sim::scenes::scene::{Scene, TriadEffects};
use triad_sim::scenes::simulator::Simulator;
use triad_sim::scenes::temperature_profile::TemperatureProfile;

/// `length` m of fibre on a coil of diameter `diameter` m at 1550 nm.
fn coil(length: f64, diameter: f64, readout: Loop) -> FibreOpticParams {
    FibreOpticParams {
        turns: length / (std::f64::consts::PI * diameter),
        coil_area: std::f64::consts::PI * diameter * diameter / 4.0,
        wavelength: 1550e-9,
        readout,
        reference: 25.0,
        area_per_degree: 1e-6,
        wavelength_per_degree: 10e-6,
    }
}

#[test]
fn the_sagnac_phase_is_8_pi_n_a_omega_over_lambda_c() {
    // THEORY.md's two forms: 8πNAω/(λc) = 4πRLω/(λc), L = 2πRN the fibre's length.
    let (length, diameter) = (1000.0, 0.1);
    let p = coil(length, diameter, Loop::Closed);
    let r = diameter / 2.0;
    let other = 4.0 * std::f64::consts::PI * r * length / (p.wavelength * SPEED_OF_LIGHT);
    assert!((p.phase_per_rate() / other - 1.0).abs() < 1e-12);
    // 1 km on 10 cm at 1550 nm: 1.35 rad per rad/s; π/2 at 66.6 °/s.
    assert!(
        (p.phase_per_rate() - 1.3512).abs() < 1e-3,
        "{}",
        p.phase_per_rate()
    );
    assert!((p.open_loop_limit().to_degrees() - 66.6).abs() < 0.1);
    assert_eq!(p.phase(1.0, 25.0), p.phase_per_rate());
}

#[test]
fn the_open_loop_response_is_sin_of_the_phase() {
    // A sweep to twice the ±π/2 limit: the output times S₀ is sin(S₀·ω).
    let p = coil(200.0, 0.06, Loop::Open);
    let s0 = p.phase_per_rate();
    let limit = p.open_loop_limit();
    let mut last: Option<f64> = None;
    for i in -200..=200 {
        let rate = 2.0 * limit * i as f64 / 100.0;
        let out = p.output(rate, 25.0);
        assert!((out * s0 - (s0 * rate).sin()).abs() < 1e-12, "ω {rate}");
        // Rising (one rate per output) inside ±π/2.
        if rate.abs() <= limit {
            assert!(last.is_none_or(|l| out > l), "ω {rate}: not rising");
            last = Some(out);
        }
    }
    // Most sensitive at zero: the slope is 1 there and falls with the phase.
    let slope = |w: f64| (p.output(w + 1e-7, 25.0) - p.output(w - 1e-7, 25.0)) / 2e-7;
    assert!((slope(0.0) - 1.0).abs() < 1e-6);
    assert!(slope(0.5 * limit) < slope(0.0) && slope(0.9 * limit) < slope(0.5 * limit));
    // Ambiguous beyond π/2: ω and π/S₀ − ω give one output.
    let w = 0.6 * limit;
    let mirror = std::f64::consts::PI / s0 - w;
    assert!(mirror > limit);
    assert!((p.output(w, 25.0) - p.output(mirror, 25.0)).abs() < 1e-12);
}

#[test]
fn the_closed_loop_is_linear_and_its_scale_follows_temperature() {
    let p = coil(1000.0, 0.1, Loop::Closed);
    for rate in [-3.0, -0.1, 0.0, 1e-6, 2.0] {
        assert!((p.output(rate, 25.0) - rate).abs() <= 1e-15 * rate.abs());
    }
    // +1 ppm/°C of area, +10 ppm/°C of wavelength: about −9 ppm/°C.
    let ratio = p.output(1.0, 35.0);
    assert!((ratio - (1.0 + 10e-6) / (1.0 + 100e-6)).abs() < 1e-15);
    assert!((ratio - 1.0 + 90e-6).abs() < 1e-8, "{ratio}");
}

#[test]
fn the_simulator_reads_a_rate_table_through_the_closed_loop() {
    // 30 °/s about +z while the temperature ramps 25 → 45 °C: the measured
    // rate is the true one times S(T)/S₀ at every sample.
    let mut scene = Scene::new(
        100.0,
        Motion::RateTable {
            axis: Axis::PlusZ,
            rate: 30f64.to_radians(),
        },
    );
    scene.temperature = TemperatureProfile::Ramp {
        from: 25.0,
        to: 45.0,
        start: 0.0,
        duration: 10.0,
    };
    let p = coil(1000.0, 0.1, Loop::Closed);
    scene.gyro = TriadEffects {
        fibre_optic: Some(p),
        ..TriadEffects::NONE
    };
    let mut sim = Simulator::new(&scene, 1).unwrap();
    for _ in 0..1000 {
        let s = sim.step();
        let (m, t) = (s.measured.angular_rate[2], s.truth.angular_rate[2]);
        let expected = t * p.scale_ratio(s.truth.temperature);
        assert!(
            (m - expected).abs() <= 1e-15 * t.abs(),
            "t {}: {m} vs {expected}",
            s.t
        );
    }
}
