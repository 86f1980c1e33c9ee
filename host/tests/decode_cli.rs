//! `triad decode` end to end: a recorded stream in, CSV and a summary out.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

use triad::protocol::{encode, Flags, Frame, MAX_ENCODED_LEN};

const TRIAD: &str = env!("CARGO_BIN_EXE_triad");

fn frame(sequence: u32, timestamp_us: u32) -> Frame {
    let s = sequence as f32;
    Frame {
        sequence,
        timestamp_us,
        flags: if sequence.is_multiple_of(3) {
            Flags::GYRO_CLIPPED
        } else {
            Flags::empty()
        },
        overruns: 0,
        dropped: 0,
        calibration_id: 7,
        accel: [0.1 + s * 1e-3, -9.80665, 1.0e-30],
        gyro: [f32::MIN_POSITIVE, -0.0175 * s, 3.0e38],
        temperature: 21.5 + s / 7.0,
    }
}

fn encoded(f: &Frame) -> Vec<u8> {
    let mut out = [0u8; MAX_ENCODED_LEN];
    let n = encode(f, &mut out);
    out[..n].to_vec()
}

/// A temporary file that removes itself.
struct TempFile(PathBuf);

impl TempFile {
    fn with(name: &str, bytes: &[u8]) -> TempFile {
        let path = std::env::temp_dir().join(format!("triad-decode-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        TempFile(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn run(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let mut child = Command::new(TRIAD)
        .arg("decode")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut pipe = child.stdin.take().unwrap();
    let input = stdin.unwrap_or_default().to_vec();
    // Written from a thread: the decoder may stop (--max-frames) before
    // reading everything, which closes the pipe early.
    let writer = std::thread::spawn(move || match pipe.write_all(&input) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {}
        other => other.unwrap(),
    });
    let output = child.wait_with_output().unwrap();
    writer.join().unwrap();
    output
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).unwrap()
}

/// Parsed CSV rows: (seq, t, values, flags).
fn rows(stdout: &str) -> Vec<(u32, String, [f32; 7], u16)> {
    let mut lines = stdout.lines();
    assert_eq!(lines.next(), Some("seq,t,ax,ay,az,gx,gy,gz,temp,flags"));
    lines
        .map(|line| {
            let cols: Vec<&str> = line.split(',').collect();
            assert_eq!(cols.len(), 10, "{line}");
            let mut values = [0f32; 7];
            for (v, c) in values.iter_mut().zip(&cols[2..9]) {
                *v = c.parse().unwrap_or_else(|_| panic!("{c:?} is not an f32"));
            }
            (
                cols[0].parse().unwrap(),
                cols[1].to_string(),
                values,
                cols[9].parse().unwrap(),
            )
        })
        .collect()
}

fn summary_value(stderr: &str, key: &str) -> String {
    stderr
        .lines()
        .find_map(|l| l.strip_prefix(&format!("{key}: ")))
        .unwrap_or_else(|| panic!("no {key:?} in summary:\n{stderr}"))
        .to_string()
}

#[test]
fn file_with_damage_gives_exact_csv_and_counts() {
    // Joined 10 bytes into frame 0; frame 4 corrupted (CRC error); frame 7
    // missing entirely (gap); 5 bytes of frame 10 at the end.
    let mut bytes = encoded(&frame(0, 0))[10..].to_vec();
    let mut sent = Vec::new();
    for seq in 1..10u32 {
        let mut e = encoded(&frame(seq, seq * 1000));
        if seq == 4 {
            e[30] ^= 0x04;
            assert_ne!(e[30], 0);
        }
        if seq == 7 {
            continue;
        }
        if seq != 4 {
            sent.push(frame(seq, seq * 1000));
        }
        bytes.extend(e);
    }
    bytes.extend(&encoded(&frame(10, 10_000))[..5]);
    let file = TempFile::with("damage.bin", &bytes);
    let out = run(&[file.0.to_str().unwrap()], None);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    let got = rows(&text(&out.stdout));
    assert_eq!(got.len(), sent.len());
    for ((seq, t, values, flags), want) in got.iter().zip(&sent) {
        assert_eq!(*seq, want.sequence);
        assert_eq!(*t, format!("0.{:06}", want.timestamp_us));
        let want_values = [
            want.accel[0],
            want.accel[1],
            want.accel[2],
            want.gyro[0],
            want.gyro[1],
            want.gyro[2],
            want.temperature,
        ];
        for (g, w) in values.iter().zip(want_values) {
            assert_eq!(
                g.to_bits(),
                w.to_bits(),
                "seq {seq}: printed value does not round-trip"
            );
        }
        assert_eq!(*flags, want.flags.bits());
    }
    assert_eq!(summary_value(&stderr, "frames"), "7 (7 stored as CSV rows)");
    assert_eq!(summary_value(&stderr, "crc errors"), "1");
    assert_eq!(summary_value(&stderr, "malformed"), "0");
    assert_eq!(summary_value(&stderr, "sequence gaps"), "2 (2 frames lost)");
    let total = bytes.len();
    let skipped = (MAX_ENCODED_LEN - 10) + MAX_ENCODED_LEN;
    assert_eq!(
        summary_value(&stderr, "bytes"),
        format!("{total} ({skipped} skipped)")
    );
    assert_eq!(
        summary_value(&stderr, "incomplete frame at the end"),
        "5 bytes"
    );
}

#[test]
fn standard_input_by_dash_or_by_default() {
    let bytes: Vec<u8> = (0..5).flat_map(|s| encoded(&frame(s, s * 10))).collect();
    for args in [&["-"][..], &[][..]] {
        let out = run(args, Some(&bytes));
        assert!(out.status.success());
        let seqs: Vec<u32> = rows(&text(&out.stdout)).iter().map(|r| r.0).collect();
        assert_eq!(seqs, vec![0, 1, 2, 3, 4]);
    }
}

#[test]
fn max_frames_and_seconds_stop_early() {
    // 1 kHz for 3 s, starting at t = 5 s.
    let bytes: Vec<u8> = (0..3000)
        .flat_map(|s| encoded(&frame(s, 5_000_000 + s * 1000)))
        .collect();
    let out = run(&["--max-frames", "25"], Some(&bytes));
    assert_eq!(rows(&text(&out.stdout)).len(), 25);
    assert!(text(&out.stderr).contains("--max-frames reached"));
    let out = run(&["--seconds", "1.5"], Some(&bytes));
    let got = rows(&text(&out.stdout));
    // Frames at elapsed 0, 1 ms, …, 1499 ms are inside 1.5 s.
    assert_eq!(got.len(), 1500);
    assert_eq!(got.last().unwrap().1, "6.499000");
    assert!(text(&out.stderr).contains("--seconds reached"));
}

#[test]
fn time_keeps_rising_across_the_timestamp_wrap() {
    let ts = [u32::MAX - 999, u32::MAX, 999_999];
    let bytes: Vec<u8> = ts
        .iter()
        .enumerate()
        .flat_map(|(i, &t)| encoded(&frame(i as u32, t)))
        .collect();
    let out = run(&[], Some(&bytes));
    let t: Vec<String> = rows(&text(&out.stdout)).into_iter().map(|r| r.1).collect();
    // 2³² µs = 4294.967296 s; the third is 1 000 000 µs after the wrap.
    assert_eq!(t, vec!["4294.966296", "4294.967295", "4295.967295"]);
}

#[test]
fn non_finite_values_are_printed_parseably() {
    let mut f = frame(0, 0);
    f.accel = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let out = run(&[], Some(&encoded(&f)));
    let line = text(&out.stdout).lines().nth(1).unwrap().to_string();
    assert!(line.starts_with("0,0.000000,NaN,inf,-inf,"), "{line}");
}

#[test]
fn unreadable_file_names_the_path_and_the_reason() {
    let out = run(&["/nonexistent/dir/stream.bin"], None);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("/nonexistent/dir/stream.bin"), "{stderr}");
    assert!(stderr.to_lowercase().contains("no such file"), "{stderr}");
}

#[test]
fn unopenable_port_names_the_port() {
    let out = run(
        &["--port", "/dev/triad-no-such-port", "--baud", "921600"],
        None,
    );
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("/dev/triad-no-such-port"), "{stderr}");
    assert!(stderr.contains("921600"), "{stderr}");
}

#[test]
fn bad_seconds_is_rejected_with_its_value() {
    for bad in ["-2", "0", "NaN", "inf"] {
        let out = run(&["--seconds", bad], Some(&[]));
        assert!(!out.status.success(), "{bad}");
        let stderr = text(&out.stderr);
        assert!(stderr.contains(&format!("--seconds {bad}")), "{stderr}");
    }
}

#[test]
fn the_help_says_what_a_raw_frame_becomes() {
    let out = run(&["--help"], None);
    assert!(out.status.success());
    let help = text(&out.stdout).replace('\n', " ");
    for words in [
        "A raw frame",
        "the chip's counts times the nominal scale the frame carries",
        "RAW 0x40 and UNCALIBRATED 0x20",
        "Replies and commands in the stream are counted",
    ] {
        assert!(help.contains(words), "{words:?} not in {help}");
    }
}

#[test]
fn a_batch_frame_is_a_row_per_sample_at_its_own_time() {
    use triad::protocol::{BatchFrame, MAX_WIRE_LEN};
    let (a_lsb, g_lsb) = (0.01f32, 0.001f32);
    let mut batch = BatchFrame::new(a_lsb, g_lsb);
    batch.sequence = 3;
    batch.timestamp_us = 2_000_000;
    batch.period_ns = 125_000; // 8 kHz: rows 125 µs apart
    batch.temperature = 30.0;
    for i in 0..4 {
        batch.push([i as f32, 0.0, 9.8], [0.0, 0.0, 0.01 * i as f32]);
    }
    let mut wire = [0u8; MAX_WIRE_LEN];
    let n = batch.to_packet().unwrap().to_wire(&mut wire);
    let mut bytes = vec![0u8];
    bytes.extend_from_slice(&wire[..n]);
    bytes.extend(encoded(&frame(4, 2_000_500)));
    let out = run(&["-"], Some(&bytes));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let rows = rows(&text(&out.stdout));
    assert_eq!(rows.len(), 5);
    let times: Vec<&str> = rows.iter().map(|r| r.1.as_str()).collect();
    assert_eq!(
        times,
        ["2.000000", "2.000125", "2.000250", "2.000375", "2.000500"]
    );
    for (i, r) in rows.iter().take(4).enumerate() {
        assert_eq!(r.0, 3, "the rows of a batch share its sequence number");
        let (a, g) = batch.sample_si(i).unwrap();
        assert_eq!([r.2[0], r.2[2], r.2[5], r.2[6]], [a[0], a[2], g[2], 30.0]);
    }
    assert_eq!(
        summary_value(&text(&out.stderr), "sequence gaps"),
        "0 (0 frames lost)"
    );
}
