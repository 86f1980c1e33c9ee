//! `cargo xtask bench`: the benchmark firmware (bench/src/bin/bench.rs) on two
//! emulated cores, its digests checked against the host's computation of
//! the same variants, the accuracy of each variant against the f64
//! reference, and the report (docs/BENCHMARKS.md, or JSON on stdout).

mod accuracy;
mod command_report;
mod commands;
mod cores;
mod host;
mod plot;
mod report;

pub use cores::{bench_cargo, check_firmware_outputs, Core};

use anyhow::Result;
use triad_bench::Variant;

/// One row of the report: a variant on a core.
#[derive(Clone, Debug)]
pub struct Row {
    /// The emulated core.
    pub core: Core,
    /// The variant.
    pub variant: Variant,
    /// Instructions per 6-axis sample.
    pub instructions_per_sample: f64,
    /// Bytes of the variant's kernel function in flash.
    pub flash_bytes: Option<u64>,
    /// The kernel's stack high-water mark, bytes.
    pub stack_bytes: u32,
    /// Accuracy against the f64 reference, realistic calibration.
    pub realistic: Option<accuracy::Accuracy>,
    /// Accuracy against the f64 reference, extreme valid calibration.
    pub extreme: Option<accuracy::Accuracy>,
}

/// Runs the benchmark; prints JSON rows when `json`, else a table; writes
/// docs/BENCHMARKS.md either way.
pub fn run(json: bool) -> Result<()> {
    let mut rows = Vec::new();
    let mut command_rows = Vec::new();
    let accuracies = accuracy::all()?;
    for core in Core::ALL {
        let (measured, commands) = cores::measure(core)?;
        command_rows.extend(commands);
        for m in measured {
            let (realistic, extreme) = accuracies
                .iter()
                .find(|(v, _, _)| *v == m.variant)
                .map(|(_, r, e)| (*r, *e))
                .unwrap_or((None, None));
            rows.push(Row {
                core,
                variant: m.variant,
                instructions_per_sample: m.instructions_per_sample,
                flash_bytes: m.flash_bytes,
                stack_bytes: m.stack_bytes,
                realistic,
                extreme,
            });
        }
    }
    let host = host::measure()?;
    if json {
        println!("{}", report::json(&rows));
    } else {
        print!("{}", report::table(&rows));
    }
    let docs = crate::cmd::root().join("docs");
    let svg = plot::svg(&rows).map_err(|e| anyhow::anyhow!("plotting: {e}"))?;
    std::fs::write(docs.join("benchmarks.svg"), svg)?;
    std::fs::write(
        docs.join("BENCHMARKS.md"),
        report::markdown(&rows, &command_rows, &host)?,
    )?;
    eprintln!("xtask: wrote docs/BENCHMARKS.md and docs/benchmarks.svg");
    Ok(())
}
