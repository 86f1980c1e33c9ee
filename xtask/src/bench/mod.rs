//! `cargo xtask bench`: the benchmark firmware (bench/src/bin/bench.rs) on two
//! emulated cores, its digests checked against the host's computation of
//! the same variants, the accuracy of each variant against the f64
//! reference, and the report (docs/BENCHMARKS.md, or JSON on stdout).

mod accuracy;
pub mod allan;
mod command_report;
mod commands;
mod cores;
mod fuzz_afl;
mod high_resolution;
mod host;
mod plot;
mod report;
pub mod soak;
mod whole_firmware;
mod whole_firmware_report;

pub use cores::{bench_cargo, check_firmware_outputs, Core};

use anyhow::Result;
use triad_bench::Variant;

/// The whole firmware's measurements alone, printed as their section.
pub fn run_whole_firmware() -> Result<()> {
    let triad = crate::cmd::build_host_tool()?;
    let calibration = crate::cmd::pack_calibration(&triad, None)?;
    let rows = whole_firmware::measure(&triad, &calibration)?;
    let long_run = whole_firmware::long_run(&triad, &calibration)?;
    print!(
        "{}",
        whole_firmware_report::markdown(&rows, &long_run, None)
    );
    Ok(())
}

/// One build of the whole firmware (`--rate R --watermark W`, with
/// `--high-resolution` the ICM-42688-P's 20-bit FIFO): its row on stdout;
/// with the 20-bit FIFO the noise floors of both formats too.
pub fn run_whole_firmware_one(rate_hz: u32, watermark: u16, high_resolution: bool) -> Result<()> {
    let triad = crate::cmd::build_host_tool()?;
    let calibration = crate::cmd::pack_calibration(&triad, None)?;
    let row =
        whole_firmware::measure_single(&triad, &calibration, rate_hz, watermark, high_resolution)?;
    print!("{}", whole_firmware_report::rows_only(&[row]));
    if high_resolution {
        print!(
            "\n{}",
            high_resolution::markdown(&high_resolution::measure_both()?)
        );
    }
    Ok(())
}

/// The long mutation run of every parser that takes outside bytes
/// (fuzz/examples/bench_fuzz.rs, release): its figures on stderr; then the
/// coverage-guided runs of fuzz/'s targets under AFL++ ([`fuzz_afl`]).
pub fn run_fuzz(mutations: u64, afl_seconds: u64) -> Result<()> {
    let mut command = crate::cmd::cargo();
    command
        .args([
            "run",
            "--quiet",
            "--release",
            "-p",
            "triad-fuzz",
            "--example",
            "bench_fuzz",
            "--",
        ])
        .arg(mutations.to_string());
    crate::cmd::check(command, "the parsers' mutation run (bench_fuzz)")?;
    fuzz_afl::run(afl_seconds)
}

/// How long AFL++ fuzzes each target of fuzz/ in the benchmark.
pub const AFL_SECONDS: u64 = 600;
/// Inputs per parser of the mutation run in the benchmark (issue 26: ≥ 10⁷).
pub const MUTATIONS: u64 = 10_000_000;

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
pub fn run(json: bool, mutations: u64, afl_seconds: u64) -> Result<()> {
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
    run_fuzz(mutations, afl_seconds)?;
    let fit_imu_s = host::fit_imu_seconds()?;
    let fit_thermal_s = host::fit_thermal_seconds()?;
    let triad = crate::cmd::build_host_tool()?;
    let calibration = crate::cmd::pack_calibration(&triad, None)?;
    let firmware_rows = whole_firmware::measure(&triad, &calibration)?;
    let long_run = whole_firmware::long_run(&triad, &calibration)?;
    // Flash and RAM of each board and bus: docs/FIRMWARE_SIZE.md.
    crate::size::run()?;
    let fusion = rows
        .iter()
        .find(|r| r.core == Core::CortexM4F && r.variant.name() == "fusion_f32")
        .map(|r| r.instructions_per_sample);
    if json {
        println!("{}", report::json(&rows));
    } else {
        print!("{}", report::table(&rows));
    }
    let docs = crate::cmd::root().join("docs");
    let svg = plot::svg(&rows).map_err(|e| anyhow::anyhow!("plotting: {e}"))?;
    std::fs::write(docs.join("benchmarks.svg"), svg)?;
    let mut markdown = report::markdown(&rows, &command_rows, &host)?;
    markdown += "\n";
    markdown += &whole_firmware_report::markdown(&firmware_rows, &long_run, fusion);
    markdown += "\n";
    markdown += &high_resolution::markdown(&high_resolution::measure_both()?);
    markdown += "\n";
    markdown += "\n## Flash and RAM\n\nEach board with each bus: docs/FIRMWARE_SIZE.md, rewritten by this run (`cargo xtask size` alone).\n";
    markdown += &format!(
        "\n## The lab on the host\n\n`triad calib fit imu`'s whole fit (detection, accelerometer, moves, gyro) on a \
         10-minute 400 Hz hand-pose record (109 poses, 240 000 samples; `cargo bench -p triad-host --bench \
         fit_imu`, criterion's mean): {fit_imu_s:.2} s (goal ≤ 1 s).\n\n\
         `triad calib fit thermal`'s whole fit (detection, segments cut by temperature, the accelerometer's \
         thermal fit, the gyro's bias polynomial and its (I+Σ) against temperature) on three hand-turned soaks \
         at −10, 25 and 60 °C (14 poses each at 100 Hz; `cargo bench -p triad-host --bench fit_thermal`, \
         criterion's mean): {:.1} ms.\n",
        fit_thermal_s * 1e3
    );
    markdown += &allan::section(true)?;
    std::fs::write(docs.join("BENCHMARKS.md"), markdown)?;
    note!("xtask: wrote docs/BENCHMARKS.md and docs/benchmarks.svg");
    Ok(())
}
