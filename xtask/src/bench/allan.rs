//! `cargo xtask bench --allan`: Allan at the scale of real recordings
//! (host/examples/bench_allan_scale.rs) beside allantools, the peer, in a
//! venv under `target/allan-peer-venv` (pinned, installed from PyPI by pip
//! with its output on stderr; benchmark-only, never a product dependency).
//! The figures go to stdout; docs/BENCHMARKS.md's "Allan at scale" section
//! holds the last run's.

use anyhow::{Context, Result};
use std::process::Command;

use crate::cmd::{build_host_tool, cargo, check, host_target_dir};
use crate::setup::python_peers::{self, Venv};

/// The peer, pinned (the versions the figures were measured with).
const PEER: Venv = Venv {
    dir: "target/allan-peer-venv",
    packages: &["allantools==2024.06", "numpy==2.4.6"],
    purpose: "the Allan benchmark's peer (benchmark-only)",
};

/// Builds `triad` and the benchmark (release), installs the peer, runs it
/// (`long`: the 24-hour, 2 kHz case too) and returns its figures as the
/// markdown section of docs/BENCHMARKS.md (the benchmark's own progress on
/// stderr).
pub fn section(long: bool) -> Result<String> {
    let python = python_peers::ensure_venv(&PEER)?;
    build_host_tool()?;
    let mut build = cargo();
    build.args([
        "build",
        "--quiet",
        "--release",
        "-p",
        "triad-host",
        "--example",
        "bench_allan_scale",
    ]);
    check(build, "building the Allan benchmark")?;
    let exe = host_target_dir().join("release/examples/bench_allan_scale");
    let mut bench = Command::new(&exe);
    bench.env("TRIAD_PYTHON", &python);
    if long {
        bench.arg("--long");
    }
    note!(
        "xtask: Allan at scale (an 8-hour record{})",
        if long { " and a 24-hour one" } else { "" }
    );
    let out = bench
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("starting {}", exe.display()))?;
    anyhow::ensure!(
        out.status.success(),
        "the Allan benchmark failed ({})",
        out.status
    );
    let mut md = String::from(
        "## Allan at the scale of real recordings\n\n\
         `cargo xtask bench --allan --long` (this section alone; `cargo xtask bench` writes it with the rest): \
         host/examples/bench_allan_scale.rs on this machine, allantools' `oadev` (octave taus) on the six \
         columns already in memory, timed in its process (bench/allan_peer.py; one core), then `triad allan` \
         (every core) timed by `/usr/bin/time` (wall, user + system CPU, peak resident memory) on the same \
         samples in two MCAP bags, one after the other in one run (each three times, the run of median wall time reported, \
         every run's wall time listed: this machine's speed drifts by 10 % and more from one minute to the next): zstd chunks with CRCs (what `triad convert` writes) \
         and uncompressed chunks without CRCs (what rosbag2's MCAP storage writes by default: \
         rosbag2_storage_mcap/src/mcap_storage.cpp sets `compression = None`, `noChunkCRC = true`). \
         Wall time compares the two on this machine as they run (triad on every core, allantools on one), CPU time the work done. \
         After each bag, the floor under triad's time: the bag read as triad reads it (its own walk of the records, each chunk's data read at its place, an uncompressed one without a CRC 256 KiB at a time) and its zstd chunks decompressed, alone on one core, under the same timer.\n\n",
    );
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        md += &format!("- {line}\n");
    }
    md.push('\n');
    Ok(md)
}

/// `cargo xtask bench --allan`: the section on stdout.
pub fn run(long: bool) -> Result<()> {
    print!("{}", section(long)?);
    Ok(())
}
