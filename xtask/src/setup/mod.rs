//! Installs what is missing: the rustup targets and, for the emulated board,
//! qemu-system-arm 7.2 or later: Debian's package through [`apt`], or, where
//! installing it would remove or downgrade a package, that package unpacked
//! into the workspace's `target/` ([`qemu_unpacked`]).
//!
//! Every step says what it installs and why before it starts, and sends the
//! installers' output to stderr: `cargo xtask run`'s stdout is the CSV. An
//! install never removes or downgrades a package the machine has, and one that
//! needs root it cannot get says the exact command to run instead.

mod apt;
mod apt_cache;
mod depends;
mod privilege;
pub mod python_peers;
mod qemu_binary;
mod qemu_unpacked;

use crate::board::Board;
use crate::cmd::check;
use anyhow::{bail, Result};
use apt::Plan;
use qemu_binary::NAME as QEMU_PACKAGE;
use std::process::{Command, Stdio};

/// The Rust targets the project builds for, and what each is for.
const TARGETS: [(&str, &str); 2] = [
    ("thumbv7em-none-eabihf", "the Cortex-M4F boards' firmware"),
    ("thumbv6m-none-eabi", "the benchmark's Cortex-M0 core"),
];

pub use qemu_binary::qemu;

/// Everything: targets and QEMU.
pub fn ensure_all() -> Result<()> {
    ensure_targets()?;
    ensure_qemu()
}

/// What running on `board` needs.
pub fn ensure_for(board: Board) -> Result<()> {
    ensure_targets()?;
    if board.is_emulated() {
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
    note!(
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

/// How QEMU gets onto this machine, from apt-get's plan for the package.
#[derive(Debug, PartialEq, Eq)]
enum Route {
    /// `apt-get install` it: the plan harms nothing.
    Install,
    /// The plan would remove or downgrade: unpack the package instead.
    Unpack,
}

impl Route {
    fn from_plan(plan: &Plan) -> Route {
        if plan.harms() {
            Route::Unpack
        } else {
            Route::Install
        }
    }
}

fn ensure_qemu() -> Result<()> {
    if qemu_binary::find().is_some() {
        return Ok(());
    }
    let (major, minor) = qemu_binary::MINIMUM;
    note!(
        "xtask: no QEMU {major}.{minor} or later: {QEMU_PACKAGE} is neither on PATH nor unpacked \
         in {}; the emulated board (QEMU's netduinoplus2) runs on it. Asking apt-get how it would \
         install the Debian package {QEMU_PACKAGE} (without recommended packages; nothing \
         installed is removed or downgraded)",
        qemu_binary::cache_dir().display()
    );
    apt::require(QEMU_PACKAGE)?;
    let privilege = privilege::detect();
    if let Ok(privilege) = privilege {
        apt::update(privilege)?;
    }
    let plan = match apt::simulate(&[QEMU_PACKAGE]) {
        Ok(plan) => plan,
        // Without root the package lists may be missing or stale: updating first may help.
        Err(error) => match privilege {
            Ok(_) => return Err(error),
            Err(refusal) => return Err(apt::needs_root(refusal, &[QEMU_PACKAGE])),
        },
    };
    match Route::from_plan(&plan) {
        Route::Install => {
            let privilege = privilege.map_err(|r| apt::needs_root(r, &[QEMU_PACKAGE]))?;
            apt::install(privilege, &[QEMU_PACKAGE], &plan)?;
        }
        Route::Unpack => {
            note!(
                "xtask: installing {QEMU_PACKAGE} would {}, and xtask never removes or \
                 downgrades an installed package: it runs QEMU from Debian's package unpacked \
                 into {} instead, in three steps",
                plan.harm(),
                qemu_binary::cache_dir().display()
            );
            qemu_unpacked::install(privilege)?;
        }
    }
    if qemu_binary::find().is_none() {
        bail!(
            "after installing, neither `{QEMU_PACKAGE} --version` on PATH nor {} reports QEMU \
             {major}.{minor} or later: put QEMU {major}.{minor} or later on PATH",
            qemu_binary::unpacked().display()
        );
    }
    Ok(())
}

/// The Debian package of the Python the protocol's independent client
/// (tests/protocol_client/client.py, standard library only) runs on.
const PYTHON_PACKAGE: &str = "python3";

/// `python3` for the end-to-end test of the client written from
/// docs/PROTOCOL.md alone: on PATH, or installed from Debian when that
/// removes or downgrades nothing.
pub fn ensure_python() -> Result<()> {
    if crate::cmd::runs(PYTHON_PACKAGE) {
        return Ok(());
    }
    note!(
        "xtask: no python3 on PATH; the end-to-end test of the client written from \
         docs/PROTOCOL.md alone runs on it. Asking apt-get how it would install {PYTHON_PACKAGE}"
    );
    apt::require(PYTHON_PACKAGE)?;
    let privilege = privilege::detect().map_err(|r| apt::needs_root(r, &[PYTHON_PACKAGE]))?;
    apt::update(privilege)?;
    let plan = apt::simulate(&[PYTHON_PACKAGE])?;
    apt::install(privilege, &[PYTHON_PACKAGE], &plan)?;
    if !crate::cmd::runs(PYTHON_PACKAGE) {
        bail!("after installing {PYTHON_PACKAGE}, `python3 --version` does not run");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plan_that_removes_or_downgrades_unpacks_instead() {
        // apt-get 2.6 on Debian 12 with bookworm-backports' qemu-utils 10 installed.
        let removes = apt::parse_simulation(
            "The following packages will be REMOVED:\n  qemu-utils\n\
             Remv qemu-utils [1:10.0.2+ds-2+deb13u1~bpo12+1]\n\
             Inst qemu-system-arm (1:7.2+dfsg-7+deb12u18+b3 Debian:12.15/oldstable [amd64])\n",
        );
        assert_eq!(Route::from_plan(&removes), Route::Unpack);
        let downgrades = apt::parse_simulation(
            "The following packages will be DOWNGRADED:\n  libslirp0\n\
             Inst qemu-system-arm (1:7.2+dfsg-7+deb12u18+b3 Debian:12 [amd64])\n",
        );
        assert_eq!(Route::from_plan(&downgrades), Route::Unpack);
    }

    #[test]
    fn a_plan_that_only_adds_installs() {
        let adds = apt::parse_simulation(
            "The following NEW packages will be installed:\n  qemu-system-arm\n\
             Inst qemu-system-arm (1:7.2+dfsg-7+deb12u18+b3 Debian:12 [amd64])\n",
        );
        assert_eq!(Route::from_plan(&adds), Route::Install);
    }
}
