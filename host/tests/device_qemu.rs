//! End to end on the emulated board served like hardware: the firmware on
//! QEMU behind `xtask serve --storage FILE`, driven over its pseudo-terminal
//! by the real `triad device` binary (and, where a test reads the frames
//! themselves, by the host's transport, `triad_host::device::link`).
//!
//! Each test serves a fresh storage file. Except where it measures what a
//! user sees, QEMU runs with `--deterministic` (`-icount`: one instruction
//! per virtual nanosecond), so a loaded host cannot make the board overrun;
//! the board then runs at about half of real time here. The raw sample
//! behind a frame is known by replaying the chip model on the host
//! (`emulated_board::Replay`).
//!
//! The link runs at the board's 921600 baud in name only: QEMU's USART sends
//! each byte at once and a pseudo-terminal has no baud, so what is checked
//! here is the firmware's logic (priorities, queues, storage), not a wire's
//! timing. The emulated chip samples at its driver configuration's rate
//! (1 kHz for the ICM-42688-P, the default chip), every sample streamed
//! (decimation 1): the highest rate the firmware runs.
//!
//! Run by `cargo xtask test` (it sets TRIAD_SERVE_XTASK, TRIAD_PEERS_PYTHON, TRIAD_SERVE_ELF and
//! TRIAD_SERVE_BLOB); ignored in a plain `cargo test`.

mod emulated_board;
mod served_board;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use emulated_board::{decoded_csv, triad_correct, Replay};
use served_board::{env_path, frames, test_dir, text, Clock, ServedBoard};
use triad::device::start_calibration;
use triad::model::{blob, Corrector};
use triad::protocol::{CalibrationSource, Command, Mode, Packet, RawFrame, RawScale};
use triad::protocol::{Flags, Frame};
use triad_host::calib::file as calib_file;
use triad_host::device::{identify, transfer};
use triad_sim::chips::emulated_board::DESCRIPTION;

/// Long enough for a few thousand frames at half of real time on a loaded machine.
const STREAM_TIMEOUT: Duration = Duration::from_secs(60);

/// The id of the calibration built into the firmware under test.
fn built_in_id() -> u32 {
    let bytes = std::fs::read(env_path("TRIAD_SERVE_BLOB")).expect("the built-in blob");
    blob::decode(&bytes).expect("the built-in blob decodes").id
}

/// A valid calibration other than the built-in one, with the id `id` and a
/// correction the size of a consumer IMU's; `offset` shifts its accel bias,
/// so two files differ. No temperature terms and no orientation: what the
/// device applies is exactly what `triad correct` applies.
fn calibration_file(d: &Path, id: u32, offset: f64) -> PathBuf {
    let text = format!(
        "id = {id:#010x}\n\
         [accel]\n\
         scale_misalignment = [[1.01, 0.002, 0.0], [0.0, 0.995, -0.001], [0.003, 0.0, 1.004]]\n\
         bias = [{}, -0.2, 0.15]\n\
         [gyro]\n\
         scale_misalignment = [[0.998, 0.0, 0.001], [0.0, 1.002, 0.0], [0.0, 0.0, 1.0]]\n\
         bias = [0.01, -0.004, 0.002]\n",
        0.3 + offset
    );
    let path = d.join(format!("{id:08x}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn data(packet: &Packet) -> &Frame {
    match packet {
        Packet::Data(frame) => frame,
        other => panic!("a data frame expected, got {other:?}"),
    }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Uploads `file` and saves it; `save`'s stdout.
fn upload_and_save(board: &ServedBoard, file: &Path) -> String {
    board.device_ok(&["upload", s(file)]);
    board.device_ok(&["save"])
}

/// `info`'s line `calibration: ID (SOURCE)` and `stored: STATE` as `triad device info` prints them.
fn assert_info(board: &ServedBoard, id: u32, source: &str, stored: &str) {
    let out = board.device_ok(&["info"]);
    let calibration = format!("calibration: {id:#010x} ({source})");
    let stored = format!("stored: {stored}");
    assert!(
        out.lines().any(|l| l == calibration) && out.lines().any(|l| l == stored),
        "{calibration:?} and {stored:?} in:\n{out}"
    );
}

/// The next `count` frames all carry calibration `id`.
fn assert_stream_id(board: &ServedBoard, id: u32, count: usize) {
    let mut link = board.link();
    for packet in frames(&mut link, count, STREAM_TIMEOUT) {
        let frame = data(&packet);
        assert_eq!(frame.calibration_id, id, "frame {}", frame.sequence);
        assert!(!frame.flags.contains(Flags::UNCALIBRATED));
    }
}

/// The frames' sequence numbers map to the chip model's samples only if the
/// device dropped no frame and failed no read (see `Replay`).
fn assert_replayable<P: std::io::Read + std::io::Write>(
    link: &mut triad_host::device::link::Link<P>,
) {
    let counters = identify(link).unwrap().counters;
    assert_eq!(
        (counters.frames_dropped, counters.read_failures),
        (0, 0),
        "{counters:?}"
    );
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn an_upload_changes_the_streams_calibration_to_triad_corrects_values() {
    let d = test_dir("upload");
    let file = calibration_file(&d, 0x1234_5678, 0.0);
    let cal = calib_file::load(&file).unwrap().calibration;
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    let built_in = built_in_id();
    assert_stream_id(&board, built_in, 50);

    let out = board.device_ok(&["upload", s(&file)]);
    assert!(out.contains("calibration 0x12345678 active"), "{out}");
    assert_info(&board, 0x1234_5678, "uploaded", "empty");

    // What was queued before the upload still carries the built-in id; then
    // every frame carries the new one.
    let mut link = board.link();
    let mut new = Vec::new();
    while new.len() < 1000 {
        for packet in frames(&mut link, 100, STREAM_TIMEOUT) {
            let frame = *data(&packet);
            match frame.calibration_id {
                id if id == cal.id => new.push(frame),
                id if id == built_in && new.is_empty() => {}
                id => panic!("frame {}: calibration {id:#010x}", frame.sequence),
            }
        }
    }
    assert_replayable(&mut link);

    let mut replay = Replay::from_env();
    let scale = replay.scale();
    let host = Corrector::new(&cal, &scale, DESCRIPTION.orientation).unwrap();
    let mut raws = Vec::with_capacity(new.len());
    for frame in &new {
        let raw = replay.of_frame(frame.sequence);
        assert_eq!(
            bits(&decoded_csv::frame_values(frame)),
            bits(&decoded_csv::sample_values(&host.correct(&raw))),
            "frame {}",
            frame.sequence
        );
        raws.push(raw);
    }
    let times_s: Vec<f64> = new
        .iter()
        .map(|f| f64::from(f.timestamp_us) * 1e-6)
        .collect();
    let streamed: Vec<[f32; 6]> = new
        .iter()
        .map(|f| {
            [
                f.accel[0], f.accel[1], f.accel[2], f.gyro[0], f.gyro[1], f.gyro[2],
            ]
        })
        .collect();
    // The file's (I+Σ)⁻¹ has absolute row sums below 1.02 and |b| below
    // 0.4 SI units: the bound's premise holds.
    let worst =
        triad_correct::agrees_with_firmware(&file, &raws, &times_s, &scale, &streamed, [0.0; 2]);
    println!(
        "upload: {} frames with the new id equal the host's correction bit for bit; \
         triad correct within {worst:.3} of the f32 bound",
        new.len()
    );
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_saved_calibration_starts_the_next_run_and_an_erased_one_leaves_the_built_in() {
    let d = test_dir("save");
    let file = calibration_file(&d, 0x5a5a_0001, 0.0);
    let storage = d.join("storage.bin");
    let built_in = built_in_id();
    {
        let board = ServedBoard::start(&storage, Clock::Deterministic, None);
        assert_info(&board, built_in, "built in", "empty");
        assert_eq!(
            upload_and_save(&board, &file),
            "saved calibration 0x5a5a0001 to flash (generation 1, slot 0)\n"
        );
    }
    {
        let board = ServedBoard::start(&storage, Clock::Deterministic, None);
        assert_info(&board, 0x5a5a_0001, "stored", "valid");
        assert_stream_id(&board, 0x5a5a_0001, 200);
        board.device_ok(&["erase"]);
        // The stored one runs until restart.
        assert_info(&board, 0x5a5a_0001, "stored", "empty");
    }
    let erased = std::fs::read(&storage).unwrap();
    assert!(
        erased.iter().all(|&b| b == 0xFF),
        "erase leaves erased flash"
    );
    let board = ServedBoard::start(&storage, Clock::Deterministic, None);
    assert_info(&board, built_in, "built in", "empty");
    assert_stream_id(&board, built_in, 200);
}

/// Flash gone bad between two runs (issue 26): a bit flipped in the saved
/// record, then a whole record whose blob is of a later version. Each run
/// starts the built-in calibration and `info` says why the stored one was
/// rejected.
#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_stored_record_gone_bad_is_rejected_with_the_reason_and_the_built_in_runs() {
    let d = test_dir("gone-bad");
    let file = calibration_file(&d, 0x5a5a_0002, 0.0);
    let storage = d.join("storage.bin");
    let built_in = built_in_id();
    {
        let board = ServedBoard::start(&storage, Clock::Deterministic, None);
        upload_and_save(&board, &file);
    }
    let saved = std::fs::read(&storage).unwrap();
    // Slot 0: the record's 16-byte header (magic TRST), then the blob.
    assert_eq!(&saved[..4], b"TRST");
    let mut flipped = saved.clone();
    flipped[16 + 200] ^= 0x10;
    std::fs::write(&storage, &flipped).unwrap();
    {
        let board = ServedBoard::start(&storage, Clock::Deterministic, None);
        assert_info(
            &board,
            built_in,
            "built in",
            "rejected (the record fails its check (a flipped bit, a cut save or erase, foreign data))",
        );
        assert_stream_id(&board, built_in, 50);
    }
    // A whole record (its CRC good) over a blob of the next version.
    let mut future = saved.clone();
    let blob_at = 16;
    future[blob_at + 4] = blob::VERSION + 1;
    let len = blob::BLOB_LEN;
    let blob_crc = triad::protocol::crc32c(&future[blob_at..blob_at + len - 4]);
    future[blob_at + len - 4..blob_at + len].copy_from_slice(&blob_crc.to_le_bytes());
    // The record's CRC: its generation and length (header bytes 4..12), then the blob.
    let mut covered = future[4..12].to_vec();
    covered.extend_from_slice(&future[blob_at..blob_at + len]);
    let record_crc = triad::protocol::crc32c(&covered);
    future[12..16].copy_from_slice(&record_crc.to_le_bytes());
    std::fs::write(&storage, &future).unwrap();
    let board = ServedBoard::start(&storage, Clock::Deterministic, None);
    assert_info(
        &board,
        built_in,
        "built in",
        "rejected (the record's calibration blob is of a version this firmware does not read)",
    );
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_bad_upload_is_refused_with_calib_checks_reason_and_changes_nothing() {
    let d = test_dir("bad");
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    let built_in = built_in_id();
    let bad_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../calibrations/bad");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&bad_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut refused_by_device = Vec::new();
    for bad in &files {
        let check = std::process::Command::new(env!("CARGO_BIN_EXE_triad"))
            .args(["calib", "check"])
            .arg(bad)
            .output()
            .unwrap();
        assert!(
            !check.status.success(),
            "{} passes calib check",
            bad.display()
        );
        let check_err = text(&check.stderr);
        let reason = check_err
            .trim_end()
            .strip_prefix(&format!("triad: {}: ", bad.display()))
            .unwrap_or_else(|| panic!("{check_err}"));
        let out = board.device(&["upload", s(bad)]);
        assert_eq!(out.status.code(), Some(1), "{}", bad.display());
        let err = text(&out.stderr);
        // A file that does not even read as a calibration is refused by the
        // host, with calib check's message; any other reaches the device,
        // which gives calib check's reason.
        let device_says =
            format!("triad: upload commit: the device answered invalid calibration: {reason}\n");
        if err == device_says {
            refused_by_device.push(bad.file_name().unwrap().to_string_lossy().into_owned());
        } else {
            assert_eq!(err, check_err, "{}", bad.display());
        }
    }
    assert!(
        refused_by_device.contains(&"singular.toml".to_string()),
        "{refused_by_device:?}"
    );
    let mut link = board.link();
    let info = identify(&mut link).unwrap();
    assert_eq!(
        (info.calibration_id, info.calibration_source),
        (built_in, CalibrationSource::BuiltIn)
    );
    assert_eq!(
        info.counters.command_errors as usize,
        refused_by_device.len(),
        "one error per refused commit"
    );
    drop(link);
    assert_stream_id(&board, built_in, 200);
    println!(
        "bad uploads: {} of {} files refused by the device ({refused_by_device:?}), the rest by the host",
        refused_by_device.len(),
        files.len()
    );
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn raw_frames_carry_the_chips_counts_which_scaled_are_the_uncalibrated_values() {
    let d = test_dir("raw");
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    let out = board.device_ok(&["raw"]);
    assert!(out.starts_with("mode: raw"), "{out}");

    let mut replay = Replay::from_env();
    let scale = replay.scale();
    // What a firmware without a calibration streams: the start-up identity.
    let uncalibrated = start_calibration(None, &[], &scale, DESCRIPTION.orientation)
        .unwrap()
        .corrector;
    let mut link = board.link();
    let mut raw: Vec<RawFrame> = Vec::new();
    while raw.len() < 500 {
        for packet in frames(&mut link, 100, STREAM_TIMEOUT) {
            match packet {
                Packet::Raw(frame) => raw.push(frame),
                // Queued before the switch.
                Packet::Data(_) if raw.is_empty() => {}
                other => panic!("after a raw frame: {other:?}"),
            }
        }
    }
    let info = identify(&mut link).unwrap();
    assert_eq!(info.scale, RawScale::of(&scale), "identify's scale");
    assert_replayable(&mut link);
    drop(link);
    for frame in &raw {
        let n = frame.sequence;
        let sample = replay.of_frame(n);
        // Counts: the chip's registers, exactly.
        assert_eq!(
            frame.accel,
            sample.accel.map(|x| x as f32),
            "accel of frame {n}"
        );
        assert_eq!(
            frame.gyro,
            sample.gyro.map(|x| x as f32),
            "gyro of frame {n}"
        );
        assert_eq!(frame.temperature, f32::from(sample.temperature));
        assert_eq!(frame.scale, info.scale, "frame {n}");
        assert!(frame.flags.contains(Flags::RAW.union(Flags::UNCALIBRATED)));
        // Scaled: what the uncalibrated firmware computes, bit for bit.
        let (a, g, t) = frame.to_si();
        let want = uncalibrated.correct(&sample);
        assert_eq!(bits(&a), bits(&want.accel), "accel of frame {n}");
        assert_eq!(bits(&g), bits(&want.gyro), "gyro of frame {n}");
        assert_eq!(t.to_bits(), want.temperature.to_bits(), "frame {n}");
    }

    // `triad device stream` prints raw frames scaled, flagged RAW and UNCALIBRATED.
    let rows = decoded_csv::rows(&board.device_ok(&["stream", "--max-frames", "100"]));
    assert_eq!(rows.len(), 100);
    for row in &rows {
        let want = uncalibrated.correct(&replay.of_frame(row.sequence));
        let want = decoded_csv::sample_values(&want);
        assert_eq!(bits(&row.values), bits(&want), "{row:?}");
        assert!(
            row.flags.contains(Flags::RAW.union(Flags::UNCALIBRATED)),
            "{row:?}"
        );
    }

    board.device_ok(&["calibrated"]);
    let mut link = board.link();
    let last = frames(&mut link, 200, STREAM_TIMEOUT);
    assert!(matches!(last.last(), Some(Packet::Data(_))), "{last:?}");
    println!(
        "raw mode: {} raw frames are the chip model's counts, scaled bit for bit as uncalibrated",
        raw.len()
    );
}

/// The rows an independent reader (Python's mcap and mcap-ros2-support,
/// host/tests/peers/recordings.py) reads from the MCAP at `mcap`:
/// t (ns), ax..gz, temp, seq, flags.
fn read_by_python(mcap: &Path, out: &Path) -> Vec<Vec<f64>> {
    let python = env_path("TRIAD_PEERS_PYTHON");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/recordings.py");
    let o = std::process::Command::new(python)
        .arg(script)
        .args(["read-mcap", s(mcap), s(out)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,ax,ay,az,gx,gy,gz,temp,seq,flags"));
    lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect()
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_stream_recorded_as_mcap_opens_in_python_with_every_sample() {
    let d = test_dir("stream-mcap");
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    // Raw frames: each value is then known exactly from the chip model.
    board.device_ok(&["raw"]);
    let mut replay = Replay::from_env();
    let uncalibrated = start_calibration(None, &[], &replay.scale(), DESCRIPTION.orientation)
        .unwrap()
        .corrector;
    const FRAMES: usize = 2000;
    let mcap = d.join("rec.mcap");
    board.device_ok(&[
        "stream",
        "--max-frames",
        &FRAMES.to_string(),
        "--out",
        s(&mcap),
    ]);
    let rows = read_by_python(&mcap, &d.join("python.csv"));
    assert_eq!(rows.len(), FRAMES, "every frame streamed is in the bag");
    let first = rows[0][8] as u32;
    for (k, row) in rows.iter().enumerate() {
        let seq = row[8] as u32;
        assert_eq!(seq, first + k as u32, "no frame missing or repeated");
        if k > 0 {
            assert!(row[0] > rows[k - 1][0], "stamps increase: row {k}");
        }
        let flags = Flags::from_bits_retain(row[9] as u16);
        assert!(
            flags.contains(Flags::RAW.union(Flags::UNCALIBRATED)),
            "frame {seq}"
        );
        // The bag's f64 is the CSV's shortest decimal of the firmware's f32.
        let got: Vec<f32> = row[1..8].iter().map(|&v| v as f32).collect();
        let want = decoded_csv::sample_values(&uncalibrated.correct(&replay.of_frame(seq)));
        assert_eq!(bits(&got), bits(&want), "frame {seq}");
    }
    println!(
        "triad device stream --out rec.mcap: {FRAMES} frames from {first}, every one read back by Python's mcap-ros2-support as the chip model's sample"
    );
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn commands_while_streaming_at_the_full_rate_cost_no_overrun_and_no_frame() {
    let d = test_dir("busy");
    let file = calibration_file(&d, 0x0b05_0001, 0.0);
    let upload = blob::encode(&calib_file::load(&file).unwrap().calibration);
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    let mut link = board.link();
    // Past whatever the port held when it was opened.
    let first = frames(&mut link, 20, STREAM_TIMEOUT);
    let start_seq = data(first.last().unwrap()).sequence;
    let before = *link.stats();
    let info = identify(&mut link).unwrap();
    let rate = info.sample_rate_hz;
    assert_eq!(info.decimation, 1);

    // Every command but the self-test (which pauses sampling by design),
    // back to back, for at least 1000 frames (a second of stream). Each
    // succeeds: a change the sampling task has not taken yet (it takes one
    // per sample, two queued at most) is answered busy, counted as a
    // command error, and asked again by the link.
    let mut rounds = 0u32;
    let mut last_seq = start_seq;
    let started = Instant::now();
    while last_seq < start_seq + 1000 {
        assert!(started.elapsed() < STREAM_TIMEOUT, "the stream stalled");
        link.command(&Command::Identify).unwrap();
        link.command(&Command::SetMode(Mode::Calibrated)).unwrap();
        link.command(&Command::SetDecimation(1)).unwrap();
        transfer::upload(&mut link, &upload).unwrap();
        transfer::download(&mut link).unwrap().unwrap();
        link.command(&Command::Save).unwrap();
        link.command(&Command::Erase).unwrap();
        rounds += 1;
        // The newest frame's number (the replies' waits skip frames).
        let next = frames(&mut link, 1, STREAM_TIMEOUT);
        last_seq = data(&next[0]).sequence;
    }
    let after = *link.stats();
    let counters = identify(&mut link).unwrap().counters;
    let frames_seen = after.frames - before.frames;
    println!(
        "{} commands ({rounds} rounds of identify, mode, decimation, upload, read back, save, \
         erase) while streaming {frames_seen} frames at {rate} Hz, decimation 1, 921600 baud \
         (nominal: QEMU and the pty ignore it), deterministic clock: overruns {}, dropped {}, \
         sequence gaps {}; {} busy replies, each asked again",
        counters.commands,
        counters.overruns,
        counters.frames_dropped,
        after.sequence_gaps - before.sequence_gaps,
        counters.command_errors
    );
    assert!(frames_seen >= 1000, "{frames_seen} frames");
    assert_eq!(after.sequence_gaps, before.sequence_gaps, "{after:?}");
    assert_eq!(after.crc_errors, before.crc_errors, "{after:?}");
    assert_eq!(after.device_overruns, before.device_overruns, "{after:?}");
    assert_eq!(after.device_dropped, before.device_dropped, "{after:?}");
    // The emulated board's flash (a host file) never stalls its CPU, however
    // many saves and erases.
    assert_eq!(
        (
            counters.overruns,
            counters.frames_dropped,
            counters.rx_overflows,
            counters.flash_stalls
        ),
        (0, 0, 0, 0),
        "{counters:?}"
    );
    // At least identify, mode, decimation, commit, a read, save, erase per round.
    assert!(counters.commands >= 7 * rounds, "{counters:?}");
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_self_test_stops_no_task_and_the_frame_after_counts_exactly_the_samples_it_missed() {
    use std::io::Write as _;
    let d = test_dir("selftest");
    let board = ServedBoard::start(&d.join("storage.bin"), Clock::Deterministic, None);
    // The link, and a second handle on its port to send the command
    // through, so that the link sees every frame around it (its own
    // exchange would skip them).
    let port = triad_host::plumbing::serial::open(
        board.port(),
        served_board::BAUD,
        Duration::from_millis(20),
    )
    .expect("opening the served port");
    let mut writer = port.try_clone().expect("a second handle on the port");
    let settings = triad_host::device::link::Settings {
        timeout: Duration::from_secs(2),
        tries: 3,
    };
    let mut link = triad_host::device::link::Link::new(port, settings, board.port().into(), 0x4000);
    // Streaming (data frames, or batch frames with the FIFO on).
    let deadline = Instant::now() + STREAM_TIMEOUT;
    let mut streamed = 0;
    while streamed < 20 {
        match link.next_packet(deadline).expect("reading the port") {
            Some(Ok(Packet::Data(_) | Packet::Batch(_))) => streamed += 1,
            Some(_) => {}
            None => panic!("{streamed} of 20 frames within {STREAM_TIMEOUT:?}"),
        }
    }
    let info = identify(&mut link).unwrap();
    assert_eq!(info.decimation, 1);
    let period_us = 1e6 / f64::from(info.sample_rate_hz);
    let overruns_before = info.counters.overruns;
    let mut wire = [0u8; triad::protocol::MAX_WIRE_LEN];
    let n = Command::SelfTest
        .to_packet(0x7001)
        .unwrap()
        .to_wire(&mut wire);
    writer.write_all(&[0]).unwrap();
    writer.write_all(&wire[..n]).unwrap();
    writer.flush().unwrap();

    // Every packet until 20 frames after the reply (data frames, or batch
    // frames from a firmware built with the FIFO on).
    let deadline = Instant::now() + STREAM_TIMEOUT;
    let (mut before, mut after, mut reply) = (Vec::new(), Vec::new(), None);
    while after.len() < 20 {
        let frame = match link.next_packet(deadline).expect("reading the port") {
            Some(Ok(Packet::Data(f))) => Seen::of_data(&f),
            Some(Ok(Packet::Batch(b))) => Seen::of_batch(&b),
            Some(Ok(Packet::Reply(r))) if r.sequence == 0x7001 => {
                reply = Some(r);
                continue;
            }
            Some(Ok(other)) => panic!("{other:?}"),
            Some(Err(e)) => panic!("a damaged packet: {e:?}"),
            None => panic!(
                "{} frames after the reply within {STREAM_TIMEOUT:?}",
                after.len()
            ),
        };
        match reply {
            None => before.push(frame),
            Some(_) => after.push(frame),
        }
    }
    let reply = reply.unwrap();
    assert_eq!(reply.status, triad::protocol::Status::Ok, "{reply:?}");
    assert!(before.iter().all(|f| !f.flags.contains(Flags::SELF_TEST)));
    // The reply goes out first; the first frame after it says what was missed.
    let (last, first) = (before.last().unwrap(), &after[0]);
    assert!(
        first.flags.contains(Flags::SELF_TEST | Flags::OVERRUN),
        "{first:?}"
    );
    // The chip's FIFO, flushed at the procedure's end, lost nothing of the
    // stream's own: no FIFO_OVERFLOW.
    assert!(!first.flags.contains(Flags::FIFO_OVERFLOW), "{first:?}");
    assert!(after[1..]
        .iter()
        .all(|f| !f.flags.contains(Flags::SELF_TEST)));
    assert_eq!(
        first.sequence,
        last.sequence + 1,
        "no frame lost on the way"
    );
    // From the last sample before to the first after.
    let last_sample_us = f64::from(last.timestamp_us) + f64::from(last.samples - 1) * period_us;
    let gap_us = f64::from(first.timestamp_us) - last_sample_us;
    let periods = (gap_us / period_us).round() as u16;
    println!(
        "self-test: {:.3} s between the samples around it at {} Hz, {} per frame, {} samples not measured",
        gap_us / 1e6,
        info.sample_rate_hz,
        first.samples,
        first.overruns
    );
    // The stream's time went on, and the count is that time's samples.
    assert!(
        gap_us > 0.1e6,
        "a data sheet's self-test takes longer: {gap_us} µs"
    );
    assert_eq!(first.overruns, periods - 1, "{gap_us} µs at {period_us} µs");
    let counters = identify(&mut link).unwrap().counters;
    assert_eq!(
        counters.overruns - overruns_before,
        u32::from(first.overruns),
        "every sample the device counts lost is the self-test's"
    );
}

/// What the self-test test reads of a data or batch frame.
#[derive(Debug)]
struct Seen {
    sequence: u32,
    /// Its first sample's time, µs (wrapping ignored: the test is short).
    timestamp_us: u32,
    samples: u32,
    flags: Flags,
    overruns: u16,
}

impl Seen {
    fn of_data(f: &Frame) -> Seen {
        Seen {
            sequence: f.sequence,
            timestamp_us: f.timestamp_us,
            samples: 1,
            flags: f.flags,
            overruns: f.overruns,
        }
    }

    fn of_batch(b: &triad::protocol::BatchFrame) -> Seen {
        Seen {
            sequence: b.sequence,
            timestamp_us: b.timestamp_us,
            samples: u32::from(b.count),
            flags: b.flags,
            overruns: b.overruns,
        }
    }
}

/// The storage file's two slots (16 KiB each).
const SLOT: usize = 16 * 1024;
/// A record's header before its blob.
const HEADER: usize = 16;

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn a_power_cut_during_a_save_leaves_the_old_calibration_or_the_new_one_whole() {
    let d = test_dir("cut");
    let storage = d.join("storage.bin");
    let old = calibration_file(&d, 0x01d0_0001, 0.0);
    let new = calibration_file(&d, 0x0e30_0002, 0.05);
    let new_blob = blob::encode(&calib_file::load(&new).unwrap().calibration);
    {
        let board = ServedBoard::start(&storage, Clock::Deterministic, None);
        upload_and_save(&board, &old);
    }
    let slot0 = std::fs::read(&storage).unwrap()[..SLOT].to_vec();

    // A save of the new calibration (into slot 1) is one erase, then the
    // blob's 64-byte writes (the last one short), then the header's write:
    // `operations` operations of the emulated flash. A cut before operation
    // n leaves n done. The order makes each cut's effect visible: after
    // n = operations − 1 slot 1 holds the whole blob, so n = 0 (before the
    // erase) is seen to leave it there.
    let writes = new_blob.len().div_ceil(64);
    let operations = (writes + 2) as u32;
    let cuts = std::iter::once(operations - 1).chain(0..operations - 1);
    for n in cuts {
        let mut board = ServedBoard::start(&storage, Clock::Deterministic, Some(n));
        // Whatever the last cut left, the old calibration starts, from flash.
        assert_info(&board, 0x01d0_0001, "stored", "valid");
        board.device_ok(&["upload", s(&new)]);
        let out = board.device(&["save"]);
        assert_eq!(out.status.code(), Some(1), "save cut at operation {n}");
        let status = board
            .wait_exit(Duration::from_secs(30))
            .unwrap_or_else(|| panic!("QEMU still runs after the cut at {n}"));
        assert!(!status.success());
        let log = board.log();
        assert!(log.contains("the firmware stopped QEMU"), "{log}");
        let flash = std::fs::read(&storage).unwrap();
        assert_eq!(flash[..SLOT], slot0[..], "slot 0 untouched (cut at {n})");
        let slot1 = &flash[SLOT..];
        let written = match n {
            0 => None,
            n => Some((64 * (n as usize - 1)).min(new_blob.len())),
        };
        if let Some(written) = written {
            assert!(slot1[..HEADER].iter().all(|&b| b == 0xFF), "header at {n}");
            let blob_end = HEADER + written;
            assert_eq!(slot1[HEADER..blob_end], new_blob[..written], "blob at {n}");
            assert!(
                slot1[blob_end..].iter().all(|&b| b == 0xFF),
                "erased at {n}"
            );
        } else {
            // Before the erase: the last run's whole blob is still there.
            assert_eq!(slot1[HEADER..HEADER + new_blob.len()], new_blob[..]);
        }
    }
    {
        // Every operation done: the save completes.
        let board = ServedBoard::start(&storage, Clock::Deterministic, Some(operations));
        assert_info(&board, 0x01d0_0001, "stored", "valid");
        assert_eq!(
            upload_and_save(&board, &new),
            "saved calibration 0x0e300002 to flash (generation 2, slot 1)\n"
        );
    }
    let board = ServedBoard::start(&storage, Clock::Deterministic, None);
    assert_info(&board, 0x0e30_0002, "stored", "valid");
    assert_stream_id(&board, 0x0e30_0002, 100);
}

/// The median and the largest of `v` (sorted here).
fn median_max(v: &mut [Duration]) -> (Duration, Duration) {
    v.sort();
    (v[v.len() / 2], v[v.len() - 1])
}

#[test]
#[ignore = "needs the served board of `cargo xtask test`"]
fn identify_round_trips_figure() {
    let d = test_dir("round-trip");
    for clock in [Clock::RealTime, Clock::Deterministic] {
        let board = ServedBoard::start(&d.join("storage.bin"), clock, None);
        // Nobody reads for a while: the pty fills up with the stream, as it
        // does before a user's first command.
        std::thread::sleep(Duration::from_millis(1500));
        let port =
            triad_host::plumbing::serial::open(board.port(), 921_600, Duration::from_millis(5))
                .expect("opening the served port");
        // One try each: a reply lost anywhere fails here.
        let settings = triad_host::device::link::Settings {
            timeout: Duration::from_secs(2),
            tries: 1,
        };
        let mut link = triad_host::device::link::Link::new(port, settings, "served".into(), 9);
        let mut times = Vec::with_capacity(100);
        for _ in 0..100 {
            let sent = Instant::now();
            identify(&mut link).unwrap();
            times.push(sent.elapsed());
        }
        let (median, max) = median_max(&mut times);
        println!(
            "identify round trip, {clock:?} clock, 921600 baud nominal (QEMU's USART and the pty \
             ignore it): median {median:?}, max {max:?} over 100"
        );
    }
}

/// `xtask serve` in other people's processes (issue 26): its stderr (notes
/// and the firmware's log) on a read-write /dev/null as Python's
/// `subprocess.DEVNULL` gives it, closed, full, or a pipe whose reader
/// left, costs nothing but the notes; its stdout (the port's path, what
/// scripts read) full or abandoned is an error naming standard output,
/// and closed is /dev/null (Rust's runtime reopens it so; the port is
/// still named on stderr).
#[test]
#[ignore = "needs the emulated board: run by cargo xtask test"]
fn serve_runs_with_its_standard_streams_on_other_peoples_files() {
    use std::fs::{File, OpenOptions};
    use std::io::{BufRead, BufReader};
    use std::process::{Command as Process, Stdio};

    let null_rw = || {
        OpenOptions::new()
            .read(true)
            .write(true)
            .open("/dev/null")
            .unwrap()
    };
    let full = || File::create("/dev/full").unwrap();
    let serve = |shell_redirect: &str| {
        let mut command = Process::new("sh");
        command
            .arg("-c")
            .arg(format!("exec \"$0\" serve --elf \"$1\" {shell_redirect}"))
            .arg(env_path("TRIAD_SERVE_XTASK"))
            .arg(env_path("TRIAD_SERVE_ELF"))
            .stdin(null_rw());
        command
    };
    // The port from the first stdout line; the board answers identify on it.
    let answers_identify = |mut child: std::process::Child, what: &str| {
        let stdout = child.stdout.take().unwrap();
        let port = BufReader::new(stdout).lines().next();
        let port = match port {
            Some(Ok(port)) => port,
            other => {
                let _ = child.kill();
                panic!("{what}: no port line ({other:?}, {:?})", child.wait());
            }
        };
        let out = Process::new(env!("CARGO_BIN_EXE_triad"))
            .args(["device", "--port", &port, "info"])
            .output()
            .unwrap();
        let _ = child.kill();
        let _ = child.wait();
        assert!(out.status.success(), "{what}: {}", text(&out.stderr));
        assert!(text(&out.stdout).contains("icm42688"), "{what}");
    };
    for (what, stderr) in [
        ("2> read-write /dev/null", Stdio::from(null_rw())),
        ("2> /dev/full", Stdio::from(full())),
    ] {
        let child = serve("")
            .stdout(Stdio::piped())
            .stderr(stderr)
            .spawn()
            .unwrap();
        answers_identify(child, what);
    }
    let closed = serve("2>&-").stdout(Stdio::piped()).spawn().unwrap();
    answers_identify(closed, "2>&-");
    let mut abandoned = serve("")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(abandoned.stderr.take());
    answers_identify(abandoned, "2> a pipe whose reader left");

    // stdout: the port cannot be told, so the board is not served.
    let out = serve("")
        .stdout(full())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let said = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "> /dev/full: {said}");
    assert!(
        said.contains("writing the port's path to standard output: No space left on device"),
        "{said}"
    );
    let mut gone = serve("")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(gone.stdout.take());
    let out = gone.wait_with_output().unwrap();
    let said = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "> abandoned pipe: {said}");
    assert!(
        said.contains("writing the port's path to standard output: Broken pipe"),
        "{said}"
    );
    // stdout closed: the port is on stderr.
    let mut closed = serve(">&-")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(closed.stderr.take().unwrap()).lines();
    let port = lines
        .find_map(|l| {
            let l = l.ok()?;
            let rest = l.split_once("link is ")?.1;
            Some(rest.split_whitespace().next()?.to_string())
        })
        .expect("the port named on stderr");
    std::thread::spawn(move || for _ in lines {});
    let out = Process::new(env!("CARGO_BIN_EXE_triad"))
        .args(["device", "--port", &port, "info"])
        .output()
        .unwrap();
    let _ = closed.kill();
    let _ = closed.wait();
    assert!(out.status.success(), ">&-: {}", text(&out.stderr));
}

/// The client of tests/protocol_client/client.py, written from
/// docs/PROTOCOL.md alone in another language (Python, standard library),
/// against the served board with an erased storage file: every check passes.
#[test]
#[ignore = "needs the emulated board and python3: run by cargo xtask test"]
fn a_client_written_from_the_protocol_document_alone_passes_every_check() {
    let d = test_dir("doc-client");
    let board = ServedBoard::start(&d.join("flash.bin"), Clock::Deterministic, None);
    let client = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/protocol_client/client.py");
    let out = std::process::Command::new("python3")
        .arg(&client)
        .arg(board.port())
        .output()
        .expect("running python3 (cargo xtask test installs it)");
    let said = text(&out.stdout);
    println!("{said}");
    assert!(
        out.status.success() && said.contains(" checks passed") && !said.contains("FAIL"),
        "{}\n{said}\n{}\nserve's log:\n{}",
        out.status,
        text(&out.stderr),
        board.log()
    );
}
