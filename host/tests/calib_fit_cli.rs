//! `triad calib fit`: simulated records with known (I+Σ) and b → fit →
//! the estimates within 3σ of the truth, the written file passes `triad
//! calib check`, and `triad correct` with it brings |f| to g (accel) and the
//! gyro output to the table rate within the noise. And each refusal.
#![allow(clippy::needless_range_loop)] // index form reads as the matrix formulas

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{calibration, dir, s, text, triad};
use triad::model::matrix;
use triad_lab::calib_fit::numerics::small3::{cholesky_upper, gram};

const G: f64 = 9.80665;

/// The accelerometer errors of tumble-6 (a consumer MEMS part): truth below.
const ACCEL_ERRORS: &str = r#"
white_noise = "70 ug/sqrt(Hz)"
bias = ["20 mg", "-15 mg", "30 mg"]
scale_factor = ["5000 ppm", "-3000 ppm", "2000 ppm"]
misalignment = [["0", "2 mrad", "-1 mrad"], ["1 mrad", "0", "3 mrad"], ["-2 mrad", "1 mrad", "0"]]
"#;
const MG: f64 = G * 1e-3;
const ACCEL_M: [[f64; 3]; 3] = [
    [1.005, 0.002, -0.001],
    [0.001, 0.997, 0.003],
    [-0.002, 0.001, 1.002],
];
const ACCEL_B: [f64; 3] = [20.0 * MG, -15.0 * MG, 30.0 * MG];
/// Per-sample σ of the white noise: 70 µg/√Hz · √(100 Hz) (σ_d = σ_n/√Ts).
const ACCEL_SIGMA: f64 = 70e-6 * G * 10.0;

/// Static records at `attitudes` (roll, pitch in degrees), 10 s at 100 Hz each.
fn static_records(d: &Path, attitudes: &[(f64, f64)]) -> Vec<PathBuf> {
    attitudes
        .iter()
        .enumerate()
        .map(|(i, (roll, pitch))| {
            let scene = d.join(format!("static-{i}.toml"));
            std::fs::write(
                &scene,
                format!(
                    "rate_hz = 100.0\nduration_s = 10.0\n[motion]\nkind = \"static\"\n\
                     attitude_deg = [{roll:.1}, {pitch:.1}, 0.0]\n[accel]\n{ACCEL_ERRORS}"
                ),
            )
            .unwrap();
            let out = d.join(format!("static-{i}.csv"));
            let seed = (i + 1).to_string();
            let run = triad(&[
                "sim",
                "--scene",
                s(&scene),
                "--seed",
                &seed,
                "--out",
                s(&out),
            ]);
            assert!(run.status.success(), "{}", text(&run.stderr));
            out
        })
        .collect()
}

/// 20 attitudes: the six faces, the twelve cube edges' midpoints (45°), and two more.
const SPREAD: [(f64, f64); 20] = [
    (0.0, 0.0),
    (180.0, 0.0),
    (90.0, 0.0),
    (-90.0, 0.0),
    (0.0, 90.0),
    (0.0, -90.0),
    (45.0, 0.0),
    (-45.0, 0.0),
    (135.0, 0.0),
    (-135.0, 0.0),
    (0.0, 45.0),
    (0.0, -45.0),
    (45.0, 45.0),
    (45.0, -45.0),
    (-45.0, 45.0),
    (-45.0, -45.0),
    (135.0, 45.0),
    (135.0, -45.0),
    (-135.0, 45.0),
    (-135.0, -45.0),
];

fn read_toml(path: &Path) -> toml::Table {
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn matrix_of(v: &toml::Value) -> [[f64; 3]; 3] {
    let rows = v.as_array().unwrap();
    core::array::from_fn(|i| vector_of(&rows[i]))
}

fn vector_of(v: &toml::Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    core::array::from_fn(|i| a[i].as_float().unwrap())
}

/// Per-column means of a CSV's data rows.
fn column_means(csv: &str) -> Vec<f64> {
    let mut sum = Vec::new();
    let mut n = 0.0;
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        sum.resize(v.len(), 0.0);
        for (s, x) in sum.iter_mut().zip(v) {
            *s += x;
        }
        n += 1.0;
    }
    sum.into_iter().map(|x| x / n).collect()
}

#[test]
fn accel_fit_round_trip_recovers_the_truth_within_3_sigma_and_corrects_to_g() {
    let d = dir("fit_accel_round_trip");
    let records = static_records(&d, &SPREAD);
    let cal = d.join("cal.toml");
    let mut args = vec!["calib", "fit", "accel"];
    for r in &records {
        args.extend(["--positions", s(r)]);
    }
    args.extend(["--out", s(&cal)]);
    let out = triad(&args);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        stdout.contains("20 static segments, 20 distinct orientations"),
        "{stdout}"
    );
    assert!(
        stdout.contains("residual |(I+Σ)⁻¹(f̂ − b)| − g: RMS"),
        "{stdout}"
    );

    // The written file passes `triad calib check`.
    let check = triad(&["calib", "check", s(&cal)]);
    assert!(check.status.success(), "{}", text(&check.stderr));

    // The truth in the fit's convention: T = upper Cholesky factor of
    // M⁻ᵀM⁻¹ (invariant under the unobservable rotation), (I+Σ) = T⁻¹.
    let t = cholesky_upper(&gram(&matrix::inverse(&ACCEL_M).unwrap())).unwrap();
    let m_truth = matrix::inverse(&t).unwrap();
    let doc = read_toml(&cal);
    let accel = doc["accel"].as_table().unwrap();
    let fit = doc["fit"]["accel"].as_table().unwrap();
    let m = matrix_of(&accel["scale_misalignment"]);
    let b = vector_of(&accel["bias"]);
    let sm = matrix_of(&fit["sigma_scale_misalignment"]);
    let sb = vector_of(&fit["sigma_bias"]);
    // 3σ: the σ's are the fit's own s²(JᵀJ)⁻¹ with 20 − 9 = 11 degrees of
    // freedom (a t distribution: P(|t| > 3) ≈ 1.2 % per parameter); the
    // seeds are fixed, so the outcome is deterministic.
    for i in 0..3 {
        assert!(
            (b[i] - ACCEL_B[i]).abs() <= 3.0 * sb[i],
            "b[{i}] {} vs {} ± {}",
            b[i],
            ACCEL_B[i],
            sb[i]
        );
        for j in i..3 {
            let err = (m[i][j] - m_truth[i][j]).abs();
            assert!(
                err <= 3.0 * sm[i][j],
                "(I+Σ)[{i}][{j}] {} vs {} ± {}",
                m[i][j],
                m_truth[i][j],
                sm[i][j]
            );
        }
        for j in 0..i {
            assert_eq!(m[i][j], 0.0, "lower triangle by convention");
        }
    }
    // The σ's are those of a mean of 1000 samples of σ = 6.9e-3 m/s² over
    // 20 orientations: bias σ ≈ σ/√1000 · √(3/20)·(geometry) ~ 1e-4 —
    // check they are of that order, not vacuous.
    for x in sb {
        assert!(x > 1e-5 && x < 5e-4, "σ_b {x}");
    }

    // `triad correct` with the fitted file: the mean of |f| − g per record.
    // Bound: the mean of |f| over n = 1000 samples scatters by σ/√n =
    // 2.2e-4 m/s² (noise along gravity); the calibration's own error adds
    // ≲ the fit residual (RMS ≈ 1.4e-4 here); |f| of a noisy vector is
    // biased by σ²/g = 5e-6 and f32 rounding is ~1e-6. 4σ/√n = 8.7e-4 bounds
    // every record (P ≈ 6e-5 each for the noise). Uncorrected, |f̂| − g
    // reaches 0.37 m/s², so the bound is 400× tighter than doing nothing.
    let bound = 4.0 * ACCEL_SIGMA / 1000f64.sqrt();
    let mut raw_worst = 0.0f64;
    for r in &records {
        let out = triad(&["correct", "--calib", s(&cal), s(r)]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let mut sum = 0.0;
        let mut n = 0.0;
        for line in text(&out.stdout).lines().skip(1) {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            sum += (v[1] * v[1] + v[2] * v[2] + v[3] * v[3]).sqrt() - G;
            n += 1.0;
        }
        let mean = sum / n;
        assert!(
            mean.abs() <= bound,
            "{}: mean |f| − g = {mean:e} > {bound:e}",
            r.display()
        );
        let raw = column_means(&std::fs::read_to_string(r).unwrap());
        raw_worst =
            raw_worst.max(((raw[1] * raw[1] + raw[2] * raw[2] + raw[3] * raw[3]).sqrt() - G).abs());
    }
    assert!(
        raw_worst > 100.0 * bound,
        "the uncorrected data should be far off: {raw_worst}"
    );
}

/// The records one after another in one file (t shifted by `shift` s each).
fn concatenate(records: &[PathBuf], out: &Path, shift: f64) {
    let mut text = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for (i, r) in records.iter().enumerate() {
        for line in std::fs::read_to_string(r).unwrap().lines().skip(1) {
            let (t, rest) = line.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            text.push_str(&format!("{},{rest}\n", t + shift * i as f64));
        }
    }
    std::fs::write(out, text).unwrap();
}

#[test]
fn accel_fit_finds_the_segments_of_one_record_or_takes_them_given() {
    // The 20 records back to back in one file: the detector must find 20
    // segments (the orientation changes fall between 0.5 s blocks, so only
    // the jump of the block mean separates them); --segments gives the same
    // segments by hand. Both fits agree to well within their σ.
    let d = dir("fit_accel_one_file");
    let records = static_records(&d, &SPREAD);
    let one = d.join("all.csv");
    concatenate(&records, &one, 10.0);
    let detected = d.join("detected.toml");
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--positions",
        s(&one),
        "--out",
        s(&detected),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("20 static segments, 20 distinct orientations"),
        "{}",
        text(&out.stdout)
    );
    let given = d.join("given.toml");
    let segments = (0..20)
        .map(|i| format!("{}-{}", 10 * i + 1, 10 * i + 9))
        .collect::<Vec<_>>()
        .join(",");
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--positions",
        s(&one),
        "--segments",
        &segments,
        "--out",
        s(&given),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let a = read_toml(&detected);
    let b = read_toml(&given);
    let sb = vector_of(&a["fit"]["accel"]["sigma_bias"]);
    let (ba, bb) = (
        vector_of(&a["accel"]["bias"]),
        vector_of(&b["accel"]["bias"]),
    );
    for i in 0..3 {
        // The given segments are 8 s of the detected ~9 s: same data mostly,
        // so the estimates differ by well under their σ.
        assert!((ba[i] - bb[i]).abs() < sb[i], "{ba:?} {bb:?} ± {sb:?}");
    }
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--positions",
        s(&one),
        "--segments",
        "5-2",
        "--out",
        s(&given),
    ]);
    assert!(
        text(&out.stderr).contains("--segments: `5-2` ends before it starts"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn accel_fit_keeps_the_base_gyro_and_orientation() {
    let d = dir("fit_accel_base");
    // The six faces and six attitudes tilted about two axes (45°, 45°). The
    // first twelve of SPREAD would not do: with no direction off all three
    // coordinate planes the x–y coupling is undetermined (κ ≈ 2e4, refused).
    let attitudes: Vec<(f64, f64)> = SPREAD[..6].iter().chain(&SPREAD[12..18]).copied().collect();
    let records = static_records(&d, &attitudes);
    let base = calibration("lab-example.toml");
    let cal = d.join("cal.toml");
    let mut args = vec![
        "calib",
        "fit",
        "accel",
        "--base",
        s(&base),
        "--out",
        s(&cal),
    ];
    for r in &records {
        args.extend(["--positions", s(r)]);
    }
    let out = triad(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let doc = read_toml(&cal);
    let base_doc = read_toml(&base);
    assert_eq!(
        doc["gyro"], base_doc["gyro"],
        "the gyro triad is kept, temperature terms and all"
    );
    assert_eq!(doc["orientation"].as_str(), Some("ROTATION_YAW_90"));
    assert!(
        doc["accel"].get("temperature").is_none(),
        "the fitted triad has no temperature terms"
    );
    let check = triad(&["calib", "check", s(&cal)]);
    assert!(check.status.success(), "{}", text(&check.stderr));
}

#[test]
fn accel_fit_refuses_a_cube_tumble_naming_the_orientations_found() {
    // tumble-6 and tumble-24: faces up in turn, turns between. The detector
    // finds every static dwell (6 and 24), but a cube tumble has only 6
    // gravity directions (the 24 differ in heading, which gravity cannot
    // see), fewer than the 9 unknowns.
    let d = dir("fit_accel_tumble");
    for (scene, segments) in [("tumble-6", 6), ("tumble-24", 24)] {
        let raw = d.join(format!("{scene}.csv"));
        let run = triad(&["sim", "--scene", scene, "--out", s(&raw)]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let cal = d.join("cal.toml");
        let out = triad(&[
            "calib",
            "fit",
            "accel",
            "--positions",
            s(&raw),
            "--out",
            s(&cal),
        ]);
        let stderr = text(&out.stderr);
        assert!(!out.status.success());
        let found =
            format!("found 6 distinct static orientation(s) in {segments} static segment(s)");
        assert!(
            stderr.contains(&found)
                && stderr.contains("needs at least 9")
                && stderr.contains("use --axis-aligned"),
            "{scene}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!cal.exists(), "nothing written on refusal");
    }
}

#[test]
fn accel_fit_refuses_orientations_in_one_plane() {
    // Twelve attitudes rolling about x: gravity stays in the y–z plane.
    let d = dir("fit_accel_plane");
    let rolls: Vec<(f64, f64)> = (0..12).map(|i| (-180.0 + 30.0 * i as f64, 0.0)).collect();
    let records = static_records(&d, &rolls);
    let mut args = vec!["calib", "fit", "accel", "--out"];
    let cal = d.join("cal.toml");
    args.push(s(&cal));
    for r in &records {
        args.extend(["--positions", s(r)]);
    }
    let out = triad(&args);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("the 12 static orientations have gravity directions in one plane"),
        "{stderr}"
    );
}

#[test]
fn fit_reports_a_non_numeric_cell_with_its_line_and_missing_columns() {
    let d = dir("fit_bad_csv");
    let bad = d.join("bad.csv");
    std::fs::write(
        &bad,
        "t,ax,ay,az,gx,gy,gz,temp\n0,0,0,9.8,0,0,0,25\n0.01,abc,0,9.8,0,0,0,25\n",
    )
    .unwrap();
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--positions",
        s(&bad),
        "--out",
        s(&d.join("c.toml")),
    ]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("bad.csv line 3, column 2 (ax): `abc` is not a finite number"),
        "{stderr}"
    );

    let short = d.join("short.csv");
    std::fs::write(&short, "t,ax,ay\n0,0,0\n").unwrap();
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--positions",
        s(&short),
        "--out",
        s(&d.join("c.toml")),
    ]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("short.csv: missing column(s) `az` in the header `t,ax,ay`"),
        "{stderr}"
    );
    let out = triad(&[
        "calib",
        "fit",
        "gyro",
        "--rate-table",
        s(&short),
        "--rates",
        "z:30",
        "--out",
        s(&d.join("c.toml")),
    ]);
    assert!(
        text(&out.stderr).contains("missing column(s) `gx`, `gy`, `gz`"),
        "{}",
        text(&out.stderr)
    );
}

/// The gyro errors of a rate-grade part (tumble-6's gyro, without
/// quantisation and g-sensitivity: g-sensitivity is not in the model).
const GYRO_ERRORS: &str = r#"
white_noise = "0.0028 deg/s/sqrt(Hz)"
bias = ["0.5 deg/s", "-0.3 deg/s", "0.2 deg/s"]
scale_factor = ["4000 ppm", "-2000 ppm", "1000 ppm"]
misalignment = [["0", "1 mrad", "-2 mrad"], ["2 mrad", "0", "1 mrad"], ["-1 mrad", "2 mrad", "0"]]
"#;
const GYRO_M: [[f64; 3]; 3] = [
    [1.004, 0.001, -0.002],
    [0.002, 0.998, 0.001],
    [-0.001, 0.002, 1.001],
];
/// Per-sample σ: 0.0028 °/s/√Hz · √(200 Hz).
const GYRO_SIGMA: f64 = 0.0028 * 0.017453292519943295 * 14.142135623730951;

/// Rate-table runs (axis up, rate in °/s), 20 s at 200 Hz each.
fn rate_runs(d: &Path, runs: &[(&str, f64)]) -> Vec<PathBuf> {
    runs.iter()
        .enumerate()
        .map(|(i, (axis, rate))| {
            let scene = d.join(format!("rate-{i}.toml"));
            std::fs::write(
                &scene,
                format!(
                    "rate_hz = 200.0\nduration_s = 20.0\n[motion]\nkind = \"rate-table\"\naxis = \"{axis}\"\n\
                     rate = \"{rate} deg/s\"\n[gyro]\n{GYRO_ERRORS}"
                ),
            )
            .unwrap();
            let out = d.join(format!("rate-{i}.csv"));
            let seed = (100 + i).to_string();
            let run = triad(&["sim", "--scene", s(&scene), "--seed", &seed, "--out", s(&out)]);
            assert!(run.status.success(), "{}", text(&run.stderr));
            out
        })
        .collect()
}

/// `triad calib fit gyro --rates RATES --out CAL --rate-table F…`.
fn fit_gyro(rates: &str, files: &[PathBuf], cal: &Path) -> Output {
    let mut args = vec!["calib", "fit", "gyro", "--rates", rates, "--out", s(cal)];
    for f in files {
        args.extend(["--rate-table", s(f)]);
    }
    triad(&args)
}

#[test]
fn gyro_rate_table_round_trip_recovers_the_truth_within_3_sigma() {
    let d = dir("fit_gyro_round_trip");
    let runs = [
        ("+z", 30.0),
        ("+z", -30.0),
        ("+z", 90.0),
        ("+z", -90.0),
        ("+x", 30.0),
        ("+x", -30.0),
        ("+x", 90.0),
        ("+x", -90.0),
        ("+y", 30.0),
        ("+y", -30.0),
        ("+y", 90.0),
        ("+y", -90.0),
    ];
    let files = rate_runs(&d, &runs);
    let rates = runs
        .iter()
        .map(|(a, r)| format!("{}:{r}", &a[1..]))
        .collect::<Vec<_>>()
        .join(",");
    let cal = d.join("cal.toml");
    let out = fit_gyro(&rates, &files, &cal);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("gyro rate-table fit: 12 segments"),
        "{}",
        text(&out.stdout)
    );
    let check = triad(&["calib", "check", s(&cal)]);
    assert!(check.status.success(), "{}", text(&check.stderr));

    let doc = read_toml(&cal);
    let gyro = doc["gyro"].as_table().unwrap();
    let fit = doc["fit"]["gyro"].as_table().unwrap();
    let m = matrix_of(&gyro["scale_misalignment"]);
    let b = vector_of(&gyro["bias"]);
    let sm = matrix_of(&fit["sigma_scale_misalignment"]);
    let sb = vector_of(&fit["sigma_bias"]);
    let b_true = [
        0.5f64.to_radians(),
        (-0.3f64).to_radians(),
        0.2f64.to_radians(),
    ];
    // 3σ with 12 − 4 = 8 degrees of freedom per axis (t distribution:
    // P(|t| > 3) ≈ 1.7 % per parameter); fixed seeds, deterministic.
    for i in 0..3 {
        assert!(
            (b[i] - b_true[i]).abs() <= 3.0 * sb[i],
            "b[{i}] {} vs {} ± {}",
            b[i],
            b_true[i],
            sb[i]
        );
        for j in 0..3 {
            assert!(
                (m[i][j] - GYRO_M[i][j]).abs() <= 3.0 * sm[i][j],
                "(I+Σ)[{i}][{j}] {} vs {} ± {}",
                m[i][j],
                GYRO_M[i][j],
                sm[i][j]
            );
        }
    }
    // `triad correct`: each run's corrected mean rate equals the table rate.
    // The mean of n = 4000 samples scatters by σ/√n = 1.1e-5 rad/s; the
    // calibration's error at 90 °/s adds |δ(I+Σ)|·ω ≲ 3·σ_m·ω ≈ a few 1e-5
    // (σ_m from the file). Bound per axis: 4σ/√n + 3·max σ_m·|ω| + 3·max σ_b.
    let max_sm = sm.iter().flatten().fold(0.0f64, |a, &x| a.max(x));
    let max_sb = sb.iter().fold(0.0f64, |a, &x| a.max(x));
    for (f, (axis, rate)) in files.iter().zip(runs) {
        let out = triad(&["correct", "--exact", "--calib", s(&cal), s(f)]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let means = column_means(&text(&out.stdout));
        let k = match axis.as_bytes()[1] {
            b'x' => 0,
            b'y' => 1,
            _ => 2,
        };
        let w = rate.to_radians();
        let bound = 4.0 * GYRO_SIGMA / 4000f64.sqrt() + 3.0 * max_sm * w.abs() + 3.0 * max_sb;
        for axis_i in 0..3 {
            let want = if axis_i == k { w } else { 0.0 };
            let got = means[4 + axis_i];
            assert!(
                (got - want).abs() <= bound,
                "{}: axis {axis_i} {got} vs {want} (bound {bound:e})",
                f.display()
            );
        }
    }
}

#[test]
fn gyro_fit_refuses_rates_about_one_axis_and_too_few_rates() {
    let d = dir("fit_gyro_degenerate");
    let runs = [("+z", 30.0), ("+z", -30.0), ("+z", 90.0), ("+z", -90.0)];
    let files = rate_runs(&d, &runs);
    let cal = d.join("cal.toml");
    let out = fit_gyro("z:30,z:-30,z:90,z:-90", &files, &cal);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("the true rate vectors are on one line (e.g. all about one axis)"),
        "{stderr}"
    );

    let out = fit_gyro("z:30,z:-30,x:30", &files[..3], &cal);
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("found 3 rate segment(s)") && stderr.contains("needs at least 4"),
        "{stderr}"
    );

    let out = fit_gyro("z:30,z:-30", &files[..3], &cal);
    assert!(
        text(&out.stderr).contains("--rates gives 2 rate(s) for 3 segment(s)"),
        "{}",
        text(&out.stderr)
    );
    assert!(!cal.exists());
}

#[test]
fn gyro_static_bias_is_the_mean_with_its_standard_error() {
    let d = dir("fit_gyro_static");
    let scene = d.join("bench.toml");
    std::fs::write(
        &scene,
        format!("rate_hz = 200.0\nduration_s = 60.0\n[motion]\nkind = \"static\"\n[gyro]\n{GYRO_ERRORS}"),
    )
    .unwrap();
    let raw = d.join("bench.csv");
    assert!(triad(&["sim", "--scene", s(&scene), "--out", s(&raw)])
        .status
        .success());
    let cal = d.join("cal.toml");
    let out = triad(&[
        "calib",
        "fit",
        "gyro",
        "--static",
        s(&raw),
        "--out",
        s(&cal),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("the Earth rate (up to Ω = 15.041 °/h) is included"),
        "{}",
        text(&out.stdout)
    );
    let doc = read_toml(&cal);
    let b = vector_of(&doc["gyro"]["bias"]);
    let sb = vector_of(&doc["fit"]["gyro"]["sigma_bias"]);
    // No Earth rate in this scene, static at level: the mean is b exactly
    // plus noise of σ/√12000 = 3.6e-6 rad/s; the reported standard error
    // must be that (±10 %: the sample σ of 12000 values is within 1 %).
    let b_true = [
        0.5f64.to_radians(),
        (-0.3f64).to_radians(),
        0.2f64.to_radians(),
    ];
    let se = GYRO_SIGMA / 12000f64.sqrt();
    for i in 0..3 {
        assert!((sb[i] - se).abs() < 0.1 * se, "σ_b {} vs {se}", sb[i]);
        assert!(
            (b[i] - b_true[i]).abs() <= 4.0 * se,
            "b[{i}] {} vs {}",
            b[i],
            b_true[i]
        );
    }
    assert!(triad(&["calib", "check", s(&cal)]).status.success());
}

#[test]
fn a_shipped_calibration_is_a_base_and_a_bad_base_fails_before_the_records_are_read() {
    let d = dir("fit_base_shipped");
    let raw = d.join("still.csv");
    let run = triad(&[
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        "5",
        "--out",
        s(&raw),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let cal = d.join("cal.toml");
    let fit = |record: &Path, base: &str| {
        triad(&[
            "calib",
            "fit",
            "gyro",
            "--static",
            s(record),
            "--base",
            base,
            "--out",
            s(&cal),
        ])
    };
    // `default` is the calibration built into triad, as `calib check` takes it.
    let out = fit(&raw, "default");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let doc = read_toml(&cal);
    let shipped = read_toml(&calibration("default.toml"));
    assert_eq!(doc["accel"], shipped["accel"], "the other triad is kept");
    assert_eq!(
        doc["gyro"]["scale_misalignment"],
        shipped["gyro"]["scale_misalignment"]
    );
    assert!(triad(&["calib", "check", s(&cal)]).status.success());
    // A base that is no file and no shipped name is refused before the
    // (missing) record is opened.
    std::fs::remove_file(&cal).unwrap();
    let out = fit(&d.join("missing.csv"), "nope");
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("calibration `nope`: no such file"),
        "{stderr}"
    );
    assert!(!cal.exists());
}

#[test]
fn gyro_rate_table_segments_of_one_record_give_the_same_fit() {
    // Four runs (±30 °/s about z, +30 °/s about x and y: the minimum, 4 rate
    // vectors not in one plane) back to back in one file, with --segments.
    // 4 segments for 4 unknowns per axis: an exact fit (residual at
    // rounding level) and no σ, which the output says.
    let d = dir("fit_gyro_one_file");
    let runs = [("+z", 30.0), ("+z", -30.0), ("+x", 30.0), ("+y", 30.0)];
    let files = rate_runs(&d, &runs);
    let one = d.join("all.csv");
    concatenate(&files, &one, 20.0);
    let cal = d.join("cal.toml");
    let out = triad(&[
        "calib",
        "fit",
        "gyro",
        "--rate-table",
        s(&one),
        "--segments",
        "0-19.99,20-39.99,40-59.99,60-79.99",
        "--rates",
        "z:+30,z:-30,x:+30,y:+30",
        "--out",
        s(&cal),
    ]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains("no degree of freedom"), "{stdout}");
    let doc = read_toml(&cal);
    let m = matrix_of(&doc["gyro"]["scale_misalignment"]);
    // Exactly determined: the error is the noise of the means (1.1e-5
    // rad/s over 4000 samples) divided by the 0.52 rad/s lever of 30 °/s,
    // ≈ 2e-5 per entry; 2e-4 is 10 such σ (no σ is estimated here).
    for i in 0..3 {
        for j in 0..3 {
            assert!((m[i][j] - GYRO_M[i][j]).abs() < 2e-4, "{m:?}");
        }
    }
    assert!(doc["fit"]["gyro"].get("sigma_bias").is_none());
}

#[test]
fn gyro_static_bias_removes_the_vertical_earth_rate_when_given_the_latitude() {
    // Level at 48° N: the body sees (0, Ω cos φ, Ω sin φ). --latitude 48
    // removes the vertical Ω sin φ = 5.4e-5 rad/s (15 standard errors) from
    // z and leaves the horizontal Ω cos φ in y, as the output says.
    let d = dir("fit_gyro_static_latitude");
    let scene = d.join("bench.toml");
    std::fs::write(
        &scene,
        format!(
            "rate_hz = 200.0\nduration_s = 60.0\nlatitude_deg = 48.0\n[motion]\nkind = \"static\"\n[gyro]\n{GYRO_ERRORS}"
        ),
    )
    .unwrap();
    let raw = d.join("bench.csv");
    assert!(triad(&["sim", "--scene", s(&scene), "--out", s(&raw)])
        .status
        .success());
    let cal = d.join("cal.toml");
    let out = triad(&[
        "calib",
        "fit",
        "gyro",
        "--static",
        s(&raw),
        "--latitude",
        "48",
        "--out",
        s(&cal),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("the horizontal part Ω·cos φ = 10.064 °/h"),
        "{}",
        text(&out.stdout)
    );
    let b = vector_of(&read_toml(&cal)["gyro"]["bias"]);
    let earth = 7.292115e-5f64;
    let phi = 48f64.to_radians();
    let se = GYRO_SIGMA / 12000f64.sqrt();
    let b_true = [
        0.5f64.to_radians(),
        (-0.3f64).to_radians(),
        0.2f64.to_radians(),
    ];
    // Scale/misalignment act on the Earth rate too: ≤ 0.4 % of 7.3e-5 = 3e-7, ≪ se.
    assert!(
        (b[2] - b_true[2]).abs() <= 4.0 * se,
        "z {} vs {}",
        b[2],
        b_true[2]
    );
    assert!(
        (b[1] - (b_true[1] + earth * phi.cos())).abs() <= 4.0 * se,
        "y {}",
        b[1]
    );
    assert!((b[0] - b_true[0]).abs() <= 4.0 * se, "x {}", b[0]);
}

#[test]
fn accel_axis_aligned_fit_of_a_24_position_tumble_recovers_the_full_matrix() {
    // A 24-position cube tumble with the accelerometer errors above and
    // white noise only: --axis-aligned knows gravity's direction in each
    // position, so the full (I+Σ) is compared with the truth directly.
    let d = dir("fit_accel_cube");
    let scene = d.join("tumble.toml");
    std::fs::write(
        &scene,
        format!(
            "rate_hz = 100.0\nduration_s = 360.0\n[motion]\nkind = \"tumble\"\npositions = 24\n\
             dwell_s = 10.0\ntransition_s = 5.0\n[accel]\n{ACCEL_ERRORS}"
        ),
    )
    .unwrap();
    let raw = d.join("tumble.csv");
    let run = triad(&["sim", "--scene", s(&scene), "--out", s(&raw)]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let cal = d.join("cal.toml");
    let out = triad(&[
        "calib",
        "fit",
        "accel",
        "--axis-aligned",
        "--positions",
        s(&raw),
        "--out",
        s(&cal),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("24 static segments"),
        "{}",
        text(&out.stdout)
    );
    assert!(triad(&["calib", "check", s(&cal)]).status.success());
    let doc = read_toml(&cal);
    let m = matrix_of(&doc["accel"]["scale_misalignment"]);
    let b = vector_of(&doc["accel"]["bias"]);
    let sm = matrix_of(&doc["fit"]["accel"]["sigma_scale_misalignment"]);
    let sb = vector_of(&doc["fit"]["accel"]["sigma_bias"]);
    // 3σ with 24 − 4 = 20 degrees of freedom per axis (P(|t| > 3) ≈ 0.7 %
    // per parameter); fixed seed, deterministic.
    for i in 0..3 {
        assert!(
            (b[i] - ACCEL_B[i]).abs() <= 3.0 * sb[i],
            "b[{i}] {} vs {} ± {}",
            b[i],
            ACCEL_B[i],
            sb[i]
        );
        for j in 0..3 {
            assert!(
                (m[i][j] - ACCEL_M[i][j]).abs() <= 3.0 * sm[i][j],
                "(I+Σ)[{i}][{j}] {} vs {} ± {}",
                m[i][j],
                ACCEL_M[i][j],
                sm[i][j]
            );
        }
    }
}
