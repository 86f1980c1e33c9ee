//! `triad allan` on records whose noise cannot be fitted honestly: a dead
//! or constant channel, a τ grid too short for the fit, a value whose
//! square overflows.

mod common;

use std::path::PathBuf;

use common::{allan, tmp};

/// A CSV `t,gx,gy,gz` at 100 Hz: gx all zero, gy constant 0.1, gz noise
/// (a fixed pseudo-random sequence), `big` written into gz at row `big_row`.
fn record(name: &str, rows: usize, big: Option<(usize, &str)>) -> PathBuf {
    let mut text = String::from("t,gx,gy,gz\n");
    let mut state = 12345u64;
    for i in 0..rows {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let noise = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e-3;
        let gz = match big {
            Some((row, value)) if row == i => value.to_string(),
            _ => noise.to_string(),
        };
        text += &format!("{},0,0.1,{gz}\n", i as f64 / 100.0);
    }
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn dead_and_constant_channels_have_no_noise_and_no_grade() {
    let input = record("dead.csv", 20_000, None);
    let o = allan(&input, &["--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for c in 0..2 {
        let col = &v["columns"][c];
        assert_eq!(col["no_fit"]["reason"], "no noise detected", "{col}");
        assert!(col["grade"].is_null() && col["fit"].is_null());
    }
    // The noisy column is fitted and graded.
    assert!(v["columns"][2]["grade"]["grade"].is_string());
    let o = allan(&input, &["--columns", "gx"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("no noise detected"), "{text}");
    assert!(!text.contains("grade:"), "{text}");
}

#[test]
fn a_fit_from_too_few_tau_points_is_refused_with_the_count() {
    let input = record("short-grid.csv", 20_000, None);
    // --max-tau 0.02 s at 100 Hz: m = 1, 2.
    let o = allan(&input, &["--columns", "gz", "--max-tau", "0.02", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let col = &v["columns"][0];
    assert_eq!(col["no_fit"]["reason"], "too few tau points");
    assert_eq!(col["no_fit"]["points"], 2);
    assert_eq!(col["no_fit"]["needed"], 6);
    assert!(col["grade"].is_null() && col["terms"] == serde_json::json!({}));
    let o = allan(&input, &["--columns", "gz", "--max-tau", "0.02"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("2 octave tau points"), "{text}");
}

#[test]
fn a_value_whose_square_overflows_is_refused_with_its_line() {
    let input = record("huge.csv", 6000, Some((5000, "1e308")));
    let o = allan(&input, &["--columns", "gz"]);
    assert!(!o.status.success());
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    for needle in ["line 5002", "column gz", "1e308", "too large"] {
        assert!(err.contains(needle), "{needle} in {err}");
    }
    assert!(!err.contains("NaN"), "{err}");
}
