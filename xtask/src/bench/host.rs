//! Host figures: the same variants timed on this machine by criterion
//! (host/benches/model.rs, a release build: xtask itself is built without
//! full optimisation, so it must not time anything), read back from
//! criterion's estimates.

use anyhow::{Context, Result};
use triad_bench::{Variant, BATCH, BATCHES};

use crate::cmd::{cargo, check, host_target_dir};

/// Seconds of `triad calib fit imu`'s whole fit on a 10-minute 400 Hz
/// hand-pose record (host/benches/fit_imu.rs; criterion's mean).
pub fn fit_imu_seconds() -> Result<f64> {
    run_criterion("fit_imu", "10", "the fit imu benchmark (criterion)")?;
    let path = host_target_dir().join("criterion/fit_imu/hand_10min_400hz/new/estimates.json");
    Ok(mean_ns(&path)? * 1e-9)
}

/// Seconds of `triad calib fit thermal`'s whole fit on three hand-turned
/// soaks (host/benches/fit_thermal.rs; criterion's mean).
pub fn fit_thermal_seconds() -> Result<f64> {
    run_criterion("fit_thermal", "5", "the fit thermal benchmark (criterion)")?;
    let path =
        host_target_dir().join("criterion/fit_thermal/whole_3_soaks_100hz/new/estimates.json");
    Ok(mean_ns(&path)? * 1e-9)
}

/// Runs host/benches/`bench`.rs (1 s warm-up, `seconds` measuring);
/// `what` names it in an error.
fn run_criterion(bench: &str, seconds: &str, what: &str) -> Result<()> {
    let mut command = cargo();
    command.args([
        "bench",
        "--quiet",
        "-p",
        "triad-host",
        "--bench",
        bench,
        "--",
        "--warm-up-time",
        "1",
        "--measurement-time",
        seconds,
    ]);
    // Criterion's progress goes to stderr (check): stdout carries the table or the JSON.
    check(command, what)
}

/// Criterion's mean (ns) from its estimates file at `path`.
fn mean_ns(path: &std::path::Path) -> Result<f64> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let estimates: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    estimates["mean"]["point_estimate"]
        .as_f64()
        .with_context(|| format!("no mean.point_estimate in {}", path.display()))
}

/// Nanoseconds per 6-axis sample on the host, per variant (criterion's mean).
pub fn measure() -> Result<Vec<(Variant, f64)>> {
    run_criterion("model", "2", "the host benchmark (criterion)")?;
    Variant::ALL
        .into_iter()
        .map(|variant| {
            let path = host_target_dir()
                .join("criterion/model")
                .join(variant.name())
                .join("new/estimates.json");
            let ns = mean_ns(&path)?;
            Ok((variant, ns / (BATCH * BATCHES) as f64))
        })
        .collect()
}
