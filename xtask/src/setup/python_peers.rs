//! The Python peers the recordings tests run beside triad (test-only,
//! never dependencies of the product): rosbags (writes ROS 1 and ROS 2
//! bags, both storages), pyulog (reads ULog), mcap and mcap-ros2-support
//! (read an MCAP from its schema text), pinned, in a venv under
//! `target/py-peers`, installed from PyPI by pip with its output on stderr.
//! Python's venv module comes from Debian's python3-venv where it is missing.

use super::{apt, privilege};
use crate::cmd::{check, root};
use anyhow::{Context, Result};
use std::path::PathBuf;
use std::process::Command;

/// What the tests need, pinned (the versions the tests were written against).
const PACKAGES: [&str; 4] = [
    "rosbags==0.11.9",
    "pyulog==1.3.0",
    "mcap==1.6.0",
    "mcap-ros2-support==0.6.0",
];

/// The Debian packages that give `python3 -m venv`.
const DEBIAN: [&str; 2] = ["python3", "python3-venv"];

/// The venv's directory.
fn venv() -> PathBuf {
    root().join("target/py-peers")
}

/// The venv's python, the peers installed in it (once: a marker file lists
/// what was installed).
pub fn ensure() -> Result<PathBuf> {
    let dir = venv();
    let python = dir.join("bin/python");
    let marker = dir.join("triad-peers.txt");
    let wanted = PACKAGES.join("\n");
    if python.exists() && std::fs::read_to_string(&marker).ok().as_deref() == Some(&wanted) {
        return Ok(python);
    }
    note!(
        "xtask: installing the Python peers of the recordings tests ({}) into a venv in {} \
         (test-only; pip's output follows)",
        PACKAGES.join(", "),
        dir.display()
    );
    if !python.exists() && !make_venv(&dir)? {
        install_venv_module()?;
        let mut again = Command::new("python3");
        again.args(["-m", "venv"]).arg(&dir);
        check(again, "python3 -m venv")?;
    }
    let mut pip = Command::new(&python);
    pip.args(["-m", "pip", "install", "--disable-pip-version-check"])
        .args(PACKAGES);
    check(pip, "pip install (the recordings tests' Python peers)")?;
    std::fs::write(&marker, wanted).with_context(|| format!("writing {}", marker.display()))?;
    Ok(python)
}

/// `python3 -m venv DIR`; false when Python or its venv module is missing.
fn make_venv(dir: &std::path::Path) -> Result<bool> {
    let status = Command::new("python3")
        .args(["-m", "venv"])
        .arg(dir)
        .stdout(std::io::stderr())
        .status();
    Ok(matches!(status, Ok(s) if s.success()))
}

/// Debian's python3 and python3-venv, through apt-get.
fn install_venv_module() -> Result<()> {
    note!(
        "xtask: python3 -m venv failed: installing Debian's {} (without recommended packages; \
         nothing installed is removed or downgraded)",
        DEBIAN.join(" and ")
    );
    apt::require("python3-venv")?;
    let privilege = privilege::detect().map_err(|r| apt::needs_root(r, &DEBIAN))?;
    apt::update(privilege)?;
    let plan = apt::simulate(&DEBIAN)?;
    apt::install(privilege, &DEBIAN, &plan)
}
