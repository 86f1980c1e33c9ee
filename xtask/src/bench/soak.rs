//! `cargo xtask bench --soak`: the emulated board for hours of device time
//! under command storms and hourly sensor faults (host/examples/bench_soak.rs,
//! release): figures and checks on stderr, a failed check fails the run.

use crate::board::{Board, Firmware};
use crate::{cmd, setup};
use anyhow::Result;

/// Runs the soak for `seconds` of device time (or until `wall_seconds` of
/// wall time, when given), a fault every `fault_every` seconds (3600 in
/// the soak), the chip's FIFO watermark `watermark` (1: no FIFO).
pub fn run(
    seconds: f64,
    fault_every: f64,
    wall_seconds: Option<f64>,
    watermark: u16,
) -> Result<()> {
    setup::ensure_for(Board::emulated())?;
    let triad = cmd::build_host_tool()?;
    let calibration = cmd::pack_calibration(&triad, None)?;
    let mut firmware = Firmware::default_emulated();
    firmware.sampling.watermark = (watermark > 1).then_some(watermark);
    let elf = cmd::build_firmware(firmware, &calibration)?;
    let xtask = cmd::serving_xtask()?;
    note!(
        "xtask: the soak: {seconds} s of device time on the emulated board ({}), a sensor fault \
         every {fault_every} s, a command storm every 5 s (host/examples/bench_soak.rs)",
        firmware.label()
    );
    let mut command = cmd::cargo();
    command
        .args(["run", "--quiet", "--release", "-p", "triad-host"])
        .args(["--example", "bench_soak"])
        .env("TRIAD_SOAK_XTASK", xtask)
        .env("TRIAD_SOAK_ELF", elf)
        .env("TRIAD_SOAK_BLOB", calibration)
        .env("TRIAD_SOAK_SECONDS", seconds.to_string())
        .env("TRIAD_SOAK_FAULT_EVERY", fault_every.to_string())
        .env("TRIAD_SOAK_DIR", cmd::root().join("target/soak"));
    if let Some(wall) = wall_seconds {
        command.env("TRIAD_SOAK_WALL_SECONDS", wall.to_string());
    }
    cmd::check(command, "the soak (bench_soak)")
}
