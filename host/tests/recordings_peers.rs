//! Recordings written and read by independent implementations, run by
//! `cargo xtask test` with the Python peers it installs (a venv under
//! target/: rosbags, pyulog, mcap, mcap-ros2-support; never dependencies
//! of triad) and `TRIAD_PEERS_PYTHON` naming its python:
//!
//!     TRIAD_PEERS_PYTHON=target/py-peers/bin/python \
//!         cargo test -p triad-host --test recordings_peers -- --ignored
//!
//! Bags of a simulated record written by rosbags (ROS 1 with plain, bz2 and
//! lz4 chunks, ROS 2 SQLite and MCAP) give the CSV's Allan results; two IMU topics need --topic; an
//! MCAP written by `triad convert` decodes (from its own schema text) with
//! every sample in Python's mcap-ros2-support; a real PX4 ULog reads as
//! pyulog reads it.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{dir, s, text, triad};

/// The python of the peers' venv.
fn python() -> String {
    std::env::var("TRIAD_PEERS_PYTHON")
        .expect("TRIAD_PEERS_PYTHON: the python of the venv `cargo xtask test` prepares")
}

/// `recordings.py ARGS` with the peers' python.
fn peer(args: &[&str]) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/recordings.py");
    let o = Command::new(python())
        .arg(script)
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "recordings.py {args:?}: {}",
        text(&o.stderr)
    );
}

/// The shipped static-bench scene (tactical IMU at rest, 100 Hz) for `seconds`.
fn record(d: &Path, seconds: &str) -> PathBuf {
    let out = d.join("static.csv");
    let o = triad(&[
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        seconds,
        "--seed",
        "3",
        "--quiet",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    out
}

fn allan(pre: &[&str], input: &Path) -> Vec<f64> {
    let mut args = pre.to_vec();
    args.extend(["allan", s(input), "--json"]);
    let o = triad(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut numbers = Vec::new();
    for c in v["columns"].as_array().unwrap() {
        for p in c["curve"].as_array().unwrap() {
            for k in ["tau", "oadev", "ci_low", "ci_high"] {
                numbers.push(p[k].as_f64().unwrap());
            }
        }
    }
    numbers
}

#[test]
#[ignore = "needs the Python peers: run by cargo xtask test"]
fn bags_written_by_rosbags_give_the_csvs_allan_and_two_topics_need_a_choice() {
    let d = dir("rosbags");
    let csv = record(&d, "600");
    peer(&["bags", s(&csv), s(&d.join("one"))]);
    let want = allan(&[], &csv);
    assert!(want.len() > 6 * 4 * 10, "{}", want.len());
    for bag in [
        "ros1.bag",
        "ros1-bz2.bag",
        "ros1-lz4.bag",
        "ros2_sqlite",
        "ros2_mcap",
        "ros2_mcap/ros2_mcap.mcap",
    ] {
        let got = allan(&[], &d.join("one").join(bag));
        assert_eq!(got.len(), want.len(), "{bag}");
        for (g, w) in got.iter().zip(&want) {
            // The bound; the stamps are the CSV's times to the nanosecond.
            assert!((g - w).abs() <= 1e-9 * w.abs(), "{bag}: {g} vs {w}");
        }
    }
    let short = d.join("short.csv");
    let text_all = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text_all.lines().take(101).collect();
    std::fs::write(&short, lines.join("\n") + "\n").unwrap();
    peer(&[
        "bags",
        s(&short),
        s(&d.join("two")),
        "/imu_left",
        "/imu_right",
    ]);
    for bag in ["ros1.bag", "ros2_sqlite", "ros2_mcap"] {
        let o = triad(&["allan", s(&d.join("two").join(bag))]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains("2 IMU topics (/imu_left, /imu_right): choose one with --topic"),
            "{bag}: {err}"
        );
    }
}

/// The rows of a CSV as numbers.
fn rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect()
}

#[test]
#[ignore = "needs the Python peers: run by cargo xtask test"]
fn an_mcap_written_by_triad_opens_in_python_with_every_sample() {
    let d = dir("mcap-python");
    let csv = record(&d, "600");
    let mcap = d.join("rec.mcap");
    let o = triad(&["convert", s(&csv), s(&mcap)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let py = d.join("python.csv");
    peer(&["read-mcap", s(&mcap), s(&py)]);
    let (theirs, ours) = (rows(&py), rows(&csv));
    assert_eq!(theirs.len(), ours.len());
    assert_eq!(theirs.len(), 60_000);
    for (k, (a, b)) in theirs.iter().zip(&ours).enumerate() {
        // Python's t is the stamp in integer nanoseconds.
        assert_eq!(a[0], (b[0] * 1e9).round(), "row {k}");
        assert_eq!(a[1..], b[1..], "row {k}");
    }
}

#[test]
#[ignore = "needs the Python peers: run by cargo xtask test"]
fn a_real_ulog_reads_as_pyulog_reads_it() {
    let d = dir("pyulog");
    let ulog = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/recordings/px4_sample_log_small.ulg");
    let py = d.join("pyulog.csv");
    peer(&["ulog", s(&ulog), s(&py)]);
    let ours = d.join("triad.csv");
    let o = triad(&["--topic", "sensor_combined", "convert", s(&ulog), s(&ours)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (theirs, ours) = (rows(&py), rows(&ours));
    assert_eq!(theirs.len(), 1298);
    assert_eq!(theirs, ours);
}

#[test]
#[ignore = "needs the Python peers: run by cargo xtask test"]
fn a_decoded_stream_written_as_mcap_opens_in_python_with_every_frame() {
    let d = dir("decode-python");
    let stream = d.join("stream.bin");
    std::fs::write(&stream, triad_host::fixtures::stream(2000)).unwrap();
    let (mcap, csv) = (d.join("rec.mcap"), d.join("rec.csv"));
    for out in [&mcap, &csv] {
        let o = triad(&["decode", s(&stream), "--out", s(out)]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let py = d.join("python.csv");
    peer(&["read-mcap", s(&mcap), s(&py)]);
    let (theirs, ours) = (rows(&py), rows(&csv));
    assert_eq!(theirs.len(), 2000);
    assert_eq!(theirs.len(), ours.len());
    for (k, (a, b)) in theirs.iter().zip(&ours).enumerate() {
        // Python: t_ns,ax..gz,temp,seq,flags; triad decode: seq,t,ax..gz,temp,flags.
        assert_eq!(a[0], (b[1] * 1e9).round(), "row {k}");
        assert_eq!(a[1..8], b[2..9], "row {k}");
        assert_eq!((a[8], a[9]), (b[0], b[9]), "row {k}");
    }
}
