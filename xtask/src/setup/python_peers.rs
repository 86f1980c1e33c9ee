//! The Python peers triad runs beside itself in tests and benchmarks (never
//! dependencies of the product), each set pinned in a venv under target/,
//! installed from PyPI by pip with its output on stderr; Python's venv
//! module comes from Debian's python3-venv where it is missing. The
//! recordings tests' set ([`RECORDINGS_PEERS`]): rosbags (writes ROS 1 and
//! ROS 2 bags, both storages), pyulog (reads ULog), mcap and
//! mcap-ros2-support (read an MCAP from its schema text); the Allan
//! benchmark's is in xtask/src/bench/allan.rs.

use super::{apt, privilege};
use crate::cmd::{check, root};
use anyhow::{Context, Result};
use std::path::PathBuf;
use std::process::Command;

/// A venv of pinned Python packages under target/, for tests or benchmarks
/// only (never a dependency of the product).
pub struct Venv {
    /// Its directory, relative to the workspace root.
    pub dir: &'static str,
    /// What is installed, pinned (the versions the tests or figures were made with).
    pub packages: &'static [&'static str],
    /// Who needs it, for the note printed when it is installed.
    pub purpose: &'static str,
}

/// The recordings tests' peers.
pub const RECORDINGS_PEERS: Venv = Venv {
    dir: "target/py-peers",
    packages: &[
        "rosbags==0.11.9",
        "pyulog==1.3.0",
        "mcap==1.6.0",
        "mcap-ros2-support==0.6.0",
    ],
    purpose: "the Python peers of the recordings tests (test-only)",
};

/// The Debian packages that give `python3 -m venv`.
const DEBIAN: [&str; 2] = ["python3", "python3-venv"];

/// The recordings tests' venv's python ([`RECORDINGS_PEERS`]).
pub fn ensure() -> Result<PathBuf> {
    ensure_venv(&RECORDINGS_PEERS)
}

/// The python of `venv`, its packages installed (once: a marker file lists
/// what was installed; another list installs again).
pub fn ensure_venv(venv: &Venv) -> Result<PathBuf> {
    let dir = root().join(venv.dir);
    let python = dir.join("bin/python");
    let marker = dir.join("triad-peers.txt");
    let wanted = venv.packages.join("\n");
    if python.exists() && std::fs::read_to_string(&marker).ok().as_deref() == Some(&wanted) {
        return Ok(python);
    }
    note!(
        "xtask: installing {} ({}) into a venv in {} (pip's output follows)",
        venv.purpose,
        venv.packages.join(", "),
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
        .args(venv.packages);
    check(pip, &format!("pip install ({})", venv.purpose))?;
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
