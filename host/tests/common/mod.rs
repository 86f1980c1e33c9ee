//! What the `triad` command's test binaries share: running it, naming its
//! files (the fixtures that need no binary are `triad_host::fixtures`). Each
//! binary uses a part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `triad` binary under test.
pub const TRIAD: &str = env!("CARGO_BIN_EXE_triad");

/// `triad ARGS`, run to its end.
pub fn triad(args: &[&str]) -> Output {
    Command::new(TRIAD).args(args).output().expect("run triad")
}

/// `triad allan INPUT ARGS`, run to its end.
pub fn allan(input: &Path, args: &[&str]) -> Output {
    Command::new(TRIAD)
        .arg("allan")
        .arg(input)
        .args(args)
        .output()
        .expect("run triad allan")
}

/// Output bytes as text (invalid UTF-8 shown, not a panic).
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A fresh, empty directory for one test (named after the test binary too).
pub fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("{}-{name}", env!("CARGO_CRATE_NAME")));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `name` in a directory of this run of this test binary (made once, kept:
/// files made there can be shared by its tests).
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "triad-{}-{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// `calibrations/NAME` of the source tree.
pub fn calibration(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../calibrations")
        .join(name)
}

/// Writes the scene `body` to `d`/`name`.toml and simulates `seconds` of it
/// (seed `seed`) into `d`/`name`.csv, which it returns.
pub fn simulate_scene(d: &Path, name: &str, body: &str, seconds: &str, seed: &str) -> PathBuf {
    let scene = d.join(format!("{name}.toml"));
    std::fs::write(&scene, body).unwrap();
    let out = d.join(format!("{name}.csv"));
    let o = triad(&[
        "sim",
        "--scene",
        s(&scene),
        "--seconds",
        seconds,
        "--seed",
        seed,
        "--quiet",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    out
}

/// The hand-turned unit of the rig-free tests ([`hand_record::MEMS_UNIT`]).
///
/// [`hand_record::MEMS_UNIT`]: triad_lab::calib_fit::hand_record::MEMS_UNIT
pub fn hand_unit() -> triad_lab::calib_fit::hand_record::Unit {
    triad_lab::calib_fit::hand_record::MEMS_UNIT
}
