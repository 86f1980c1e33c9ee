//! `triad device` against a fake device: the core's real command handler and
//! sampler over the emulated board's chip model, on a thread (see
//! `device_cli/fake_device.rs`). The command line is run as a user runs it,
//! `--port /dev/pts/N`, the device on the other end of a pseudo-terminal;
//! the transport alone is driven over an in-memory pipe where a test needs
//! to lose a reply or script the other end.

mod fake_device;
mod pipe;
#[cfg(unix)]
mod pty;
mod ram_flash;
#[cfg(unix)]
mod session;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

use fake_device::{Applied, FakeDevice, Options};
use ram_flash::RamFlash;
use triad::device::Outgoing;
use triad::model::{blob, Corrector, Orientation};
use triad::protocol::{Command, Packet, Reply, Status};
use triad::protocol::{Decoder, Flags};
use triad_host::calib::file::{self as calib_file, CalibFile};
use triad_host::device::link::{Link, LinkError, Settings};
use triad_host::device::{identify, transfer};

/// `triad ARGS`, run to its end.
fn triad(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_triad"))
        .args(args)
        .output()
        .expect("run triad")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("device_cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The shipped default calibration, which the fake device has built in.
fn default_calibration() -> CalibFile {
    calib_file::load(Path::new("default")).unwrap()
}

fn options() -> Options {
    Options {
        built_in: blob::encode(&default_calibration().calibration).to_vec(),
        flash: None,
        drop_replies: Vec::new(),
        sample_every: Duration::from_millis(1),
    }
}

/// A valid calibration other than the default, with an id of its own and,
/// with `temperature`, temperature terms.
fn lab_file(d: &Path, temperature: bool) -> PathBuf {
    let mut text = "id = 0x12345678\n\
        [accel]\n\
        scale_misalignment = [[1.01, 0.002, 0.0], [0.0, 0.995, -0.001], [0.003, 0.0, 1.004]]\n\
        bias = [0.3, -0.2, 0.15]\n\
        [gyro]\n\
        scale_misalignment = [[0.998, 0.0, 0.001], [0.0, 1.002, 0.0], [0.0, 0.0, 1.0]]\n\
        bias = [0.01, -0.004, 0.002]\n"
        .to_string();
    if temperature {
        text += "[gyro.temperature]\n\
            reference_c = 25.0\n\
            bias_coefficients = [[1e-4, 0.0, 0.0], [0.0, -2e-4, 0.0], [0.0, 0.0, 5e-5]]\n\
            scale_misalignment_per_c = [[1e-5, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1e-5]]\n";
    }
    let path = d.join(if temperature {
        "lab-t.toml"
    } else {
        "lab.toml"
    });
    std::fs::write(&path, text).unwrap();
    path
}

/// `name: value` lines as a map.
fn fields(stdout: &str) -> HashMap<String, String> {
    stdout
        .lines()
        .filter_map(|l| l.split_once(": "))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

fn assert_ok(out: &Output) {
    assert!(
        out.status.success(),
        "stdout: {}\nstderr: {}",
        text(&out.stdout),
        text(&out.stderr)
    );
}

/// The CSV rows of a `stream` run: (seq, the seven values, flags).
fn rows(out: &Output) -> Vec<(u32, [f32; 7], u16)> {
    assert_ok(out);
    let csv = text(&out.stdout);
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("seq,t,ax,ay,az,gx,gy,gz,temp,flags"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let mut v = [0f32; 7];
            for (slot, x) in v.iter_mut().zip(&f[2..9]) {
                *slot = x.parse().unwrap();
            }
            (f[0].parse().unwrap(), v, f[9].parse().unwrap())
        })
        .collect()
}

/// The frame of sequence `seq` the device logged, with its raw sample.
fn logged(device: &FakeDevice, seq: u32) -> (Outgoing, triad::sensor::RawSample) {
    let log = device.log.lock().unwrap();
    *log.frames
        .iter()
        .find(|(f, _)| f.sequence() == seq)
        .unwrap_or_else(|| panic!("frame {seq} was not sent"))
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[cfg(unix)]
mod over_a_pty {
    use super::*;
    use pty::Pty;

    /// `triad device --port PTY ARGS`.
    fn device(pty: &Pty, args: &[&str]) -> Output {
        triad(&[&["device", "--port", &pty.path], args].concat())
    }

    fn info(pty: &Pty) -> HashMap<String, String> {
        let out = device(pty, &["info"]);
        assert_ok(&out);
        fields(&text(&out.stdout))
    }

    #[test]
    fn info_prints_every_field() {
        let pty = Pty::open();
        let fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
        fake.wait_frames(5);
        let f = info(&pty);
        let default_id = default_calibration().calibration.id;
        let expected = [
            (
                "link",
                format!("at 921600 baud on {}, protocol 2", pty.path),
            ),
            ("firmware", "fake-0.0.0".into()),
            ("board", "fake-board".into()),
            ("chip", "icm42688".into()),
            ("bus", "spi".into()),
            ("mode", "calibrated".into()),
            ("baud", "921600".into()),
            ("calibration", format!("{default_id:#010x} (built in)")),
            ("stored", "no storage".into()),
            ("command errors", "0".into()),
            ("rx overflows", "0".into()),
            ("flash stalls", "0".into()),
        ];
        for (key, value) in expected {
            assert_eq!(f.get(key), Some(&value), "{key} in {f:?}");
        }
        let rate = f["sample rate"]
            .trim_end_matches(" Hz")
            .parse::<f64>()
            .unwrap();
        assert_eq!(
            f["decimation"],
            format!("1 ({} frames/s)", f["sample rate"].trim_end_matches(" Hz"))
        );
        assert!(rate > 100.0, "{rate}");
        assert!(f["frames sent"].parse::<u32>().unwrap() >= 5);
        // identify counts itself.
        assert_eq!(f["commands"], "1");
        let uptime = &f["uptime"];
        assert!(
            uptime.len() == 12 && uptime.starts_with("00:00:"),
            "{uptime}"
        );
        let a = fake.scale.accel.si_per_lsb as f32;
        assert!(
            f["scale"].starts_with(&format!("accel {} m/s² per LSB, gyro", f64::from(a))),
            "{}",
            f["scale"]
        );

        // Decimation and reset-counters reach the device.
        let out = device(&pty, &["decimation", "4"]);
        assert_ok(&out);
        assert!(text(&out.stdout).starts_with("decimation: 4 ("));
        assert_eq!(fake.applied(), [Applied::Decimation(4)]);
        assert_ok(&device(&pty, &["reset-counters"]));
        let f = info(&pty);
        assert!(f["decimation"].starts_with("4 ("), "{f:?}");
        // The reset zeroed the count and then counted itself; this identify
        // is the second.
        assert_eq!(f["commands"], "2", "{f:?}");
    }

    #[test]
    fn an_upload_is_applied_from_the_next_frame_and_downloads_back() {
        let d = dir("upload");
        let file = lab_file(&d, false);
        let cal = calib_file::load(&file).unwrap();
        let pty = Pty::open();
        let fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
        let out = device(&pty, &["upload", s(&file)]);
        assert_ok(&out);
        assert!(
            text(&out.stdout).contains("calibration 0x12345678 active"),
            "{}",
            text(&out.stdout)
        );
        assert_eq!(fake.applied(), [Applied::Calibrate(0x1234_5678)]);

        // The stream: every frame carries the new id, and its values are
        // the host's correction of the raw sample it was made from.
        let host =
            Corrector::new(&cal.calibration, &fake.scale, Orientation::RotationNone).unwrap();
        let rows = rows(&device(&pty, &["stream", "--max-frames", "20"]));
        assert_eq!(rows.len(), 20);
        for (seq, values, flags) in rows {
            let (frame, raw) = logged(&fake, seq);
            let Outgoing::Data(frame) = frame else {
                panic!("frame {seq} is raw")
            };
            assert_eq!(frame.calibration_id, 0x1234_5678, "frame {seq}");
            let want = host.correct(&raw);
            let want: Vec<f32> = want.accel.iter().chain(&want.gyro).copied().collect();
            assert_eq!(bits(&values[..6]), bits(&want), "frame {seq}");
            assert_eq!(flags, frame.flags.bits());
            assert!(!frame.flags.contains(Flags::UNCALIBRATED));
        }
        assert_eq!(info(&pty)["calibration"], "0x12345678 (uploaded)");

        // Read back: the same calibration, id included.
        let back = d.join("back.toml");
        assert_ok(&device(&pty, &["download", "-o", s(&back)]));
        let read = calib_file::load(&back).unwrap();
        assert_eq!(read.calibration, cal.calibration);
        assert!(!read.id_from_parameters);
    }

    #[test]
    fn an_invalid_upload_is_refused_with_calib_checks_reason_and_changes_nothing() {
        let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("../calibrations/bad/singular.toml");
        let check = triad(&["calib", "check", s(&bad)]);
        assert!(!check.status.success());
        let check_err = text(&check.stderr);
        let reason = check_err
            .trim_end()
            .strip_prefix(&format!("triad: {}: ", bad.display()))
            .unwrap_or_else(|| panic!("{check_err}"));

        let pty = Pty::open();
        let fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
        let before = info(&pty)["calibration"].clone();
        let out = device(&pty, &["upload", s(&bad)]);
        assert_eq!(out.status.code(), Some(1));
        assert_eq!(
            text(&out.stderr).trim_end(),
            format!("triad: upload commit: the device answered invalid calibration: {reason}")
        );
        assert_eq!(info(&pty)["calibration"], before);
        assert_eq!(fake.applied(), []);
        let default_id = default_calibration().calibration.id;
        for (seq, ..) in rows(&device(&pty, &["stream", "--max-frames", "5"])) {
            let (Outgoing::Data(frame), _) = logged(&fake, seq) else {
                panic!("frame {seq} is raw")
            };
            assert_eq!(frame.calibration_id, default_id, "frame {seq}");
        }
    }

    #[test]
    fn raw_mode_streams_counts_times_the_chips_scale() {
        let pty = Pty::open();
        let fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
        let out = device(&pty, &["raw"]);
        assert_ok(&out);
        assert!(text(&out.stdout).starts_with("mode: raw"));
        let scale = fake.scale;
        let (a, g) = (scale.accel.si_per_lsb as f32, scale.gyro.si_per_lsb as f32);
        let (t_lsb, t0) = (
            scale.temperature_per_lsb as f32,
            scale.temperature_offset as f32,
        );
        let raw_rows = rows(&device(&pty, &["stream", "--seconds", "0.02"]));
        // 20 ms of stream time, counted from the first frame.
        let period_us = triad::device::sample_period_us(fake.rate_hz);
        assert_eq!(raw_rows.len(), 20_000usize.div_ceil(period_us as usize));
        for (seq, values, flags) in raw_rows {
            let (frame, raw) = logged(&fake, seq);
            assert!(matches!(frame, Outgoing::Raw(_)), "frame {seq}");
            let want: Vec<f32> = raw
                .accel
                .iter()
                .map(|&c| (c as f32) * a)
                .chain(raw.gyro.iter().map(|&c| (c as f32) * g))
                .chain([f32::from(raw.temperature) * t_lsb + t0])
                .collect();
            assert_eq!(bits(&values), bits(&want), "frame {seq}");
            assert_eq!(flags & 0x60, 0x60, "RAW and UNCALIBRATED on frame {seq}");
        }
        assert_ok(&device(&pty, &["calibrated"]));
        for (seq, ..) in rows(&device(&pty, &["stream", "--max-frames", "3"])) {
            assert!(matches!(logged(&fake, seq).0, Outgoing::Data(_)));
        }
    }

    #[test]
    fn save_and_erase_go_to_the_flash() {
        let d = dir("save");
        let file = lab_file(&d, false);
        let flash = RamFlash::new();
        let pty = Pty::open();
        let _fake = FakeDevice::spawn(
            pty.master.try_clone().unwrap(),
            Options {
                flash: Some(flash.clone()),
                ..options()
            },
        );
        assert_eq!(info(&pty)["stored"], "empty");
        assert_ok(&device(&pty, &["upload", s(&file)]));
        let out = device(&pty, &["save"]);
        assert_ok(&out);
        assert_eq!(
            text(&out.stdout),
            "saved calibration 0x12345678 to flash (generation 1, slot 0)\n"
        );
        let cal = calib_file::load(&file).unwrap();
        assert_eq!(flash.stored_blob(), Some(blob::encode(&cal.calibration)));
        let f = info(&pty);
        assert_eq!(
            (f["stored"].as_str(), f["calibration"].as_str()),
            ("valid", "0x12345678 (stored)")
        );
        assert_ok(&device(&pty, &["erase"]));
        assert_eq!(flash.stored_blob(), None);
        let f = info(&pty);
        assert_eq!(
            (f["stored"].as_str(), f["calibration"].as_str()),
            ("empty", "0x12345678 (stored)")
        );
    }

    #[test]
    fn a_board_without_storage_says_so_and_the_self_test_prints_each_axis() {
        let pty = Pty::open();
        let _fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
        let out = device(&pty, &["save"]);
        assert_eq!(out.status.code(), Some(1));
        assert_eq!(
            text(&out.stderr),
            "triad: save: the device answered not supported: this board has no calibration storage\n"
        );
        // The driver's self-test on the chip model: every axis answers.
        let out = device(&pty, &["selftest"]);
        assert_ok(&out);
        let report = text(&out.stdout);
        let lines: Vec<&str> = report.lines().collect();
        assert_eq!(lines[0], "self-test: passed", "{report}");
        assert_eq!(lines.len(), 7, "{report}");
        for (line, name) in lines[1..].iter().zip([
            "accel x", "accel y", "accel z", "gyro x", "gyro y", "gyro z",
        ]) {
            assert!(line.starts_with(&format!("{name}: response ")), "{line}");
            assert!(line.ends_with(": ok"), "{line}");
        }
    }

    #[test]
    fn a_port_that_answers_nothing_times_out_saying_what_was_tried() {
        let mut pty = Pty::open();
        let started = Instant::now();
        let out = device(&pty, &["--timeout-ms", "100", "info"]);
        let elapsed = started.elapsed();
        assert_eq!(out.status.code(), Some(1));
        let err = text(&out.stderr);
        let (head, tail) = err.split_once(" (seq ").unwrap_or_else(|| panic!("{err}"));
        assert_eq!(head, "triad: no reply to identify");
        let (seq, tail) = tail.split_once(')').unwrap();
        seq.parse::<u16>().unwrap();
        assert_eq!(
            tail,
            format!(
                " after 3 tries of 100 ms at 921600 baud on {}: is the device running triad firmware at this baud?\n",
                pty.path
            )
        );
        assert!(elapsed >= Duration::from_millis(300), "{elapsed:?}");
        // What went out: three times the same bytes, a delimiter (for the
        // device's decoder to be in step) and the command.
        use std::io::Read;
        let mut sent = Vec::new();
        let _ = pty.master.read_to_end(&mut sent);
        assert_eq!(sent.len() % 3, 0, "{sent:02x?}");
        let one = sent.len() / 3;
        assert_eq!(sent[0], 0, "{sent:02x?}");
        assert!(sent[1..one - 1].iter().all(|&b| b != 0), "{sent:02x?}");
        assert_eq!(&sent[..one], &sent[one..2 * one]);
        assert_eq!(&sent[..one], &sent[2 * one..]);
    }

    #[test]
    fn the_retries_are_an_option() {
        let pty = Pty::open();
        let out = device(&pty, &["--timeout-ms", "20", "--tries", "1", "raw"]);
        assert!(
            text(&out.stderr).contains(" after 1 try of 20 ms at 921600 baud"),
            "{}",
            text(&out.stderr)
        );
    }
}

#[test]
fn a_port_that_does_not_exist_is_named() {
    let out = triad(&["device", "--port", "/dev/triad-no-such-port", "info"]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.starts_with("triad: cannot open serial port /dev/triad-no-such-port at 921600 baud: "),
        "{err}"
    );
}

/// A link to a fake device over an in-memory pipe.
fn piped(options: Options, timeout_ms: u64) -> (Link<pipe::End>, FakeDevice) {
    let (host, device) = pipe::pair(Duration::from_millis(5));
    let fake = FakeDevice::spawn(device, options);
    let settings = Settings {
        timeout: Duration::from_millis(timeout_ms),
        tries: 3,
    };
    (
        Link::new(host, settings, "on the test pipe".into(), 7),
        fake,
    )
}

#[test]
fn a_retry_after_a_lost_reply_is_answered_without_applying_twice() {
    // Replies: 0 identify, 1 set decimation (lost), 2 its retry.
    let (mut link, fake) = piped(
        Options {
            drop_replies: vec![1],
            ..options()
        },
        100,
    );
    identify(&mut link).unwrap();
    let reply = link.command(&Command::SetDecimation(4)).unwrap();
    assert_eq!((reply.sequence, reply.status), (8, Status::Ok));
    let info = identify(&mut link).unwrap();
    assert_eq!(info.decimation, 4);
    // identify, set decimation, its retry, this identify: four commands
    // reached the device, one change was applied.
    assert_eq!(info.counters.commands, 4);
    assert_eq!(fake.applied(), [Applied::Decimation(4)]);
}

#[test]
fn an_upload_with_a_lost_chunk_reply_completes_and_reads_back_whole() {
    let d = dir("lost-chunk");
    let cal = calib_file::load(&lab_file(&d, true)).unwrap();
    let bytes = blob::encode(&cal.calibration);
    // Replies: 0 identify, 1 and 2 chunks 0 and 1; the second chunk's is lost.
    let (mut link, fake) = piped(
        Options {
            drop_replies: vec![2],
            ..options()
        },
        100,
    );
    identify(&mut link).unwrap();
    assert_eq!(transfer::upload(&mut link, &bytes).unwrap(), 0x1234_5678);
    assert_eq!(
        transfer::download(&mut link).unwrap().as_deref(),
        Some(&bytes[..])
    );
    assert_eq!(fake.applied(), [Applied::Calibrate(0x1234_5678)]);
}

#[test]
fn a_device_without_calibration_has_nothing_to_download() {
    let (mut link, _fake) = piped(
        Options {
            built_in: Vec::new(),
            ..options()
        },
        500,
    );
    assert_eq!(transfer::download(&mut link).unwrap(), None);
}

#[test]
fn a_reply_to_another_command_is_an_error() {
    // The other end answers every command's number with an erase's code.
    let (host, mut device) = pipe::pair(Duration::from_millis(5));
    let answering = std::thread::spawn(move || {
        use std::io::{Read, Write};
        let mut decoder = Decoder::new();
        let mut buf = [0u8; 256];
        loop {
            let n = match device.read(&mut buf) {
                Ok(n) => n,
                Err(_) => {
                    std::thread::sleep(Duration::from_millis(1));
                    continue;
                }
            };
            for decoded in decoder.feed_packets(&buf[..n]) {
                if let Ok(Packet::Command(c)) = decoded {
                    let reply = Reply {
                        sequence: c.sequence,
                        command: triad::protocol::command::code::ERASE,
                        status: Status::Ok,
                        payload: Default::default(),
                    };
                    let mut wire = [0u8; triad::protocol::MAX_WIRE_LEN];
                    let len = reply.to_packet().unwrap().to_wire(&mut wire);
                    device.write_all(&wire[..len]).unwrap();
                    return;
                }
            }
        }
    });
    let mut link = Link::new(host, Settings::default(), "on the test pipe".into(), 40);
    let err = identify(&mut link).unwrap_err();
    answering.join().unwrap();
    assert!(matches!(err, LinkError::WrongCommand { .. }), "{err:?}");
    assert_eq!(
        err.to_string(),
        "the reply to identify (seq 40) answers erase (code 0x08): another program may be talking to the device"
    );
}
