//! `cargo xtask bench --fuzz`, coverage-guided part: the fuzz targets of
//! fuzz/ under AFL++ for a fixed time each, through cargo-afl (afl.rs) on
//! the stable toolchain. cargo-afl is installed by cargo from crates.io
//! into target/tools (pinned: the version of the `afl` crate in Cargo.lock),
//! and builds AFL++ from the source it ships into target/tools/share (its
//! output on stderr); the instrumented targets build into target/afl, apart
//! from the ordinary release build. Printed per target: executions, their
//! rate, the corpus AFL grew from the seeds, the map coverage, crashes and
//! hangs; a crash or a hang fails the run and names its file.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::cmd::{cargo, check, root};

/// cargo-afl, pinned to the `afl` crate fuzz/Cargo.toml resolves to.
const CARGO_AFL: &str = "0.18.2";

/// The targets: (binary, seed directory under fuzz/seeds).
const TARGETS: [(&str, &str); 8] = [
    ("fuzz_record", "record"),
    ("fuzz_triad_csv", "record"),
    ("fuzz_command_path", "commands"),
    ("fuzz_stream_decoder", "stream"),
    ("fuzz_cobs", "cobs"),
    ("fuzz_calibration_blob", "calibration_blob"),
    ("fuzz_scene_blob", "scene_blob"),
    ("fuzz_calibration_toml", "calibration_toml"),
];

/// Where cargo-afl and AFL++ are installed.
fn tools() -> PathBuf {
    root().join("target/tools")
}

/// `cargo` with cargo-afl on PATH and AFL++'s build kept under target/tools.
fn cargo_afl() -> Command {
    let mut command = cargo();
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut dirs = vec![tools().join("bin")];
    dirs.extend(std::env::split_paths(&path));
    command
        .env("PATH", std::env::join_paths(dirs).unwrap_or(path))
        .env("XDG_DATA_HOME", tools().join("share"))
        .arg("afl");
    command
}

/// Installs cargo-afl and builds AFL++ once.
fn ensure_cargo_afl() -> Result<()> {
    if !tools().join("bin/cargo-afl").exists() {
        note!("xtask: installing cargo-afl {CARGO_AFL} from crates.io into target/tools (cargo's output follows)");
        let mut install = cargo();
        install
            .args(["install", "--locked", "--version", CARGO_AFL, "--root"])
            .arg(tools())
            .arg("cargo-afl");
        check(install, "cargo install cargo-afl")?;
    }
    let built = tools().join("share/afl.rs");
    let has_runtime = std::fs::read_dir(&built)
        .map(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().starts_with("rustc-"))
        })
        .unwrap_or(false);
    if !has_runtime {
        note!("xtask: building AFL++ (cargo afl config --build; its output follows)");
        let mut config = cargo_afl();
        config.args(["config", "--build"]);
        check(config, "cargo afl config --build")?;
    }
    Ok(())
}

/// A field of AFL++'s `fuzzer_stats`.
fn stat(stats: &str, key: &str) -> String {
    stats
        .lines()
        .find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == key).then(|| v.trim().to_string())
        })
        .unwrap_or_else(|| "?".into())
}

/// Files in `dir` other than AFL's README.
fn findings(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.flatten()
                .map(|e| e.path())
                .filter(|p| p.file_name().is_some_and(|n| n != "README.txt"))
                .collect()
        })
        .unwrap_or_default()
}

/// Builds the targets with AFL's instrumentation and fuzzes each for `seconds`.
pub fn run(seconds: u64) -> Result<()> {
    ensure_cargo_afl()?;
    let target_dir = root().join("target/afl");
    note!("xtask: building the fuzz targets with AFL++'s instrumentation (target/afl)");
    let mut build = cargo_afl();
    build
        .args([
            "build",
            "--release",
            "--quiet",
            "-p",
            "triad-fuzz",
            "--features",
            "afl",
        ])
        .env("CARGO_TARGET_DIR", &target_dir);
    check(build, "cargo afl build -p triad-fuzz")?;
    let mut failed = Vec::new();
    for (target, seeds) in TARGETS {
        let runs = target_dir.join("out");
        let out = runs.join(target);
        // AFL++ makes its output directory, not the directories above it.
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(&runs).with_context(|| format!("creating {}", runs.display()))?;
        note!("xtask: AFL++ on {target} for {seconds} s");
        let mut fuzz = cargo_afl();
        fuzz.arg("fuzz")
            .arg("-i")
            .arg(root().join("fuzz/seeds").join(seeds))
            .arg("-o")
            .arg(&out)
            .args(["-V", &seconds.to_string(), "--"])
            .arg(target_dir.join("release").join(target))
            .env("AFL_NO_UI", "1")
            .env("AFL_SKIP_CPUFREQ", "1")
            .env("AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES", "1")
            .env("AFL_QUIET", "1");
        check(fuzz, &format!("AFL++ on {target}"))?;
        let stats = std::fs::read_to_string(out.join("default/fuzzer_stats"))
            .with_context(|| format!("AFL++'s statistics of {target}"))?;
        let (crashes, hangs) = (
            findings(&out.join("default/crashes")),
            findings(&out.join("default/hangs")),
        );
        println!(
            "{target}: {} executions in {} s ({} /s), corpus {} from the seeds, map coverage {}, stability {}, {} crash(es), {} hang(s)",
            stat(&stats, "execs_done"),
            stat(&stats, "run_time"),
            stat(&stats, "execs_per_sec"),
            stat(&stats, "corpus_count"),
            stat(&stats, "bitmap_cvg"),
            stat(&stats, "stability"),
            crashes.len(),
            hangs.len()
        );
        for f in crashes.iter().chain(&hangs) {
            failed.push(format!("{target}: {}", f.display()));
        }
    }
    if !failed.is_empty() {
        bail!(
            "AFL++ found inputs that crash or hang (replay one with `triad_fuzz::TARGET`): {}",
            failed.join("; ")
        );
    }
    Ok(())
}
