//! The checks of the crates that only build for the embedded targets: clippy
//! on the firmware of every board × bus (and chip model) (and with a simulated scene),
//! on the benchmark firmware for both cores and on the example of a user's
//! own firmware, whose dependency tree must hold only the core.

use crate::bench::{bench_cargo, Core};
use crate::board::{Board, Firmware};
use crate::cmd::{cargo, check, firmware_cargo, root};
use anyhow::{bail, Context, Result};
use std::path::Path;

/// The example crate of a user's own firmware (examples/user-firmware).
const EXAMPLE: &str = "triad-example-user-firmware";
/// What the example must not pull in: the RTIC runtime, a PAC or HAL, the
/// simulator (and any board: [`Board::all`]).
const NOT_IN_EXAMPLE: [&str; 5] = [
    "rtic",
    "cortex-m-rt",
    "stm32f4",
    "stm32f4xx-hal",
    "triad-sim",
];

/// `cargo clippy -- -D warnings` on `firmware`, as it is built (its board's
/// target dir, the calibration blob, the scene blob).
pub fn clippy_firmware(
    firmware: Firmware,
    calibration: &Path,
    scene_blob: Option<&Path>,
) -> Result<()> {
    let mut command = firmware_cargo("clippy", firmware, calibration, scene_blob);
    command.args(["--", "-D", "warnings"]);
    check(
        command,
        &format!(
            "cargo clippy on the firmware for {}{}",
            firmware.label(),
            if scene_blob.is_some() {
                " with a scene"
            } else {
                ""
            }
        ),
    )
}

/// Clippy on the benchmark firmware for both emulated cores.
pub fn clippy_bench_firmware() -> Result<()> {
    for core in Core::ALL {
        let mut command = bench_cargo("clippy", core);
        command.args(["--", "-D", "warnings"]);
        check(
            command,
            &format!("cargo clippy on the benchmark firmware ({})", core.name()),
        )?;
    }
    Ok(())
}

/// The example builds for the Cortex-M4F, clippy-clean, and `cargo tree`
/// shows none of [`NOT_IN_EXAMPLE`].
pub fn check_example() -> Result<()> {
    let target = "thumbv7em-none-eabihf";
    let dir = root().join("target/example");
    let mut command = cargo();
    command
        .args(["clippy", "--quiet", "-p", EXAMPLE, "--target", target])
        .args(["--", "-D", "warnings"])
        .env("CARGO_TARGET_DIR", &dir);
    check(command, "cargo clippy on the user-firmware example")?;
    let mut command = cargo();
    command
        .args([
            "build",
            "--quiet",
            "--release",
            "-p",
            EXAMPLE,
            "--target",
            target,
        ])
        .env(crate::cmd::EMBEDDED_PANIC.0, crate::cmd::EMBEDDED_PANIC.1)
        .env("CARGO_TARGET_DIR", &dir);
    check(command, "building the user-firmware example")?;
    let tree = cargo()
        .args(["tree", "-p", EXAMPLE, "--target", target, "-e", "normal"])
        .args(["--prefix", "none", "--format", "{p}"])
        .output()
        .context("running cargo tree")?;
    if !tree.status.success() {
        bail!("cargo tree -p {EXAMPLE} failed ({})", tree.status);
    }
    let tree = String::from_utf8_lossy(&tree.stdout);
    let crates: Vec<&str> = tree
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .collect();
    let boards: Vec<String> = Board::all().iter().map(|b| b.package()).collect();
    let pulled: Vec<&str> = NOT_IN_EXAMPLE
        .iter()
        .copied()
        .chain(boards.iter().map(String::as_str))
        .filter(|name| crates.contains(name))
        .collect();
    if !pulled.is_empty() {
        bail!("the user-firmware example pulls in {}", pulled.join(", "));
    }
    let mut unique: Vec<&str> = crates;
    unique.sort_unstable();
    unique.dedup();
    note!(
        "xtask: the user-firmware example depends on {}",
        unique.join(", ")
    );
    Ok(())
}

/// `cargo doc --no-deps` of the libraries, warnings denied.
pub fn docs() -> Result<()> {
    let mut command = cargo();
    command
        .args(["doc", "--quiet", "--no-deps"])
        .args(["-p", "triad", "-p", "triad-sim", "-p", "triad-lab"])
        .env("RUSTDOCFLAGS", "-D warnings");
    check(command, "cargo doc of the core, sim and lab crates")
}
