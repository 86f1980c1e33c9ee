//! Host figures: the same variants timed on this machine by the release
//! build of host/examples/bench_model.rs (xtask itself is built without
//! full optimisation, so it must not time anything).

use anyhow::{Context, Result};
use triad::bench::Variant;

use crate::cmd::cargo;

/// Nanoseconds per 6-axis sample on the host, per variant.
pub fn measure() -> Result<Vec<(Variant, f64)>> {
    let mut command = cargo();
    command.args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "triad-host",
        "--example",
        "bench_model",
        "--",
        "--json",
    ]);
    let output = command.output().context("running the host benchmark")?;
    anyhow::ensure!(
        output.status.success(),
        "the host benchmark failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows: Vec<serde_json::Value> =
        serde_json::from_slice(&output.stdout).context("the host benchmark's JSON")?;
    rows.iter()
        .map(|r| {
            let name = r["variant"].as_str().context("variant name")?;
            let variant = Variant::from_name(name)
                .with_context(|| format!("unknown variant {name:?} from the host benchmark"))?;
            let ns = r["ns_per_sample"].as_f64().context("ns_per_sample")?;
            Ok((variant, ns))
        })
        .collect()
}
