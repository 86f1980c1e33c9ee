//! `triad calib fit thermal`: a simulated unit (consumer-mems) turned by hand
//! at three soaks (hand-soak) gives back its temperature terms within 3σ of
//! `--truth-calib`'s; the file corrects a record at a temperature the fit did
//! not use to the truth, where the same file without its temperature terms
//! does not; `triad correct` counts the samples outside the fitted range;
//! every refusal says what is wrong, and writes nothing.
#![allow(clippy::needless_range_loop)] // index form reads as the matrix formulas

mod common;

use std::path::{Path, PathBuf};

use common::{dir, s, text, triad};
use triad::model::matrix::{self, Mat3};
use triad_lab::calib_fit::numerics::small3::{cholesky_upper, gram};

const G: f64 = 9.80665;

/// `triad sim --unit consumer-mems --script SCRIPT --record-seed K` into
/// `d`/`name`.csv (and the true calibration, when asked).
fn simulate(d: &Path, name: &str, script: &str, seed: &str, truth: Option<&[&str]>) -> PathBuf {
    let out = d.join(format!("{name}.csv"));
    let mut args = vec![
        "sim",
        "--unit",
        "consumer-mems",
        "--script",
        script,
        "--record-seed",
        seed,
        "--quiet",
        "--out",
        s(&out),
    ];
    args.extend(truth.unwrap_or_default());
    let o = triad(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    out
}

/// The hand-soak script's motion at one constant temperature (or soaks).
fn hand_script(d: &Path, name: &str, temperature: &str) -> PathBuf {
    let path = d.join(format!("{name}.toml"));
    let body = format!(
        "rate_hz = 100.0\nduration_s = 240.0\n[motion]\nkind = \"hand\"\nposes = 24\nseed = 5\n\
         dwell_s = 8.0\nturn_s = 2.0\n[temperature]\n{temperature}\n"
    );
    std::fs::write(&path, body).unwrap();
    path
}

fn load(path: &Path) -> toml::Table {
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

fn matrix_of(v: &toml::Value) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| v[i][j].as_float().unwrap()))
}

fn vector_of(v: &toml::Value) -> [f64; 3] {
    std::array::from_fn(|i| v[i].as_float().unwrap())
}

/// The truth's (I+Σ)(T) in the fit's convention: its upper triangular
/// factor U ((I+Σ)(T) = U·Q, Q a rotation).
fn upper_at(truth: &toml::Table, t: f64) -> Mat3 {
    let a = &truth["accel"];
    let (m, d) = (
        matrix_of(&a["scale_misalignment"]),
        matrix_of(&a["temperature"]["scale_misalignment_per_c"]),
    );
    let delta = t - a["temperature"]["reference_c"].as_float().unwrap();
    let m_t: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] + delta * d[i][j]));
    let inv = matrix::inverse(&m_t).unwrap();
    matrix::inverse(&cholesky_upper(&gram(&inv)).unwrap()).unwrap()
}

/// Per static pose of a corrected record (the truth's gyro exactly zero):
/// |mean accel| − g and the mean gyro, the worst over the poses; and over
/// the turns (true rate > 0.5 rad/s) the mean relative error of |ω|, the
/// gyro's scale (a rotation of the frame, which the accelerometer's
/// convention leaves free, does not change it).
fn pose_and_turn_errors(corrected: &str, truth_csv: &Path) -> (f64, f64, f64) {
    let rows = |t: &str| -> Vec<Vec<f64>> {
        t.lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let (c, t) = (
        rows(corrected),
        rows(&std::fs::read_to_string(truth_csv).unwrap()),
    );
    let (mut accel, mut gyro) = (0.0f64, 0.0f64);
    let norm = |r: &[f64]| (r[4] * r[4] + r[5] * r[5] + r[6] * r[6]).sqrt();
    let turning: Vec<usize> = (0..t.len()).filter(|&k| norm(&t[k]) > 0.5).collect();
    let scale = turning
        .iter()
        .map(|&k| norm(&c[k]) / norm(&t[k]) - 1.0)
        .sum::<f64>()
        / turning.len() as f64;
    let mut i = 0;
    while i < t.len() {
        let still = |k: usize| t[k][4..7].iter().all(|&w| w == 0.0);
        if !still(i) {
            i += 1;
            continue;
        }
        let start = i;
        while i < t.len() && still(i) {
            i += 1;
        }
        let n = (i - start) as f64;
        let mean = |col: usize| c[start..i].iter().map(|r| r[col]).sum::<f64>() / n;
        let a = [mean(1), mean(2), mean(3)];
        accel = accel.max(((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt() - G).abs());
        gyro = gyro.max((4..7).map(|k| mean(k).abs()).fold(0.0, f64::max));
    }
    (accel, gyro, scale)
}

#[test]
fn a_unit_at_three_soaks_gives_back_its_temperature_terms_and_corrects_a_fourth_temperature() {
    let d = dir("soaks");
    let truth_path = d.join("truth.toml");
    let soaks = simulate(
        &d,
        "soaks",
        "hand-soak",
        "1",
        Some(&["--truth-calib", s(&truth_path)]),
    );
    let cal = d.join("cal.toml");
    let o = triad(&["calib", "fit", "thermal", s(&soaks), "--out", s(&cal)]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{}{report}", text(&o.stderr));
    assert!(
        report.contains(
            "72 static segments over -10.0..60.0 °C (swing 70.0 °C, 3 levels), reference 25.0 °C"
        ),
        "{report}"
    );
    assert!(
        report.contains("warning: accelerometer: not fitted, left zero: bias_coefficients c3: 3 distinct temperature level(s)"),
        "{report}"
    );
    let (fit, truth) = (load(&cal), load(&truth_path));
    let stats = &fit["fit"]["accel"];
    assert_eq!(stats["degrees_of_freedom"].as_integer(), Some(72 - 21));
    assert_eq!(stats["temperature_range_c"][1].as_float(), Some(60.0));
    assert_eq!(
        fit["accel"]["temperature"]["reference_c"].as_float(),
        Some(25.0)
    );

    // Every fitted term within 3σ of the truth (one session: the many-seed
    // coverage is lab/tests/thermal_fit.rs's).
    let a = &fit["accel"];
    let (u0, u_plus, u_minus) = (
        upper_at(&truth, 25.0),
        upper_at(&truth, 26.0),
        upper_at(&truth, 24.0),
    );
    let d_truth: Mat3 =
        std::array::from_fn(|i| std::array::from_fn(|j| (u_plus[i][j] - u_minus[i][j]) / 2.0));
    let (m, sm) = (
        matrix_of(&a["scale_misalignment"]),
        matrix_of(&stats["sigma_scale_misalignment"]),
    );
    let (dm, sd) = (
        matrix_of(&a["temperature"]["scale_misalignment_per_c"]),
        matrix_of(&stats["sigma_scale_misalignment_per_c"]),
    );
    for i in 0..3 {
        for j in i..3 {
            assert!(
                (m[i][j] - u0[i][j]).abs() <= 3.0 * sm[i][j],
                "(I+Σ)[{i}][{j}] {} vs {}",
                m[i][j],
                u0[i][j]
            );
            assert!(
                (dm[i][j] - d_truth[i][j]).abs() <= 3.0 * sd[i][j],
                "D[{i}][{j}] {} vs {}",
                dm[i][j],
                d_truth[i][j]
            );
        }
    }
    // The gyro's (I+Σ)(T) in the accelerometer's corrected frame at T.
    let gyro_truth = |t: f64| -> Mat3 {
        let (a, g) = (&truth["accel"], &truth["gyro"]);
        let at = |x: &toml::Value| {
            let (m, d) = (
                matrix_of(&x["scale_misalignment"]),
                matrix_of(&x["temperature"]["scale_misalignment_per_c"]),
            );
            let delta = t - x["temperature"]["reference_c"].as_float().unwrap();
            let m: Mat3 =
                std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] + delta * d[i][j]));
            m
        };
        let inv = matrix::inverse(&at(a)).unwrap();
        let t_u = cholesky_upper(&gram(&inv)).unwrap();
        matrix::mul(&at(g), &matrix::mul(&inv, &matrix::inverse(&t_u).unwrap()))
    };
    let (g0, g_plus, g_minus) = (gyro_truth(25.0), gyro_truth(26.0), gyro_truth(24.0));
    let gs = &fit["fit"]["gyro"];
    let (m, sm) = (
        matrix_of(&fit["gyro"]["scale_misalignment"]),
        matrix_of(&gs["sigma_scale_misalignment"]),
    );
    let (dm, sd) = (
        matrix_of(&fit["gyro"]["temperature"]["scale_misalignment_per_c"]),
        matrix_of(&gs["sigma_scale_misalignment_per_c"]),
    );
    for i in 0..3 {
        for j in 0..3 {
            let d = (g_plus[i][j] - g_minus[i][j]) / 2.0;
            assert!(
                (m[i][j] - g0[i][j]).abs() <= 3.0 * sm[i][j],
                "gyro (I+Σ)[{i}][{j}] {} vs {}",
                m[i][j],
                g0[i][j]
            );
            assert!(
                (dm[i][j] - d).abs() <= 3.0 * sd[i][j],
                "gyro D[{i}][{j}] {} vs {d}",
                dm[i][j]
            );
        }
    }
    assert_eq!(
        gs["moves"].as_integer(),
        Some(69),
        "72 poses, 2 chamber steps"
    );
    for triad_name in ["accel", "gyro"] {
        let (f, t, st) = (
            &fit[triad_name],
            &truth[triad_name],
            &fit["fit"][triad_name],
        );
        let (c, ct, sc) = (
            matrix_of(&f["temperature"]["bias_coefficients"]),
            matrix_of(&t["temperature"]["bias_coefficients"]),
            matrix_of(&st["sigma_bias_coefficients"]),
        );
        let (b, bt, sb) = (
            vector_of(&f["bias"]),
            vector_of(&t["bias"]),
            vector_of(&st["sigma_bias"]),
        );
        for i in 0..3 {
            assert!(
                (b[i] - bt[i]).abs() <= 3.0 * sb[i],
                "{triad_name} b[{i}] {} vs {}",
                b[i],
                bt[i]
            );
            for k in 0..2 {
                assert!(sc[i][k] > 0.0, "{triad_name} c{} fitted", k + 1);
                assert!(
                    (c[i][k] - ct[i][k]).abs() <= 3.0 * sc[i][k],
                    "{triad_name} c{}[{i}] {} vs {}",
                    k + 1,
                    c[i][k],
                    ct[i][k]
                );
            }
            assert_eq!(
                (c[i][2], sc[i][2]),
                (0.0, 0.0),
                "c3 not supported by 3 levels"
            );
        }
    }

    // A record at 45 °C, which the fit did not use: each pose's corrected
    // mean has |f| = g and zero rate, to the fit's σ's carried 20 °C out
    // (accel: σ_b ≈ 1e-4 + 20·σ_c1 ≈ 4e-5 per axis, the pose mean's noise
    // 2e-4; gyro: 4e-6 + 20·8e-8, noise 1.4e-5 rad/s), so 1e-3 m/s² and
    // 1e-4 rad/s are ≥ 4σ of each. Without the temperature terms the
    // same file is 20 °C × ~1e-3 m/s²/°C and ~1e-4 rad/s/°C off.
    let h45 = hand_script(&d, "hand-45", "kind = \"constant\"\ncelsius = 45.0");
    let truth45 = d.join("h45-truth.csv");
    let rec45 = simulate(&d, "h45", s(&h45), "99", Some(&["--truth", s(&truth45)]));
    let o = triad(&["correct", "--calib", s(&cal), s(&rec45)]);
    assert!(
        o.status.success() && o.stderr.is_empty(),
        "{}",
        text(&o.stderr)
    );
    // The gyro's scale at 45 °C: σ ≈ 1.3e-5 + 20·4.5e-7 ≈ 2e-5, noise over
    // the turns' samples far less; 1e-4 is ≥ 4σ. Without D: −100 ppm/°C × 20 °C.
    let (accel, gyro, scale) = pose_and_turn_errors(&text(&o.stdout), &truth45);
    assert!(
        accel < 1e-3 && gyro < 1e-4 && scale.abs() < 1e-4,
        "|f| − g {accel:.2e} m/s², rate {gyro:.2e} rad/s, |ω| {scale:.2e}"
    );
    let mut no_terms = fit.clone();
    for t in ["accel", "gyro"] {
        no_terms[t].as_table_mut().unwrap().remove("temperature");
    }
    let bare = d.join("bare.toml");
    std::fs::write(&bare, toml::to_string(&no_terms).unwrap()).unwrap();
    let o = triad(&["correct", "--calib", s(&bare), s(&rec45)]);
    let (accel, gyro, scale) = pose_and_turn_errors(&text(&o.stdout), &truth45);
    assert!(
        accel > 5e-3 && gyro > 1e-3 && scale.abs() > 1e-3,
        "without the terms: {accel:.2e}, {gyro:.2e}, {scale:.2e}"
    );

    // `calib verify` reads the thermal fit's statistics (21 parameters, one
    // magnitude per segment) and passes a fresh record at the reference.
    let fresh = simulate(&d, "fresh", "hand-rotations", "2", None);
    let o = triad(&["calib", "verify", s(&cal), s(&fresh)]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}{}", text(&o.stderr));
    assert!(
        out.contains("p = 21, N = 72") && out.contains("verdict: PASS"),
        "{out}"
    );

    // At 45 °C verify applies the terms at each pose's temperature: the
    // fitted file passes; the same file without its terms (applied as they
    // are, at 45 °C off by 20 °C of bias and scale) fails.
    let o = triad(&["calib", "verify", s(&cal), s(&rec45)]);
    let out = text(&o.stdout);
    assert!(
        o.status.success() && out.contains("verdict: PASS"),
        "{out}{}",
        text(&o.stderr)
    );
    let o = triad(&["calib", "verify", s(&bare), s(&rec45)]);
    let out = text(&o.stdout);
    assert!(
        !o.status.success() && out.contains("verdict: FAIL"),
        "{out}{}",
        text(&o.stderr)
    );
    // A record without `temp` cannot be verified against temperature terms.
    let no_temp = d.join("no-temp.csv");
    let rows: String = std::fs::read_to_string(&rec45)
        .unwrap()
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    std::fs::write(&no_temp, rows).unwrap();
    let o = triad(&["calib", "verify", s(&cal), s(&no_temp)]);
    let err = text(&o.stderr);
    assert!(
        !o.status.success() && err.contains("no temperature column `temp`"),
        "{err}"
    );

    // At 70 °C every sample is outside the range: counted and said.
    let h70 = hand_script(&d, "hand-70", "kind = \"constant\"\ncelsius = 70.0");
    let rec70 = simulate(&d, "h70", s(&h70), "98", None);
    let o = triad(&["correct", "--calib", s(&cal), s(&rec70)]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("24000 of 24000 samples lie outside -10.0..60.0 °C")
            && err.contains("extrapolate"),
        "{err}"
    );
}

/// Runs the fit on `records`; it must fail with `expected` and write nothing.
fn refused(d: &Path, records: &[&Path], extra: &[&str], expected: &str) {
    let out = d.join("refused.toml");
    let mut args = vec!["calib", "fit", "thermal"];
    args.extend(records.iter().map(|p| s(p)));
    args.extend(extra);
    args.extend(["--out", s(&out)]);
    let o = triad(&args);
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{}", text(&o.stdout));
    assert!(err.contains(expected), "expected `{expected}` in: {err}");
    assert!(!out.exists(), "nothing written");
}

#[test]
fn records_that_cannot_support_the_terms_are_refused_with_what_to_do() {
    let d = dir("refusals");
    // A swing of 8 °C: below the 10 °C a linear term needs.
    let narrow = hand_script(
        &d,
        "narrow",
        "kind = \"soak\"\nlevels_c = [20.0, 28.0]\nhold_s = 120.0",
    );
    let narrow = simulate(&d, "narrow", s(&narrow), "1", None);
    refused(
        &d,
        &[&narrow],
        &[],
        "a swing of 8.0 °C: a temperature term needs at least 10 °C",
    );

    // A static ramp sees one gravity direction: no D, the gyro's bias only.
    let ramp = simulate(&d, "ramp", "thermal-ramp-static", "1", None);
    refused(&d, &[&ramp], &[], "found 1 colder and 1 warmer");
    let cal = d.join("gyro.toml");
    let o = triad(&[
        "calib",
        "fit",
        "thermal",
        s(&ramp),
        "--gyro-only",
        "--out",
        s(&cal),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let fit = load(&cal);
    assert!(
        fit["accel"].get("temperature").is_none(),
        "accelerometer untouched"
    );
    assert_eq!(
        fit["fit"]["gyro"]["bias_order"].as_integer(),
        Some(3),
        "a ramp: the cubic"
    );
    assert!(text(&o.stdout).contains("accelerometer: not fitted (--gyro-only)"));

    // No temperature channel, and a temperature that is not a number.
    let text_of = std::fs::read_to_string(&narrow).unwrap();
    let strip = |line: &str| line.rsplit_once(',').unwrap().0.to_string();
    let no_temp: Vec<String> = text_of.lines().map(strip).collect();
    let no_temp_path = d.join("no-temp.csv");
    std::fs::write(&no_temp_path, no_temp.join("\n")).unwrap();
    refused(&d, &[&no_temp_path], &[], "no temperature column `temp`");
    let mut lines: Vec<String> = text_of.lines().map(String::from).collect();
    lines[100] = format!("{},NaN", strip(&lines[100]));
    let nan_path = d.join("nan.csv");
    std::fs::write(&nan_path, lines.join("\n")).unwrap();
    refused(
        &d,
        &[&nan_path],
        &[],
        "line 101, column 8 (temp): `NaN` is not a finite number",
    );
}
