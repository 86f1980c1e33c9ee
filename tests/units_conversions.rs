//! Unit conversions of the inertial-sensor nomenclature: round trips and the
//! textbook equivalences.

use triad::units::*;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(f64::MIN_POSITIVE)
}

#[test]
fn one_deg_per_s_per_sqrt_hz_is_60_deg_per_sqrt_h() {
    assert_eq!(deg_per_s_per_sqrt_hz_to_deg_per_sqrt_h(1.0), 60.0);
    assert_eq!(deg_per_sqrt_h_to_deg_per_s_per_sqrt_hz(60.0), 1.0);
    // In SI: 60 °/√h = 1 (°/s)/√Hz = π/180 (rad/s)/√Hz.
    assert!(close(
        arw_deg_per_sqrt_h_to_si(60.0),
        core::f64::consts::PI / 180.0,
        1e-15
    ));
}

#[test]
fn one_g_per_sqrt_hz_is_588_m_per_s_per_sqrt_h() {
    // 9.80665 × 60 = 588.399.
    let vrw = g_per_sqrt_hz_to_m_per_s_per_sqrt_h(1.0);
    assert!(close(vrw, 588.399, 1e-15), "{vrw}");
    assert!((vrw - 588.0).abs() < 0.5);
    assert!(close(m_per_s_per_sqrt_h_to_g_per_sqrt_hz(vrw), 1.0, 1e-15));
    // (m/s)/√h → (m/s²)/√Hz agrees with going through g.
    assert!(close(
        vrw_m_per_s_per_sqrt_h_to_si(vrw),
        STANDARD_GRAVITY,
        1e-15
    ));
}

#[test]
fn round_trips_are_exact_to_rounding() {
    for x in [1e-6, 0.003, 0.15, 1.0, 59.4, 1234.5] {
        assert!(close(
            arw_si_to_deg_per_sqrt_h(arw_deg_per_sqrt_h_to_si(x)),
            x,
            1e-14
        ));
        assert!(close(
            rrw_si_to_deg_per_h_per_sqrt_h(rrw_deg_per_h_per_sqrt_h_to_si(x)),
            x,
            1e-14
        ));
        assert!(close(
            rad_per_s_to_deg_per_h(deg_per_h_to_rad_per_s(x)),
            x,
            1e-14
        ));
        assert!(close(
            si_to_ug_per_sqrt_hz(ug_per_sqrt_hz_to_si(x)),
            x,
            1e-14
        ));
        assert!(close(mps2_to_ug(ug_to_mps2(x)), x, 1e-14));
        assert!(close(mps2_to_g(g_to_mps2(x)), x, 1e-14));
        assert!(close(ratio_to_ppm(ppm_to_ratio(x)), x, 1e-14));
        assert!(close(rad_to_deg(deg_to_rad(x)), x, 1e-14));
    }
}

#[test]
fn bias_and_random_walk_units() {
    // 1 °/h = 1/3600 °/s.
    assert!(close(
        deg_per_h_to_rad_per_s(3600.0),
        core::f64::consts::PI / 180.0,
        1e-15
    ));
    // 1 (°/h)/√h = (1/3600 °/s)/(60 √s) = 1/216000 (°/s)/√s.
    assert!(close(
        rrw_deg_per_h_per_sqrt_h_to_si(216_000.0),
        core::f64::consts::PI / 180.0,
        1e-15
    ));
    // 1 (m/s/h)/√h = 1/216000 (m/s²)/√s.
    assert!(close(
        accel_rw_m_per_s_per_h_per_sqrt_h_to_si(216_000.0),
        1.0,
        1e-15
    ));
    // 100 µg/√Hz = 9.80665e-4 (m/s²)/√Hz.
    assert!(close(ug_per_sqrt_hz_to_si(100.0), 9.80665e-4, 1e-15));
}

#[test]
fn resolution_from_density_and_bandwidth() {
    // σ = N·√B: 100 µg/√Hz over 100 Hz is 1 mg rms.
    assert!(close(resolution_from_density(100.0, 100.0), 1000.0, 1e-15));
    assert!(close(
        random_walk_sigma(0.99, 1000.0),
        0.99 * 1000f64.sqrt(),
        1e-15
    ));
}
