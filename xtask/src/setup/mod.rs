//! Installs what is missing: the rustup targets and, for the emulated board,
//! qemu-system-arm (Debian's package, through [`apt`]).
//!
//! Every step says what it installs and why before it starts, and sends the
//! installers' output to stderr: `cargo xtask run`'s stdout is the CSV. An
//! install never removes or downgrades a package the machine has, and one that
//! needs root it cannot get says the exact command to run instead.

mod apt;
mod privilege;

use crate::board::Board;
use crate::cmd::{check, runs};
use anyhow::{bail, Result};
use std::process::{Command, Stdio};

/// The Rust targets the project builds for, and what each is for.
const TARGETS: [(&str, &str); 2] = [
    ("thumbv7em-none-eabihf", "the Cortex-M4F boards' firmware"),
    ("thumbv6m-none-eabi", "the benchmark's Cortex-M0 core"),
];

/// The QEMU binary the emulated board runs on.
pub const QEMU: &str = "qemu-system-arm";

/// The Debian package that has [`QEMU`].
const QEMU_PACKAGE: &str = "qemu-system-arm";

/// Everything: targets and QEMU.
pub fn ensure_all() -> Result<()> {
    ensure_targets()?;
    ensure_qemu()
}

/// What running on `board` needs.
pub fn ensure_for(board: Board) -> Result<()> {
    ensure_targets()?;
    if board == Board::Qemu {
        ensure_qemu()?;
    }
    Ok(())
}

fn ensure_targets() -> Result<()> {
    let listed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .stderr(Stdio::inherit())
        .output();
    let Ok(listed) = listed else {
        bail!(
            "rustup is not on PATH: the firmware builds need the Rust targets {}; \
             install rustup, or add these targets to your toolchain another way",
            TARGETS.map(|(t, _)| t).join(" and ")
        );
    };
    let installed = String::from_utf8_lossy(&listed.stdout);
    let missing: Vec<(&str, &str)> = TARGETS
        .into_iter()
        .filter(|(t, _)| !installed.lines().any(|l| l.trim() == *t))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let names: Vec<&str> = missing.iter().map(|(t, _)| *t).collect();
    let command = format!("rustup target add {}", names.join(" "));
    eprintln!(
        "xtask: installing the Rust targets {} with `{command}` (into the active toolchain; \
         no root needed, nothing removed)",
        missing
            .iter()
            .map(|(t, why)| format!("{t} ({why})"))
            .collect::<Vec<_>>()
            .join(" and ")
    );
    let mut add = Command::new("rustup");
    add.args(["target", "add"]).args(&names);
    check(add, &format!("`{command}`"))
}

fn ensure_qemu() -> Result<()> {
    if runs(QEMU) {
        return Ok(());
    }
    eprintln!(
        "xtask: {QEMU} is not on PATH; the emulated board (QEMU's netduinoplus2) runs on it. \
         Installing the Debian package {QEMU_PACKAGE} with apt-get (without recommended \
         packages; nothing installed is removed or downgraded)"
    );
    apt::install(QEMU_PACKAGE)?;
    if !runs(QEMU) {
        bail!(
            "apt-get installed {QEMU_PACKAGE} but `{QEMU} --version` still does not run: \
             put QEMU 7.2 or later on PATH"
        );
    }
    Ok(())
}
