//! Angle and velocity quantisation (a scene's `angle_quantisation`,
//! `velocity_quantisation`) are IEEE 952's quantisation term: `triad allan`
//! recovers Q = S/√12 from a simulated record within 5 %. The output
//! register's rounding (`output_lsb`) is not: it is white rate noise.

mod common;

use std::path::{Path, PathBuf};

use common::{allan, dir, simulate_scene, text};

/// Simulates `scene` (a static bench at 100 Hz with the given `[gyro]` and
/// `[accel]` bodies) for 2^20 samples into `d`/`name`.csv.
fn simulate(d: &Path, name: &str, gyro: &str, accel: &str) -> PathBuf {
    let body = format!(
        "rate_hz = 100.0\n[motion]\nkind = \"static\"\nattitude_deg = [0.0, 0.0, 0.0]\n[gyro]\n{gyro}\n[accel]\n{accel}\n"
    );
    simulate_scene(d, name, &body, "10485.76", "3")
}

/// Q, its σ, whether the data support it, and its unit: `column` in `triad allan --json`.
fn fitted_q(input: &Path, column: &str) -> (f64, f64, bool, String) {
    let o = allan(input, &["--json", "--quiet", "--columns", column]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let q = &v["columns"][0]["terms"]["Q"];
    (
        q["value"].as_f64().unwrap(),
        q["sigma"].as_f64().unwrap(),
        q["significant"].as_bool().unwrap(),
        q["unit"].as_str().unwrap().to_string(),
    )
}

#[test]
fn allan_recovers_the_quantisation_term_within_five_percent() {
    // Steps S = 2 arcsec (gyro) and 1 mm/s (accel), white noise moving the
    // integral by one step (1σ) per sample: the counting error is then
    // uniform and white (its correlation from one sample to the next is
    // e^(−2π²) ≈ 3e-9), so the Allan variance holds 3Q²/τ² with Q = S/√12,
    // 20 % of σ² at τ = Ts. 2^20 samples: the fit's σ of Q is 0.8 %, so
    // 5 % is 6σ (measured: gx +0.6 %, az −0.9 %; 2 s in a debug build).
    let d = dir("q");
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    let step_gyro = 2.0 * arcsec;
    // ARW with σ_θ = S per 10 ms sample: N = S/√Ts, in °/√h.
    let arw = step_gyro / 0.1 * (180.0 / std::f64::consts::PI) * 60.0;
    let accel_noise_ug = 1e-3 / 0.1 / 9.806_65e-6;
    let input = simulate(
        &d,
        "q",
        &format!("white_noise = \"{arw} deg/sqrt(h)\"\nangle_quantisation = \"2 arcsec\""),
        &format!(
            "white_noise = \"{accel_noise_ug} ug/sqrt(Hz)\"\nvelocity_quantisation = \"1 mm/s\""
        ),
    );
    for (column, truth, unit) in [
        ("gx", step_gyro / 12f64.sqrt() * 1e6, "urad"),
        ("az", 1.0 / 12f64.sqrt(), "mm/s"),
    ] {
        let (q, sigma, significant, u) = fitted_q(&input, column);
        let deviation = q / truth - 1.0;
        println!(
            "{column}: Q {q:.4} ± {sigma:.4} {u}, S/√12 = {truth:.4} {u}: {:+.2} %",
            100.0 * deviation
        );
        assert_eq!(u, unit);
        assert!(significant, "{column}: Q not detected");
        assert!(deviation.abs() < 0.05, "{column}: Q {q} vs {truth}");
    }
}

#[test]
fn output_register_rounding_is_not_the_quantisation_term() {
    // The same noise rounded per sample to an LSB of the same size (as a
    // rate: S/Ts) is white rate noise: no Q is reported.
    let d = dir("lsb");
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    let lsb_dps = 2.0 * arcsec / 0.01 * 180.0 / std::f64::consts::PI;
    let arw = 2.0 * arcsec / 0.1 * (180.0 / std::f64::consts::PI) * 60.0;
    let input = simulate(
        &d,
        "lsb",
        &format!("white_noise = \"{arw} deg/sqrt(h)\"\noutput_lsb = \"{lsb_dps} deg/s\""),
        "",
    );
    let (q, _, significant, _) = fitted_q(&input, "gx");
    assert!(!significant, "output rounding reported as Q = {q} urad");
}
