//! Recordings in the formats people have (host/src/record/): bags written
//! by an independent implementation (Python's rosbags, the fixtures'
//! README says how), a real PX4 ULog, EuRoC and imu_tk text, MCAP written by
//! `triad convert`. Each reads to the same samples as the CSV they were made
//! from, `allan`, `calib fit` and `calib verify` take them with the CSV's
//! results, a bag with two IMU topics needs `--topic`, and a truncated or
//! corrupt file of each format is refused naming the file and where it broke.

mod common;

use std::path::{Path, PathBuf};

use common::{dir, s, simulate_scene, text, triad};

/// `host/tests/fixtures/recordings/NAME`.
fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/recordings")
        .join(name)
}

/// The CSV the fixtures were written from, without its temp column (bags
/// of sensor_msgs/Imu carry none).
fn source_without_temp() -> String {
    let csv = std::fs::read_to_string(fixture("imu.csv")).unwrap();
    csv.lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect()
}

/// `triad [pre…] convert IN OUT` must succeed; OUT's text.
fn converted(pre: &[&str], input: &Path, out: &Path) -> String {
    let mut args = pre.to_vec();
    args.extend(["convert", s(input), s(out)]);
    let o = triad(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // An MCAP's bytes are not text: only a CSV's are compared as text.
    text(&std::fs::read(out).unwrap())
}

/// `triad ARGS` must fail with one line naming `what`; the line.
fn refused(args: &[&str], what: &[&str]) -> String {
    let o = triad(args);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for w in what {
        assert!(err.contains(w), "{args:?}: `{w}` not in: {err}");
    }
    err
}

const BAGS: [&str; 5] = [
    "imu.bag",
    "imu.db3",
    "imu_mcap_bag",
    "imu_mcap_bag/ros2_mcap.mcap",
    "two_imus.mcap",
];

#[test]
fn every_bag_reads_to_the_samples_it_was_written_from() {
    let d = dir("same-samples");
    let want = source_without_temp();
    for (k, bag) in BAGS.iter().enumerate() {
        let pre: &[&str] = if bag.starts_with("two") {
            &["--topic", "/imu1"]
        } else {
            &[]
        };
        let got = converted(pre, &fixture(bag), &d.join(format!("{k}.csv")));
        let rows = if bag.starts_with("two") { 21 } else { 201 };
        let want: String = want.lines().take(rows).map(|l| format!("{l}\n")).collect();
        assert_eq!(got, want, "{bag}");
        // The record time (written equal to the stamp) reads the same.
        let mut pre = pre.to_vec();
        pre.extend(["--time", "receive"]);
        let got = converted(&pre, &fixture(bag), &d.join(format!("{k}-receive.csv")));
        assert_eq!(got, want, "{bag} --time receive");
    }
}

/// `triad allan INPUT --json`, its input's name taken out.
fn allan_json(pre: &[&str], input: &Path) -> serde_json::Value {
    let mut args = pre.to_vec();
    args.extend(["allan", s(input), "--json"]);
    let o = triad(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v.as_object_mut().unwrap().remove("input");
    v
}

/// Every number of `a` within `rel` of `b`'s (same shape).
fn assert_close(a: &serde_json::Value, b: &serde_json::Value, rel: f64, at: &str) {
    use serde_json::Value::*;
    match (a, b) {
        (Number(x), Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= rel * x.abs().max(y.abs()),
                "{at}: {x} vs {y}"
            );
        }
        (Array(x), Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (k, (x, y)) in x.iter().zip(y).enumerate() {
                assert_close(x, y, rel, &format!("{at}[{k}]"));
            }
        }
        (Object(x), Object(y)) => {
            assert_eq!(
                x.keys().collect::<Vec<_>>(),
                y.keys().collect::<Vec<_>>(),
                "{at}"
            );
            for (k, x) in x {
                assert_close(x, &y[k], rel, &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{at}"),
    }
}

#[test]
fn allan_of_each_format_is_the_csvs() {
    let d = dir("allan");
    let csv = d.join("imu.csv");
    std::fs::write(&csv, source_without_temp()).unwrap();
    let want = allan_json(&[], &csv);
    for bag in &BAGS[..4] {
        // The bound: 1e-9 relative (the samples are the same f64s).
        assert_close(&allan_json(&[], &fixture(bag)), &want, 1e-9, bag);
    }
    // EuRoC (ns, gyro first) and imu_tk (one triad per file) written here
    // from the same samples.
    let (mut euroc, mut acc, mut gyr) = (
        String::from("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"),
        String::new(),
        String::new(),
    );
    for line in source_without_temp().lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let ns = (c[0].parse::<f64>().unwrap() * 1e9).round() as u64;
        euroc += &format!(
            "{ns},{},{},{},{},{},{}\n",
            c[4], c[5], c[6], c[1], c[2], c[3]
        );
        acc += &format!("{} {} {} {}\n", c[0], c[1], c[2], c[3]);
        gyr += &format!("{}\t{}\t{}\t{}\n", c[0], c[4], c[5], c[6]);
    }
    let (e, a, g) = (d.join("data.csv"), d.join("acc.txt"), d.join("gyro.txt"));
    std::fs::write(&e, euroc).unwrap();
    std::fs::write(&a, acc).unwrap();
    std::fs::write(&g, gyr).unwrap();
    assert_close(&allan_json(&[], &e), &want, 1e-9, "EuRoC");
    let columns = |v: &serde_json::Value, names: &[&str]| -> Vec<serde_json::Value> {
        v["columns"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| names.contains(&c["column"].as_str().unwrap()))
            .cloned()
            .collect()
    };
    let accel = ["ax", "ay", "az"];
    let gyro = ["gx", "gy", "gz"];
    assert_close(
        &serde_json::Value::Array(columns(&allan_json(&[], &a), &accel)),
        &serde_json::Value::Array(columns(&want, &accel)),
        1e-9,
        "imu_tk accel",
    );
    let named = allan_json(&["--imu-tk-triad", "gyro"], &d.join("gyro.txt"));
    assert_close(
        &serde_json::Value::Array(columns(&named, &gyro)),
        &serde_json::Value::Array(columns(&want, &gyro)),
        1e-9,
        "imu_tk gyro",
    );
}

#[test]
fn two_imu_topics_without_topic_are_refused_naming_both() {
    for bag in ["two_imus.bag", "two_imus.mcap"] {
        let f = fixture(bag);
        refused(
            &["allan", s(&f)],
            &[bag, "2 IMU topics (/imu0, /imu1): choose one with --topic"],
        );
        refused(
            &["allan", "--topic", "/imu7", s(&f)],
            &["no topic /imu7; the recording has: /imu0", "/imu1"],
        );
    }
    let ulog = fixture("px4_sample_log_small.ulg");
    refused(
        &["allan", s(&ulog)],
        &["2 IMU topics (sensor_accel+sensor_gyro, sensor_combined)"],
    );
}

#[test]
fn a_real_px4_ulog_reads_both_ways() {
    let d = dir("ulog");
    let f = fixture("px4_sample_log_small.ulg");
    let combined = converted(&["--topic", "sensor_combined"], &f, &d.join("c.csv"));
    assert!(combined.starts_with("t,ax,ay,az,gx,gy,gz\n"), "{combined}");
    // pyulog counts 1298 sensor_combined messages of instance 0 in this log.
    assert_eq!(combined.lines().count(), 1 + 1298);
    let pair = converted(
        &["--topic", "sensor_accel+sensor_gyro"],
        &f,
        &d.join("p.csv"),
    );
    assert!(pair.starts_with("t,ax,ay,az,gx,gy,gz,temp\n"), "{pair}");
    // Six sensor_gyro messages of instance 0, each paired; az near -g, temp °C.
    let rows: Vec<Vec<f64>> = pair
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 6);
    for r in &rows {
        assert!((r[3] + 9.8).abs() < 0.3, "{r:?}");
        assert!((0.0..80.0).contains(&r[7]), "{r:?}");
    }
}

#[test]
fn csv_to_mcap_to_csv_is_identical() {
    let d = dir("round-trip");
    let mcap = d.join("imu.mcap");
    converted(&[], &fixture("imu.csv"), &mcap);
    assert!(std::fs::read(&mcap).unwrap().starts_with(b"\x89MCAP0\r\n"));
    let back = converted(&[], &mcap, &d.join("back.csv"));
    assert_eq!(back, std::fs::read_to_string(fixture("imu.csv")).unwrap());
}

/// Truncates a copy of `name` to `keep` bytes in `d`.
fn cut(d: &Path, name: &str, keep: usize) -> PathBuf {
    let bytes = std::fs::read(fixture(name)).unwrap();
    let out = d.join(format!("cut-{}", name.replace('/', "-")));
    std::fs::write(&out, &bytes[..keep.min(bytes.len())]).unwrap();
    out
}

#[test]
fn a_truncated_or_corrupt_file_of_each_format_names_where_it_broke() {
    let d = dir("broken");
    let csv = std::fs::read_to_string(fixture("imu.csv")).unwrap();
    let mcap = d.join("imu.mcap");
    converted(&[], &fixture("imu.csv"), &mcap);
    let out = s(&d.join("out.csv")).to_string();
    let convert = |f: &Path| vec!["convert".to_string(), s(f).to_string(), out.clone()];
    let check = |args: Vec<String>, what: &[&str]| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, what)
    };
    // Text: a line cut in the middle.
    let cut_text = d.join("cut.csv");
    std::fs::write(&cut_text, &csv[..csv.len() / 2]).unwrap();
    check(convert(&cut_text), &["cut.csv, line", "expected 8 columns"]);
    let euroc = d.join("data.csv");
    std::fs::write(&euroc, "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n1000,0,0,0,0,0,9.8\n2000,0,0,").unwrap();
    check(
        convert(&euroc),
        &["data.csv, line 3: expected 7 columns, found 4"],
    );
    let imu_tk = d.join("acc.txt");
    std::fs::write(&imu_tk, "0.01 0 0 9.8\n0.02 0 0\n").unwrap();
    check(convert(&imu_tk), &["acc.txt, line 2: expected 4 numbers"]);
    // MCAP: cut in a message.
    let len = std::fs::metadata(&mcap).unwrap().len() as usize;
    let f = {
        let bytes = std::fs::read(&mcap).unwrap();
        let f = d.join("cut.mcap");
        std::fs::write(&f, &bytes[..len / 2]).unwrap();
        f
    };
    check(
        convert(&f),
        &[
            "cut.mcap: broken MCAP after",
            "message(s), within its first",
        ],
    );
    // MCAP: a message's CDR corrupted (its frame_id length made absurd).
    let corrupt = {
        let mut bytes = std::fs::read(fixture("imu_mcap_bag/ros2_mcap.mcap")).unwrap();
        let at = bytes.windows(4).position(|w| w == b"imu\0").unwrap() - 4;
        bytes[at..at + 4].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
        let f = d.join("corrupt.mcap");
        std::fs::write(&f, bytes).unwrap();
        f
    };
    check(
        convert(&corrupt),
        &["corrupt.mcap, message 1 of /imu0", "frame_id's length"],
    );
    // SQLite: the database cut in half.
    let db = cut(&d, "imu.db3", 98304 / 2);
    check(convert(&db), &["cut-imu.db3"]);
    // ROS 1: cut before its index, and a chunk's bytes overwritten.
    let bag = cut(&d, "imu.bag", 40_000);
    check(
        convert(&bag),
        &[
            "cut-imu.bag: truncated: the index should start at byte",
            "40000 bytes",
        ],
    );
    let ros1 = {
        let mut bytes = std::fs::read(fixture("imu.bag")).unwrap();
        for b in &mut bytes[4200..4400] {
            *b = 0xff;
        }
        let f = d.join("corrupt.bag");
        std::fs::write(&f, bytes).unwrap();
        f
    };
    check(convert(&ros1), &["corrupt.bag"]);
    // ULog: cut in the data section, and before it.
    let ulog = cut(&d, "px4_sample_log_small.ulg", 300_000);
    check(
        ["--topic", "sensor_combined"]
            .iter()
            .map(|s| s.to_string())
            .chain(convert(&ulog))
            .collect(),
        &["cut-px4_sample_log_small.ulg: truncated ULog: its 300000 bytes end inside a message"],
    );
    let ulog = cut(&d, "px4_sample_log_small.ulg", 500);
    check(
        convert(&ulog),
        &["truncated ULog: its 500 bytes end before the data section"],
    );
    // Nothing was written by any refused conversion.
    assert!(!d.join("out.csv").exists());
}

#[test]
fn calib_fit_and_verify_read_a_recording_as_its_csv() {
    let d = dir("calib");
    let body = "rate_hz = 100.0\nduration_s = 720.0\n[motion]\nkind = \"tumble\"\npositions = 24\n\
         dwell_s = 25.0\ntransition_s = 5.0\n[accel]\nwhite_noise = \"100 ug/sqrt(Hz)\"\n\
         bias = [\"1 mg\", \"-2 mg\", \"0.5 mg\"]\nscale_factor = [\"500 ppm\", \"-300 ppm\", \"200 ppm\"]\n";
    let sim = simulate_scene(&d, "tumble", body, "720", "1");
    // The MCAP keeps time to the nanosecond: its CSV is the reference.
    let mcap = d.join("tumble.mcap");
    converted(&[], &sim, &mcap);
    let csv = d.join("tumble-ns.csv");
    converted(&[], &mcap, &csv);
    let fit = |input: &Path, out: &Path| {
        let o = triad(&[
            "calib",
            "fit",
            "accel",
            "--axis-aligned",
            "--positions",
            s(input),
            "--out",
            s(out),
        ]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        text(&o.stdout)
            .replace(s(input), "INPUT")
            .replace(s(out), "OUTPUT")
    };
    let (from_csv, from_mcap) = (d.join("csv.toml"), d.join("mcap.toml"));
    assert_eq!(fit(&csv, &from_csv), fit(&mcap, &from_mcap));
    let strip = |p: &Path| -> String {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| !l.contains("tumble"))
            .collect()
    };
    assert_eq!(strip(&from_csv), strip(&from_mcap));
    let verify = |input: &Path| {
        let o = triad(&["calib", "verify", s(&from_csv), s(input)]);
        assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
        text(&o.stdout).replace(s(input), "INPUT")
    };
    let v = verify(&mcap);
    assert!(v.contains("verdict: PASS"), "{v}");
    assert_eq!(v, verify(&csv));
}

#[test]
fn decode_out_mcap_keeps_every_frame_and_its_seq_and_flags() {
    let d = dir("decode-mcap");
    let stream = d.join("stream.bin");
    std::fs::write(&stream, triad_host::fixtures::stream(500)).unwrap();
    let stdout = triad(&["decode", s(&stream)]);
    assert!(stdout.status.success(), "{}", text(&stdout.stderr));
    let (mcap, csv) = (d.join("rec.mcap"), d.join("rec.csv"));
    for out in [&mcap, &csv] {
        let o = triad(&["decode", s(&stream), "--out", s(out)]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    // --out FILE.csv is what standard output gets.
    assert_eq!(std::fs::read(&csv).unwrap(), stdout.stdout);
    // The MCAP's samples are the CSV's numbers (t to the nanosecond).
    let back = converted(&[], &mcap, &d.join("back.csv"));
    let numbers =
        |line: &str| -> Vec<f64> { line.split(',').map(|c| c.parse().unwrap()).collect() };
    let decoded: Vec<Vec<f64>> = text(&stdout.stdout).lines().skip(1).map(numbers).collect();
    let read: Vec<Vec<f64>> = back.lines().skip(1).map(numbers).collect();
    assert_eq!(read.len(), 500);
    for (r, c) in read.iter().zip(&decoded) {
        // back: t,ax..gz,temp; decoded: seq,t,ax..gz,temp,flags.
        assert_eq!(r[..], c[1..9]);
    }
    // The frame topic is there, with its own schema.
    let bytes = std::fs::read(&mcap).unwrap();
    for needle in [
        &b"/imu/frame"[..],
        b"triad_msgs/msg/Frame",
        b"uint32 seq\nuint16 flags",
    ] {
        assert!(
            bytes.windows(needle.len()).any(|w| w == needle),
            "{}",
            text(needle)
        );
    }
}

/// Files on which a format's library itself fails (found by AFL++, kept in
/// fuzz/findings/): each command that reads them ends with that file's
/// error, not a crash (a panic's exit status is 101, an abort's 134).
#[test]
fn a_file_its_format_library_fails_on_is_an_error_naming_it() {
    let findings = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/findings");
    for file in [
        "ulog_header_slice_out_of_range.ulg",
        "mcap_scan_subtract_overflow.mcap",
    ] {
        let path = findings.join(file);
        let out = triad(&["allan", s(&path)]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{file}: {err}");
        assert!(
            err.contains(file),
            "{file}: the error names the file: {err}"
        );
        assert!(!err.contains("panicked"), "{file}: no panic printed: {err}");
    }
    // The MCAP's channels are found by triad's own walk of its chunks, never
    // by the library's reader of a chunk's records (which overflows a
    // subtraction on it): the chunk whose header's size is false is named.
    let out = triad(&[
        "allan",
        s(&findings.join("mcap_scan_subtract_overflow.mcap")),
    ]);
    assert_eq!(
        text(&out.stderr).trim_end(),
        format!(
            "triad: {}: broken MCAP after 0 message(s), within its first 1942 bytes: the chunk that ends there: 8 bytes decompressed where its header says 9647",
            s(&findings.join("mcap_scan_subtract_overflow.mcap"))
        )
    );
}

/// The ULogs px4-ulog 0.6.1 cannot take (fuzz/findings): triad checks them
/// before the library sees the bytes, so the error names the file, the
/// message's byte and the reason, and no library failure is involved.
#[test]
fn a_ulog_the_library_cannot_take_is_refused_naming_its_byte() {
    let file = "ulog_header_slice_out_of_range.ulg";
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz/findings")
        .join(file);
    let out = triad(&["allan", s(&path)]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    // The mutation added 10 to the type of the format message ('F') at byte
    // 849 (its type at 851): a 'P' whose first byte, 'a' (97), is read as
    // the key's length.
    let expected = "cannot read this ULog: at byte 849, a parameter message ('P') of 82 bytes has a key length of 97, more than the 81 bytes after it";
    assert!(err.contains(file) && err.contains(expected), "{err}");
    assert!(
        !err.contains(triad_host::record::producer::LIBRARY_FAILED),
        "{err}"
    );
    // Formats whose flattening would take the library minutes (nested
    // arrays of an empty format) or tens of GiB (a chain of long names):
    // refused where its data section starts, before the library flattens.
    for (file, at) in [
        ("ulog_flatten_empty_format_arrays.ulg", 96),
        ("ulog_flatten_nested_long_names.ulg", 12588),
    ] {
        let path = path.with_file_name(file);
        let out = triad(&["allan", s(&path)]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        let expected = format!("cannot read this ULog: at byte {at}, flattening its formats comes to more than 8388608 fields and name bytes");
        assert!(err.contains(file) && err.contains(&expected), "{err}");
    }
}

/// `triad correct --calib calibrations/NAME [extra…] INPUT` must succeed; its stdout.
fn corrected(name: &str, input: &Path, extra: &[&str]) -> String {
    let calib = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../calibrations")
        .join(name);
    let mut args = vec!["correct", "--calib", s(&calib)];
    args.extend(extra);
    args.push(s(input));
    let o = triad(&args);
    assert!(o.status.success(), "{input:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

#[test]
fn correct_reads_each_bag_as_the_csv_of_its_samples() {
    // The bags hold the CSV's f64s: corrected natively they give the CSV's
    // rows, in the f32 kernel (each value rounded once to f32 either way)
    // and in the f64 reference, with and without g-sensitivity and
    // temperature terms.
    let d = dir("correct");
    let csv = d.join("imu.csv");
    std::fs::write(&csv, source_without_temp()).unwrap();
    for calib in ["default.toml", "lab-example.toml"] {
        for extra in [&[][..], &["--exact"][..]] {
            let want = corrected(calib, &csv, extra);
            for bag in &BAGS[..4] {
                assert_eq!(
                    corrected(calib, &fixture(bag), extra),
                    want,
                    "{bag} {calib} {extra:?}"
                );
            }
        }
    }
}

#[test]
fn correct_on_one_triad_corrects_what_is_there_and_refuses_a_gyro_that_needs_g() {
    let d = dir("correct-one-triad");
    let (mut acc, mut gyr) = (String::new(), String::new());
    for line in source_without_temp().lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        acc += &format!("{} {} {} {}\n", c[0], c[1], c[2], c[3]);
        gyr += &format!("{} {} {} {}\n", c[0], c[4], c[5], c[6]);
    }
    let (a, g) = (d.join("acc.txt"), d.join("gyr.txt"));
    std::fs::write(&a, acc).unwrap();
    std::fs::write(&g, gyr).unwrap();
    // The accelerometer's correction does not depend on the gyroscope: the
    // imu_tk file's rows are the accel columns of the whole record's.
    let whole = corrected("default.toml", &fixture("imu.bag"), &[]);
    let want: String = whole
        .lines()
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    assert_eq!(corrected("default.toml", &a, &[]), want);
    // The default calibration has G: a gyro alone cannot be corrected with it.
    let calib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../calibrations/default.toml");
    refused(
        &["correct", "--calib", s(&calib), s(&g)],
        &["gyr.txt", "gyroscope only", "g-sensitivity"],
    );
}
