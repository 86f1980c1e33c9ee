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

/// Writes the record of `script` for the hand-turned unit ([`hand_unit`])
/// as `triad sim` would (t, accel, gyro, SI) to `d`/`name`.csv.
pub fn hand_csv(
    d: &Path,
    name: &str,
    script: &triad_lab::calib_fit::hand_record::Script,
    seed: u64,
) -> PathBuf {
    use std::fmt::Write as _;
    let mut rng = triad_sim::effects::rng::Rng::from_seed(seed);
    let mut csv = String::from("t,ax,ay,az,gx,gy,gz\n");
    triad_lab::calib_fit::hand_record::generate(script, &hand_unit(), &mut || rng.uniform(), |s| {
        let [ax, ay, az] = s.accel;
        let [gx, gy, gz] = s.gyro;
        writeln!(csv, "{},{ax},{ay},{az},{gx},{gy},{gz}", s.t).unwrap();
    });
    let path = d.join(format!("{name}.csv"));
    std::fs::write(&path, csv).unwrap();
    path
}

/// A 3×3 array of a calibration file's `section`.`key` (e.g. gyro, scale_misalignment).
pub fn matrix(table: &toml::Table, section: &str, key: &str) -> [[f64; 3]; 3] {
    let rows = table[section][key].as_array().unwrap();
    std::array::from_fn(|i| {
        let row = rows[i].as_array().unwrap();
        std::array::from_fn(|j| row[j].as_float().unwrap())
    })
}

/// A unit of triad-sim's with a g-sensitivity (its `g_sensitivity`
/// effect, 0.12 °/s per g on the diagonal as issue 22's real unit), white
/// noise only; [`HAND_16`] turns it by hand.
pub const G_UNIT: &str = "seed = 11\n\
[accel]\nwhite_noise = \"70 ug/sqrt(Hz)\"\nturn_on_bias = \"20 mg\"\nturn_on_scale = \"0.5 %\"\nturn_on_misalignment = \"5 mrad\"\n\
[gyro]\nwhite_noise = \"0.0028 deg/s/sqrt(Hz)\"\nturn_on_bias = \"0.5 deg/s\"\nturn_on_scale = \"0.5 %\"\nturn_on_misalignment = \"5 mrad\"\n\
g_sensitivity = [[\"0.12 deg/s/g\", \"0.02 deg/s/g\", \"-0.01 deg/s/g\"], [\"0.015 deg/s/g\", \"-0.11 deg/s/g\", \"0.03 deg/s/g\"], [\"0 deg/s/g\", \"0.02 deg/s/g\", \"0.09 deg/s/g\"]]\n";

/// A script of 16 hand poses of 4 s, turns of 1.5 s, at 100 Hz.
pub const HAND_16: &str = "rate_hz = 100.0\nduration_s = 88.0\n\
[motion]\nkind = \"hand\"\nposes = 16\nseed = 3\ndwell_s = 4.0\nturn_s = 1.5\n";

/// Simulates [`G_UNIT`] turned by [`HAND_16`] (record seed 1) into
/// `d`/m.csv with its truth in `d`/truth.toml; returns both paths.
pub fn simulate_g_unit(d: &Path) -> (PathBuf, PathBuf) {
    let (unit, script) = (d.join("unit.toml"), d.join("script.toml"));
    std::fs::write(&unit, G_UNIT).unwrap();
    std::fs::write(&script, HAND_16).unwrap();
    let (m, truth) = (d.join("m.csv"), d.join("truth.toml"));
    let o = triad(&[
        "sim",
        "--unit",
        s(&unit),
        "--script",
        s(&script),
        "--record-seed",
        "1",
        "--out",
        s(&m),
        "--truth-calib",
        s(&truth),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    (m, truth)
}
