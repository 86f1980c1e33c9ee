//! Installs what is missing: the rustup targets and, for the emulated board,
//! qemu-system-arm (Debian package; needs root or sudo).

use crate::board::Board;
use anyhow::{bail, Context, Result};
use std::process::Command;

/// The Rust targets the project builds for: Cortex-M4F boards and the
/// Cortex-M0 benchmark core.
const TARGETS: [&str; 2] = ["thumbv7em-none-eabihf", "thumbv6m-none-eabi"];

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
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .context("running `rustup target list --installed` (is rustup on PATH?)")?;
    let installed = String::from_utf8_lossy(&installed.stdout);
    let missing: Vec<&str> = TARGETS
        .iter()
        .copied()
        .filter(|t| !installed.lines().any(|l| l.trim() == *t))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    eprintln!("xtask: installing rustup targets {}", missing.join(", "));
    // Install logs go to stderr: `cargo xtask run`'s stdout is the CSV.
    let status = Command::new("rustup")
        .args(["target", "add"])
        .args(&missing)
        .stdout(std::io::stderr())
        .status()?;
    if !status.success() {
        bail!(
            "`rustup target add {}` failed ({status})",
            missing.join(" ")
        );
    }
    Ok(())
}

/// The QEMU binary the emulated board runs on.
pub const QEMU: &str = "qemu-system-arm";

fn ensure_qemu() -> Result<()> {
    if Command::new(QEMU).arg("--version").output().is_ok() {
        return Ok(());
    }
    eprintln!("xtask: {QEMU} not found; installing the Debian package qemu-system-arm");
    let root = Command::new("id")
        .arg("-u")
        .output()
        .map(|o| o.stdout == b"0\n")
        .unwrap_or(false);
    let sudo: &[&str] = if root { &[] } else { &["sudo"] };
    for args in [
        &["apt-get", "update"][..],
        &[
            "apt-get",
            "install",
            "-y",
            "--no-install-recommends",
            "qemu-system-arm",
        ][..],
    ] {
        let mut command = Command::new(sudo.first().copied().unwrap_or(args[0]));
        command
            .args(sudo.iter().skip(1))
            .args(if root { &args[1..] } else { args });
        command.env("DEBIAN_FRONTEND", "noninteractive");
        // apt's log goes to stderr: `cargo xtask run`'s stdout is the CSV.
        command.stdout(std::io::stderr());
        let status = command
            .status()
            .with_context(|| format!("running {}", args.join(" ")))?;
        if !status.success() {
            bail!(
                "`{}` failed ({status}); install QEMU 7.2 or later (qemu-system-arm) by hand",
                args.join(" ")
            );
        }
    }
    Command::new(QEMU)
        .arg("--version")
        .output()
        .context("qemu-system-arm still not runnable")?;
    Ok(())
}
