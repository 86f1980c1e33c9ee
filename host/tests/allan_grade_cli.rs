//! `triad allan`'s grade end to end, by THEORY.md's tables: a simulated
//! sensor in a gap of a table is "between" two grades with the parameter
//! that decides it, and parameters given with `--grade-input` are graded
//! with the fitted ones.

mod common;

use std::path::{Path, PathBuf};

use common::{allan, dir, simulate_scene, text};

/// Simulates `[gyro]` `effects` on a static bench at `rate` Hz for
/// `seconds` into `d`/`name`.csv (the scene written beside it).
fn simulate(d: &Path, name: &str, gyro: &str, rate: f64, seconds: u64) -> PathBuf {
    let body = format!(
        "rate_hz = {rate:?}\n[motion]\nkind = \"static\"\nattitude_deg = [0.0, 0.0, 0.0]\n[gyro]\n{gyro}\n"
    );
    simulate_scene(d, name, &body, &seconds.to_string(), "5")
}

/// The JSON report of `triad allan` on column gx of `input` with `extra` arguments.
fn report(input: &Path, extra: &[&str]) -> serde_json::Value {
    let o = allan(
        input,
        &[&["--json", "--columns", "gx", "--quiet"], extra].concat(),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn a_gyro_in_the_tables_gap_is_between_two_grades() {
    // ARW 0.01 °/√h (aviation: < 0.05) and bias instability 0.5 °/h: the
    // gap between tactical (1–10 °/h) and aviation (< 0.1 °/h). 4.5 h at
    // 4 Hz: the floor leads from τ ≈ 3 s and is fitted to a few %.
    let d = dir("gap");
    let input = simulate(
        &d,
        "gap",
        "white_noise = \"0.01 deg/sqrt(h)\"\n[gyro.bias_instability]\nvalue = \"0.5 deg/h\"",
        4.0,
        1 << 14,
    );
    let v = report(&input, &[]);
    let g = &v["columns"][0]["grade"];
    assert_eq!(g["grade"], "between tactical and aviation", "{g}");
    assert_eq!(g["between"], serde_json::json!(["tactical", "aviation"]));
    assert_eq!(g["decided_by"], "bias instability");
    assert_eq!(g["table"], "gyro");
    let params = g["parameters"].as_array().unwrap();
    assert_eq!(params[0]["parameter"], "white noise");
    assert_eq!(params[0]["grade"], "aviation");
    assert_eq!(
        params[1]["verdict"],
        "between tactical (1–10) and aviation (< 0.1)"
    );
    let b = params[1]["value"].as_f64().unwrap();
    assert!((b - 0.5).abs() < 0.1, "B {b} deg/h");
    // The summary says the same.
    let o = allan(&input, &["--columns", "gx", "--quiet"]);
    let summary = text(&o.stdout);
    assert!(
        summary.contains("grade: between tactical and aviation (decided by bias instability)"),
        "{summary}"
    );
}

#[test]
fn given_parameters_are_graded_with_the_fitted_ones() {
    // A tactical gyro (ARW 0.15 °/√h, B 3 °/h) given a scale-factor
    // instability of 0.5 % (rate grade: 0.1–1 %) and a range of 2000 °/s:
    // the scale factor decides; the range fits tactical (> 500) and
    // navigation (> 400), not rate grade (50–1000), and ranks nothing.
    let d = dir("given");
    let input = simulate(&d, "tactical", "grade = \"tactical\"", 4.0, 1 << 14);
    let v = report(
        &input,
        &[
            "--grade-input",
            "gyro.scale-factor-instability=0.5",
            "--grade-input",
            "gyro.range=2000",
            "--grade-input",
            "accel.range=16",
        ],
    );
    let g = &v["columns"][0]["grade"];
    assert_eq!(g["grade"], "rate grade", "{g}");
    assert_eq!(g["decided_by"], "scale-factor instability");
    let params = g["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 4, "the accel input is not a gyro's: {g}");
    assert_eq!(params[3]["parameter"], "measurement range");
    assert_eq!(
        params[3]["fits"],
        serde_json::json!(["tactical", "navigation"])
    );
    assert!(params[3]["grade"].is_null());
    // Twice the same parameter is refused before the file is read.
    let o = allan(
        &input,
        &[
            "--grade-input",
            "gyro.range=1",
            "--grade-input",
            "gyro.range=2",
        ],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o.stderr).contains("gives the gyro measurement range twice"));
    let o = allan(&input, &["--grade-input", "gyro.range=fast"]);
    assert_eq!(o.status.code(), Some(2), "clap refuses it");
    assert!(text(&o.stderr).contains("\"fast\" is not a number"));
}

#[test]
fn each_optical_preset_is_classified_as_its_own_grade() {
    // THEORY.md's grade/technology pairs: tactical FOG, aviation RLG and
    // FOG, navigation RLG; 36 h at 1 Hz (the navigation RLG's bias
    // instability leads only from τ ≈ 1000 s, its white noise between its
    // fringe quantisation and that floor). Each axis in its own grade by
    // white noise and bias instability; a ring laser's Q is its fringe
    // angle over √12 (the fit's 3σ: it is measured to 0.2–0.3 %).
    use triad_sim::grade::{Grade, GyroPreset, Optics};
    let d = dir("optical");
    for p in GyroPreset::ALL.iter().filter(|p| p.optics.is_some()) {
        let input = simulate(&d, p.name, &format!("grade = \"{}\"", p.name), 1.0, 1 << 17);
        let o = allan(&input, &["--json", "--quiet", "--columns", "gx,gy,gz"]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for c in v["columns"].as_array().unwrap() {
            let g = &c["grade"];
            assert_eq!(
                g["grade"],
                p.grade.name(),
                "{} {}: {g}",
                p.name,
                c["column"]
            );
            assert_eq!(
                g["decided_by"], "white noise and bias instability",
                "{}",
                p.name
            );
            if let Some(Optics::RingLaser(r)) = p.optics {
                let q = &c["terms"]["Q"];
                let (value, sigma) = (q["si"].as_f64().unwrap(), q["si_sigma"].as_f64().unwrap());
                let truth = r.quantisation();
                println!(
                    "{} {}: Q {value:.4e} ± {sigma:.1e} rad, fringe/√12 {truth:.4e} ({:+.2} σ)",
                    p.name,
                    c["column"],
                    (value - truth) / sigma
                );
                assert!(
                    (value - truth).abs() <= 3.0 * sigma,
                    "{}: Q {value} vs {truth}",
                    p.name
                );
            }
        }
    }
}
