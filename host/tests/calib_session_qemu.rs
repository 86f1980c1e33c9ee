//! End to end on the emulated board: `triad calib session` against the
//! firmware on QEMU (`xtask serve --deterministic`) whose chip model plays
//! a simulated unit (its turn-on errors and noise) turned by hand between
//! static poses (scenes/scripts/hand-session.toml, 12 poses of 3 s with
//! 1.5 s turns, repeating). The whole loop: raw stream → live poses → the
//! rig-free fit → upload → save → corrected stream verified on fresh
//! poses; the fitted calibration against the unit's true one
//! (`triad sim --truth-calib`), put in the fit's frame
//! (`accel_frame::in_accel_frame`); and a user who declines uploads nothing.
//!
//! Run by `cargo xtask test` (it sets TRIAD_SERVE_XTASK, TRIAD_SERVE_ELF,
//! and the unit, script and record seed the firmware plays in
//! TRIAD_SESSION_UNIT, TRIAD_SESSION_SCRIPT, TRIAD_SESSION_SEED); ignored
//! in a plain `cargo test`. It takes about a minute here: each session
//! records some 60 s of the board's time, which the deterministic clock
//! runs faster than real time on an idle core.

// Shared with device_qemu.rs, which uses the parts this test does not.
#[allow(dead_code)]
mod served_board;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use served_board::{test_dir, text, Clock, ServedBoard};
use triad::model::matrix::Mat3;
use triad_host::calib::file::{self as calib_file, CalibFile};
use triad_lab::calib_fit::accel_frame::in_accel_frame;
use triad_lab::student_t;

fn env(name: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| panic!("{name} is set by cargo xtask test"))
}

/// `triad calib session --port PORT ARGS` with `stdin` as the user's
/// answer. A stream counts as stopped after 30 s without a frame (not the
/// default 5 s): QEMU shares the machine with the whole test suite.
fn session(board: &ServedBoard, args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_triad"))
        .args([
            "calib",
            "session",
            "--port",
            board.port(),
            "--stall-s",
            "30",
        ])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run triad calib session");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

/// The unit's true calibration, as `triad sim --truth-calib` writes it.
fn truth(d: &Path) -> CalibFile {
    let path = d.join("truth.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_triad"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["sim", "--unit", &env("TRIAD_SESSION_UNIT")])
        .args(["--script", &env("TRIAD_SESSION_SCRIPT")])
        .args(["--record-seed", &env("TRIAD_SESSION_SEED")])
        .arg("--truth-calib")
        .arg(&path)
        .arg("--out")
        .arg(d.join("truth-record.csv"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    calib_file::load(&path).unwrap()
}

/// A `[fit.TRIAD]` key as a matrix (a vector is one row).
fn fit_rows(file: &CalibFile, triad: &str, key: &str) -> Vec<Vec<f64>> {
    let value = &file.fit[triad][key];
    let number = |v: &toml::Value| v.as_float().unwrap();
    match value.as_array().unwrap()[0].as_array() {
        Some(_) => value
            .as_array()
            .unwrap()
            .iter()
            .map(|row| row.as_array().unwrap().iter().map(number).collect())
            .collect(),
        None => vec![value.as_array().unwrap().iter().map(number).collect()],
    }
}

/// The k with P(|t| ≤ k) = `p` for Student-t with `dof` degrees of freedom.
fn t_quantile(p: f64, dof: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1e3);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_t::coverage(mid, dof) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Each of `fitted`'s entries (rows of `fitted`, σ's `sigma`) within
/// k·σ of `truth`, k the Student-t quantile at the fit's degrees of
/// freedom for a family-wise level of 1 % over `entries` entries
/// (Bonferroni); the worst |error|/σ.
fn within_sigmas(
    what: &str,
    fitted: &[Vec<f64>],
    truth: &[Vec<f64>],
    sigma: &[Vec<f64>],
    k: f64,
) -> f64 {
    let mut worst = 0.0f64;
    for (i, ((f, t), s)) in fitted.iter().zip(truth).zip(sigma).enumerate() {
        for j in 0..f.len() {
            if s[j] == 0.0 {
                continue; // fixed by the convention (the accelerometer's lower triangle)
            }
            let z = (f[j] - t[j]).abs() / s[j];
            worst = worst.max(z);
            assert!(
                z <= k,
                "{what}[{i}][{j}]: fitted {} truth {} σ {} ({z:.1} σ > {k:.1})",
                f[j],
                t[j],
                s[j]
            );
        }
    }
    worst
}

fn rows(m: &Mat3) -> Vec<Vec<f64>> {
    m.iter().map(|r| r.to_vec()).collect()
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_declined_session_uploads_nothing_and_a_confirmed_one_matches_the_units_truth() {
    let d = test_dir("session");
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    let info = board.device_ok(&["info"]);
    let built_in = info
        .lines()
        .find(|l| l.starts_with("calibration: "))
        .unwrap()
        .to_string();

    // Declined: the fit is shown, nothing reaches the device.
    let declined = d.join("declined.toml");
    let out = session(
        &board,
        &["--poses", "12", "--out", declined.to_str().unwrap()],
        "n\n",
    );
    let stdout = text(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{stdout}\n{}",
        text(&out.stderr)
    );
    assert!(
        stdout.contains("rig-free fit of the session on"),
        "{stdout}"
    );
    assert!(stdout.contains("declined: nothing uploaded"), "{stdout}");
    let after = board.device_ok(&["info"]);
    assert!(
        after.lines().any(|l| l == built_in),
        "{built_in:?} in\n{after}"
    );
    assert!(after.contains("stored: empty"), "{after}");

    // Confirmed: fit, upload, save, verify.
    let cal = d.join("cal.toml");
    let record = d.join("record.csv");
    let out = session(
        &board,
        &[
            "--yes",
            "--poses",
            "16",
            "--out",
            cal.to_str().unwrap(),
            "--record",
            record.to_str().unwrap(),
        ],
        "",
    );
    let stdout = text(&out.stdout);
    let stderr = text(&out.stderr);
    println!("{stdout}");
    assert!(out.status.success(), "{stdout}\n{stderr}\n{}", board.log());
    assert!(stdout.contains("verdict: PASS"), "{stdout}");
    let fitted = calib_file::load(&cal).unwrap();
    let id = format!("{:#010x}", fitted.calibration.id);
    assert!(
        stdout.contains(&format!("uploaded calibration {id}, saved it")),
        "{stdout}"
    );
    let info = board.device_ok(&["info"]);
    assert!(info.contains(&format!("calibration: {id}")), "{info}");
    assert!(!info.contains("stored: empty"), "{info}");

    // The record the session kept refits to the same calibration.
    let refit = d.join("refit.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_triad"))
        .args(["calib", "fit", "imu", "--min-static", "1", "--positions"])
        .arg(&record)
        .arg("--out")
        .arg(&refit)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let refit = calib_file::load(&refit).unwrap();
    assert_eq!(refit.calibration.accel, fitted.calibration.accel);
    assert_eq!(refit.calibration.gyro, fitted.calibration.gyro);

    // Against the unit's truth, in the fit's frame (the accelerometer's
    // upper triangular corrected axes). Every fitted entry within k·σ,
    // k from Student-t at the fit's degrees of freedom with a 1 %
    // family-wise level over the 6 + 3 + 9 + 3 free entries. The σ's
    // leave out what the fit cannot see (the chip's output LSB, averaged
    // over thousands of samples per pose, and the accelerometer fit's
    // error carried into the gyro's is in them), so k is not widened.
    let truth = truth(&d);
    let (ta, ba) = truth.calibration.accel.at_temperature(25.0);
    let (tg, bg) = truth.calibration.gyro.at_temperature(25.0);
    let frame = in_accel_frame(&ta, &tg).expect("the truth's accelerometer is regular");
    let p = 1.0 - 0.01 / 21.0;
    for (triad, truth_m, truth_b) in [("accel", frame.accel, ba), ("gyro", frame.gyro, bg)] {
        let c = match triad {
            "accel" => fitted.calibration.accel,
            _ => fitted.calibration.gyro,
        };
        let dof = fitted.fit[triad]["degrees_of_freedom"]
            .as_integer()
            .unwrap() as f64;
        let k = t_quantile(p, dof);
        let m = within_sigmas(
            triad,
            &rows(&c.scale_misalignment),
            &rows(&truth_m),
            &fit_rows(&fitted, triad, "sigma_scale_misalignment"),
            k,
        );
        let b = within_sigmas(
            triad,
            &[c.bias.to_vec()],
            &[truth_b.to_vec()],
            &fit_rows(&fitted, triad, "sigma_bias"),
            k,
        );
        println!("{triad}: worst (I+Σ) error {m:.2} σ, bias {b:.2} σ (bound {k:.1} σ at {dof} degrees of freedom)");
    }
}
