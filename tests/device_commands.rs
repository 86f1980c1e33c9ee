//! The device's command handler (`triad::device::CommandHandler`), fed the
//! bytes a host sends through the same decoder the firmware runs: exactly
//! one reply for every command, good or malformed; a retry answered without
//! applying twice; an upload checked as `triad calib check` checks it and
//! applied whole or not at all; save and erase through the flash store,
//! with a power cut at every operation of a save.

mod model_support;
mod ram_flash;

use model_support::*;
use ram_flash::*;
use triad::device::startup::load_stored;
use triad::device::{
    start_calibration, ActiveCalibration, CalibrationStore, CommandHandler, Control, DeviceFacts,
    Handled, SharedCounters,
};
use triad::model::blob::{self, BLOB_LEN};
use triad::model::{Calibration, Corrector, FixedCorrector, Orientation, TemperatureTerms};
use triad::protocol::cobs::stuff;
use triad::protocol::{crc32c, Decoder};
use triad::protocol::{
    CalibrationSource, Command, DeviceInfo, Mode, Payload, Reply, Status, StoredState, CHUNK_LEN,
};

/// The device under test: its handler, what it queued for the sampling
/// task, and its flash.
struct Device {
    handler: CommandHandler<RamFlash>,
    counters: SharedCounters,
    decoder: Decoder,
    controls: Vec<Control>,
    /// Room in the control queue (the data-ready task empties it).
    room: usize,
}

const BUILT_IN_ID: u32 = 0x0B11_7100;

fn facts() -> DeviceFacts {
    DeviceFacts {
        firmware: "0.1.0",
        board: "test-board",
        chip: "icm42688",
        bus: "spi",
        sample_rate_hz: 1000.0,
        baud: 921_600,
        scale: widest_scale(),
        orientation: Orientation::RotationNone,
        cycles_hz: 84_000_000,
    }
}

fn valid_calibration(seed: u64, id: u32) -> Calibration {
    let mut cal = random_calibration(&mut rng(seed), &widest_scale());
    cal.id = id;
    cal
}

impl Device {
    /// A device running a built-in calibration, with a store over `flash`
    /// (`None`: no storage).
    fn new(flash: Option<RamFlash>) -> Device {
        let built_in = blob::encode(&valid_calibration(7, BUILT_IN_ID));
        let store = flash.map(|f| CalibrationStore::new(f, BASE, SLOT_LEN).unwrap());
        let stored = if store.is_some() {
            StoredState::Empty
        } else {
            StoredState::NoStorage
        };
        let active = ActiveCalibration {
            blob: Some(built_in),
            id: BUILT_IN_ID,
            source: CalibrationSource::BuiltIn,
        };
        Device {
            handler: CommandHandler::new(facts(), active, 1, store, stored),
            counters: SharedCounters::new(),
            decoder: Decoder::new(),
            controls: Vec::new(),
            room: 2,
        }
    }

    /// Feeds wire bytes; returns what the handler did with each packet.
    fn wire(&mut self, bytes: &[u8]) -> Vec<Handled> {
        let mut out = Vec::new();
        for &b in bytes {
            if let Some(decoded) = self.decoder.push(b) {
                let controls = &mut self.controls;
                let room = &mut self.room;
                let handled = self.handler.on_packet(
                    &decoded,
                    self.decoder.last_packet_bytes(),
                    &self.counters,
                    &mut |c| {
                        if *room == 0 {
                            return false;
                        }
                        *room -= 1;
                        controls.push(c);
                        true
                    },
                );
                out.push(handled);
            }
        }
        out
    }

    /// Sends one packet's unstuffed bytes (a leading 0x00 puts the decoder
    /// in step); the one reply it must get.
    fn packet(&mut self, bytes: &[u8]) -> Reply {
        let handled = self.wire(&on_wire(bytes));
        match handled.as_slice() {
            [Handled::Reply(reply)] => *reply,
            other => panic!("one reply expected, got {other:?}"),
        }
    }

    fn send(&mut self, command: Command, sequence: u16) -> Reply {
        let packet = command.to_packet(sequence).unwrap();
        let reply = self.packet(packet.as_bytes());
        assert_eq!(reply.sequence, sequence);
        assert_eq!(reply.command, command.code());
        reply
    }

    fn ok(&mut self, command: Command, sequence: u16) -> Payload {
        let reply = self.send(command, sequence);
        assert_eq!(
            reply.status,
            Status::Ok,
            "{}: {}",
            command.name(),
            reply.reason()
        );
        reply.payload
    }

    fn info(&mut self, sequence: u16) -> DeviceInfo {
        DeviceInfo::parse(self.ok(Command::Identify, sequence).as_slice()).unwrap()
    }

    /// Uploads `bytes` in chunks and commits them; the commit's reply.
    fn upload(&mut self, bytes: &[u8], first_sequence: u16) -> Reply {
        let mut seq = first_sequence;
        for (i, chunk) in bytes.chunks(CHUNK_LEN).enumerate() {
            let data = Payload::new(chunk).unwrap();
            let offset = (i * CHUNK_LEN) as u16;
            self.ok(Command::UploadChunk { offset, data }, seq);
            seq += 1;
        }
        self.send(
            Command::UploadCommit {
                len: bytes.len() as u16,
                crc: crc32c(bytes),
            },
            seq,
        )
    }

    /// Empties the control queue as the data-ready task would.
    fn take_controls(&mut self) -> Vec<Control> {
        self.room = 2;
        std::mem::take(&mut self.controls)
    }

    /// The store's flash, armed to lose power at its `cut`-th operation.
    fn cut_power_after(&mut self, cut: usize) {
        let flash = self.handler.store_mut().expect("a store").flash_mut();
        flash.cut_after = Some(cut);
        flash.noise = 0x1234_5678 ^ cut as u32;
    }

    /// The flash, as a restart finds it.
    fn release_flash(self) -> RamFlash {
        let mut flash = self.handler.into_store().expect("a store").release();
        flash.power_up();
        flash
    }
}

/// `bytes` stuffed, between two delimiters.
fn on_wire(bytes: &[u8]) -> Vec<u8> {
    let mut wire = vec![0u8; bytes.len() + bytes.len() / 254 + 2];
    let n = stuff(bytes, &mut wire).unwrap();
    wire.truncate(n);
    let mut out = vec![0];
    out.extend(wire);
    out.push(0);
    out
}

/// A version-2 packet of `kind` with `body` and a good CRC, built by hand.
fn sealed(version: u8, kind: u8, body: &[u8]) -> Vec<u8> {
    let mut bytes = vec![version, kind];
    bytes.extend_from_slice(body);
    let crc = crc32c(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    bytes
}

#[test]
fn identify_reports_the_facts_the_calibration_and_the_counters() {
    let mut device = Device::new(Some(RamFlash::new()));
    let info = device.info(1);
    assert_eq!(info.protocol, 2);
    assert_eq!(info.firmware.as_str(), "0.1.0");
    assert_eq!(info.board.as_str(), "test-board");
    assert_eq!(info.chip.as_str(), "icm42688");
    assert_eq!(info.bus.as_str(), "spi");
    assert_eq!(
        (info.sample_rate_hz, info.decimation, info.baud),
        (1000.0, 1, 921_600)
    );
    assert_eq!(info.mode, Mode::Calibrated);
    assert_eq!(info.calibration_id, BUILT_IN_ID);
    assert_eq!(info.calibration_source, CalibrationSource::BuiltIn);
    assert_eq!(info.stored, StoredState::Empty);
    assert_eq!(info.counters.commands, 1, "identify counts itself");
    assert_eq!(
        info.scale.accel_si_per_lsb,
        widest_scale().accel.si_per_lsb as f32
    );
    // Counters the tasks publish, and reset by a baseline.
    device.counters.publish(
        &triad::device::SamplerTotals {
            frames_sent: 10,
            frames_dropped: 2,
            overruns: 3,
            read_failures: 1,
        },
        1234,
    );
    device.counters.rx_overflowed();
    let info = device.info(2);
    assert_eq!(
        (
            info.counters.frames_sent,
            info.counters.frames_dropped,
            info.counters.overruns,
            info.counters.read_failures,
            info.counters.rx_overflows,
            info.counters.commands,
            info.uptime_ms
        ),
        (10, 2, 3, 1, 1, 2, 1234)
    );
    device.ok(Command::ResetCounters, 3);
    let info = device.info(4);
    assert_eq!(
        (
            info.counters.frames_sent,
            info.counters.rx_overflows,
            info.counters.commands
        ),
        (0, 0, 2)
    );
}

#[test]
fn identify_reports_the_flash_stalls_since_the_last_reset_and_older_replies_read_as_none() {
    let mut device = Device::new(Some(RamFlash::new()));
    assert_eq!(device.info(1).counters.flash_stalls, 0);
    // A save on a single-bank board: one erase and two writes.
    device.counters.publish_flash_stalls(3);
    assert_eq!(device.info(2).counters.flash_stalls, 3);
    device.ok(Command::ResetCounters, 3);
    assert_eq!(device.info(4).counters.flash_stalls, 0);
    // An erase since: two more, counted from the reset.
    device.counters.publish_flash_stalls(5);
    let payload = device.ok(Command::Identify, 5);
    let info = DeviceInfo::parse(payload.as_slice()).unwrap();
    assert_eq!(info.counters.flash_stalls, 2);
    // Firmware from before the field: its reply ends after the sensor's
    // health, and reads as no stall; a cut field is not read as a count.
    // (The failed restarts' 4 bytes follow it: cut those first.)
    let bytes = payload.as_slice();
    for cut in 1..=4 {
        let older = DeviceInfo::parse(&bytes[..bytes.len() - 4 - cut]).unwrap();
        assert_eq!(older.counters.flash_stalls, 0, "cut {cut}");
        assert_eq!(older.counters.commands, info.counters.commands, "cut {cut}");
    }
}

#[test]
fn identify_reports_failed_restarts_since_the_last_reset_and_older_replies_read_as_none() {
    use triad::device::HealthTotals;
    let mut device = Device::new(Some(RamFlash::new()));
    assert_eq!(device.info(1).counters.sensor_restart_failures, 0);
    let health = |restarts, restart_failures| HealthTotals {
        stalls: 1,
        restarts,
        restart_failures,
    };
    device.counters.publish_health(&health(1, 6));
    let c = device.info(2).counters;
    assert_eq!((c.sensor_restarts, c.sensor_restart_failures), (1, 6));
    device.ok(Command::ResetCounters, 3);
    device.counters.publish_health(&health(2, 9));
    let payload = device.ok(Command::Identify, 4);
    let info = DeviceInfo::parse(payload.as_slice()).unwrap();
    let c = info.counters;
    assert_eq!((c.sensor_restarts, c.sensor_restart_failures), (1, 3));
    // Firmware from before the field: its reply ends after the flash
    // stalls and reads as no failed restart; a cut field is not a count.
    let bytes = payload.as_slice();
    for cut in 0..=4 {
        let older = DeviceInfo::parse(&bytes[..bytes.len() - cut]).unwrap();
        let expected = if cut == 0 { 3 } else { 0 };
        assert_eq!(
            older.counters.sensor_restart_failures, expected,
            "cut {cut}"
        );
        assert_eq!(older.counters.sensor_restarts, 1, "cut {cut}");
    }
}

#[test]
fn identify_reports_each_tasks_share_of_the_last_second() {
    use triad::device::{LoadWindow, Task};
    let mut device = Device::new(None);
    let hz = 84_000_000;
    let mut window = LoadWindow::new();
    assert_eq!(
        window.tick(0, hz, &device.counters.load),
        None,
        "the window opens"
    );
    // Over one second: data-ready 8.4 M cycles (10 %), link 0.84 M (1 %),
    // receive 84 k (0.1 %), the longest data-ready run 8400 cycles (100 µs).
    for _ in 0..1000 {
        device.counters.load.record(Task::DataReady, 8_400);
        device.counters.load.record(Task::Link, 840);
        device.counters.load.record(Task::Receive, 84);
    }
    assert_eq!(
        window.tick(hz - 1, hz, &device.counters.load),
        None,
        "not a second yet"
    );
    assert_eq!(
        window.tick(hz, hz, &device.counters.load),
        Some([100, 10, 1, 0])
    );
    let load = device.info(1).load;
    assert_eq!(load.busy_cycles, [8_400_000, 840_000, 84_000, 0]);
    assert_eq!((load.window_cycles, load.cycles_hz), (hz, hz));
    assert_eq!(load.share(0), 0.1);
    assert!(
        (load.idle_share() - 0.889).abs() < 1e-12,
        "{}",
        load.idle_share()
    );
    assert_eq!(load.max_run_us, [100, 10, 1, 0]);
    // A window across the cycle counter's wrap, measured afresh.
    let mut window = LoadWindow::new();
    let start = u32::MAX - 1000;
    window.tick(start, hz, &device.counters.load);
    device.counters.load.record(Task::DataReady, 42_000_000);
    let later = start.wrapping_add(hz);
    assert!(later < start);
    assert_eq!(
        window.tick(later, hz, &device.counters.load),
        Some([500, 0, 0, 0])
    );
    assert_eq!(device.info(2).load.max_run_us[0], 500_000);
}

#[test]
fn mode_and_decimation_are_queued_for_the_sampling_task_or_refused_busy() {
    let mut device = Device::new(None);
    device.ok(Command::SetMode(Mode::Raw), 1);
    device.ok(Command::SetDecimation(8), 2);
    let controls = device.take_controls();
    assert!(matches!(
        controls[..],
        [Control::SetMode(Mode::Raw), Control::SetDecimation(8)]
    ));
    let info = device.info(3);
    assert_eq!((info.mode, info.decimation), (Mode::Raw, 8));
    // The sampling task has not emptied the queue: busy, and nothing changes.
    device.room = 0;
    let reply = device.send(Command::SetMode(Mode::Calibrated), 4);
    assert_eq!(reply.status, Status::Busy);
    assert!(device.controls.is_empty());
    device.room = 2;
    assert_eq!(device.info(5).mode, Mode::Raw);
    // Decimation 0 and an undefined mode are bad arguments.
    let zero = sealed(2, 0x10, &[6, 0, 0x03, 0, 0]);
    let reply = device.packet(&zero);
    assert_eq!((reply.sequence, reply.status), (6, Status::BadArgument));
    assert!(
        reply.reason().contains("decimation must be at least 1"),
        "{}",
        reply.reason()
    );
    let reply = device.packet(&sealed(2, 0x10, &[7, 0, 0x02, 9]));
    assert_eq!(reply.status, Status::BadArgument);
    assert!(device.controls.is_empty());
}

#[test]
fn an_upload_takes_effect_whole_and_reads_back_byte_for_byte() {
    let mut device = Device::new(None);
    let cal = valid_calibration(11, 0xCA11_0001);
    let bytes = blob::encode(&cal);
    let reply = device.upload(&bytes, 1);
    assert_eq!(reply.status, Status::Ok, "{}", reply.reason());
    assert_eq!(reply.payload.as_slice(), 0xCA11_0001u32.to_le_bytes());
    let controls = device.take_controls();
    let [Control::Calibrate(corrector)] = &controls[..] else {
        panic!("one calibration control expected: {controls:?}");
    };
    let expected = Corrector::new(&cal, &widest_scale(), Orientation::RotationNone).unwrap();
    assert_eq!(corrector.calibration(), expected.calibration());
    let info = device.info(10);
    assert_eq!(info.calibration_id, 0xCA11_0001);
    assert_eq!(info.calibration_source, CalibrationSource::Uploaded);
    // Read back chunk by chunk.
    let mut read = Vec::new();
    let mut seq = 11;
    while read.len() < BLOB_LEN {
        let payload = device.ok(
            Command::ReadCalibration {
                offset: read.len() as u16,
            },
            seq,
        );
        let p = payload.as_slice();
        assert_eq!(u16::from_le_bytes([p[0], p[1]]), BLOB_LEN as u16);
        assert!(p.len() - 2 <= CHUNK_LEN && p.len() > 2);
        read.extend_from_slice(&p[2..]);
        seq += 1;
    }
    assert_eq!(read, bytes);
    let reply = device.send(
        Command::ReadCalibration {
            offset: BLOB_LEN as u16 + 1,
        },
        seq,
    );
    assert_eq!(reply.status, Status::BadArgument);
}

/// Calibrations that decode but fail the checks of `triad calib check`, one
/// per reason a file can give.
fn invalid_calibrations() -> Vec<(&'static str, Calibration)> {
    let mut out = Vec::new();
    let base = || valid_calibration(3, 0xBAD0_0000);
    let mut c = base();
    c.accel.scale_misalignment[0][0] = f64::NAN;
    out.push(("non-finite", c));
    let mut c = base();
    c.accel.scale_misalignment = [[0.0; 3]; 3];
    out.push(("singular", c));
    let mut c = base();
    c.gyro.scale_misalignment = [[1.0, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1.0]];
    out.push(("badly conditioned", c));
    let mut c = base();
    c.accel.scale_misalignment = [[1.6, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    out.push(("scale out of range", c));
    let mut c = base();
    c.gyro.scale_misalignment = [[1.0, 0.2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    out.push(("misalignment", c));
    let mut c = base();
    c.accel.bias = [1e6, 0.0, 0.0];
    out.push(("bias beyond full scale", c));
    let terms = TemperatureTerms {
        reference_c: 200.0,
        bias_coefficients: [[0.0; 3]; 3],
        scale_misalignment_per_c: [[0.0; 3]; 3],
    };
    let mut c = base();
    c.gyro.temperature = Some(terms);
    out.push(("reference temperature", c));
    let mut c = base();
    let mut t = terms;
    t.reference_c = 25.0;
    t.scale_misalignment_per_c[1][0] = 0.05;
    c.gyro.temperature = Some(t);
    out.push(("absurd temperature term", c));
    out
}

#[test]
fn an_invalid_upload_is_refused_with_calib_checks_reason_and_changes_nothing() {
    let mut device = Device::new(None);
    let mut seq = 1;
    for (what, cal) in invalid_calibrations() {
        let expected = Corrector::new(&cal, &widest_scale(), Orientation::RotationNone)
            .and_then(|c| FixedCorrector::new(&c).map(|_| ()))
            .expect_err(what);
        let reply = device.upload(&blob::encode(&cal), seq);
        seq += 10;
        assert_eq!(
            reply.status,
            Status::InvalidCalibration,
            "{what}: {}",
            reply.reason()
        );
        assert_eq!(reply.reason(), expected.to_string(), "{what}");
        assert!(device.take_controls().is_empty(), "{what}: nothing applied");
        let info = device.info(seq);
        seq += 1;
        assert_eq!(
            (info.calibration_id, info.calibration_source),
            (BUILT_IN_ID, CalibrationSource::BuiltIn),
            "{what}"
        );
    }
}

#[test]
fn an_upload_with_bad_bytes_is_refused_with_the_status_that_names_why() {
    let mut device = Device::new(None);
    let good = blob::encode(&valid_calibration(5, 5));
    // The commit's CRC does not match what arrived.
    for (i, chunk) in good.chunks(CHUNK_LEN).enumerate() {
        let data = Payload::new(chunk).unwrap();
        device.ok(
            Command::UploadChunk {
                offset: (i * CHUNK_LEN) as u16,
                data,
            },
            i as u16 + 1,
        );
    }
    let reply = device.send(
        Command::UploadCommit {
            len: BLOB_LEN as u16,
            crc: 1,
        },
        9,
    );
    assert_eq!(reply.status, Status::BadCrc);
    // The blob's own CRC fails.
    let mut corrupt = good;
    corrupt[100] ^= 1;
    assert_eq!(device.upload(&corrupt, 20).status, Status::BadCrc);
    // A blob version the device does not read (CRC recomputed).
    let mut future = good;
    future[4] = 99;
    let crc = crc32c(&future[..BLOB_LEN - 4]);
    future[BLOB_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    let reply = device.upload(&future, 30);
    assert_eq!(reply.status, Status::WrongVersion, "{}", reply.reason());
    // Not a blob at all (wrong length).
    let reply = device.upload(&good[..100], 40);
    assert_eq!(
        reply.status,
        Status::InvalidCalibration,
        "{}",
        reply.reason()
    );
    // The commit's length is not what was uploaded.
    let data = Payload::new(&good[..CHUNK_LEN]).unwrap();
    device.ok(Command::UploadChunk { offset: 0, data }, 50);
    let reply = device.send(Command::UploadCommit { len: 512, crc: 0 }, 51);
    assert_eq!(reply.status, Status::BadArgument);
    assert!(
        reply.reason().contains("512") && reply.reason().contains("128"),
        "{}",
        reply.reason()
    );
    // Chunks out of order, and past the blob's end.
    let data = Payload::new(&good[..CHUNK_LEN]).unwrap();
    device.ok(Command::UploadChunk { offset: 0, data }, 60);
    let reply = device.send(Command::UploadChunk { offset: 256, data }, 61);
    assert_eq!(reply.status, Status::BadArgument);
    assert!(
        reply.reason().contains("expected 128"),
        "{}",
        reply.reason()
    );
    let whole_chunks = BLOB_LEN / CHUNK_LEN;
    for (i, seq) in (1..whole_chunks).zip(62..) {
        let data = Payload::new(&good[i * CHUNK_LEN..(i + 1) * CHUNK_LEN]).unwrap();
        device.ok(
            Command::UploadChunk {
                offset: (i * CHUNK_LEN) as u16,
                data,
            },
            seq,
        );
    }
    // A whole chunk where only the blob's last part fits.
    let offset = (whole_chunks * CHUNK_LEN) as u16;
    let reply = device.send(Command::UploadChunk { offset, data }, 70);
    assert_eq!(reply.status, Status::BadArgument);
    assert!(
        reply
            .reason()
            .contains(&format!("past the {BLOB_LEN}-byte blob")),
        "{}",
        reply.reason()
    );
    assert!(device.take_controls().is_empty());
    assert_eq!(device.info(80).calibration_id, BUILT_IN_ID);
}

#[test]
fn every_malformed_packet_gets_one_reply_naming_its_sequence_number() {
    let mut device = Device::new(None);
    let identify = Command::Identify.to_packet(0x1234).unwrap();
    let good = identify.as_bytes().to_vec();

    // Bad CRC.
    let mut bad = good.clone();
    bad[5] ^= 0x01; // inside the CRC
    let reply = device.packet(&bad);
    assert_eq!(
        (reply.sequence, reply.command, reply.status),
        (0x1234, 0x01, Status::BadCrc)
    );
    // Truncated: the CRC no longer closes it.
    let reply = device.packet(&good[..good.len() - 2]);
    assert_eq!(reply.sequence, 0x1234);
    assert!(
        matches!(reply.status, Status::BadCrc | Status::Malformed),
        "{:?}",
        reply.status
    );
    // Too short to be a command at all.
    let reply = device.packet(&sealed(2, 0x10, &[0x34]));
    assert_eq!(reply.status, Status::Malformed);
    // Unknown packet type, good CRC.
    let reply = device.packet(&sealed(2, 0x55, &[0x34, 0x12, 0x01]));
    assert_eq!(
        (reply.sequence, reply.status),
        (0x1234, Status::UnknownCommand)
    );
    // Wrong version, good CRC.
    let reply = device.packet(&sealed(3, 0x10, &[0x34, 0x12, 0x01]));
    assert_eq!(
        (reply.sequence, reply.status),
        (0x1234, Status::WrongVersion)
    );
    assert!(reply.reason().contains("version 3"), "{}", reply.reason());
    // Unknown command code.
    let reply = device.packet(&sealed(2, 0x10, &[0x35, 0x12, 0x7F]));
    assert_eq!(
        (reply.sequence, reply.command, reply.status),
        (0x1235, 0x7F, Status::UnknownCommand)
    );
    // Arguments of the wrong length.
    let reply = device.packet(&sealed(2, 0x10, &[0x36, 0x12, 0x01, 0xAA]));
    assert_eq!((reply.sequence, reply.status), (0x1236, Status::Malformed));
    assert!(
        reply.reason().contains("takes 0 argument bytes, got 1"),
        "{}",
        reply.reason()
    );
    // Oversize: longer than any packet; still one reply.
    let mut huge = vec![2, 0x10, 0x37, 0x12, 0x04];
    huge.resize(400, 0xAB);
    let reply = device.packet(&huge);
    assert_eq!((reply.sequence, reply.status), (0x1237, Status::Malformed));
    assert!(reply.reason().contains("400 bytes"), "{}", reply.reason());
    // A device ignores what devices send (a looped-back line): no reply.
    let data = triad::protocol::RawFrame::default().to_packet().unwrap();
    assert_eq!(
        device.wire(&on_wire(data.as_bytes())),
        vec![Handled::Nothing]
    );
    // Nothing of the above was applied; every error was counted.
    assert!(device.controls.is_empty());
    let info = device.info(1);
    assert_eq!(info.counters.command_errors, 8);
    assert_eq!(info.counters.commands, 9);
}

#[test]
fn a_retry_gets_the_same_reply_and_is_not_applied_twice() {
    let mut device = Device::new(Some(RamFlash::new()));
    let cal = blob::encode(&valid_calibration(21, 21));
    let reply = device.upload(&cal, 100);
    assert_eq!(reply.status, Status::Ok);
    let commit_sequence = 100 + BLOB_LEN.div_ceil(CHUNK_LEN) as u16;
    let commit = Command::UploadCommit {
        len: BLOB_LEN as u16,
        crc: crc32c(&cal),
    }
    .to_packet(commit_sequence)
    .unwrap();
    // The reply was lost; the host sends the commit again, same number.
    assert_eq!(device.packet(commit.as_bytes()), reply);
    assert_eq!(device.take_controls().len(), 1, "applied once");
    // The same for a save: one generation, not two.
    let save = Command::Save.to_packet(commit_sequence + 1).unwrap();
    let first = device.packet(save.as_bytes());
    assert_eq!(first.status, Status::Ok);
    assert_eq!(device.packet(save.as_bytes()), first);
    assert_eq!(first.payload.as_slice()[..4], 1u32.to_le_bytes());
    let again = device.ok(Command::Save, commit_sequence + 2);
    assert_eq!(
        again.as_slice()[..4],
        2u32.to_le_bytes(),
        "a new number is a new save"
    );
    // The same number with other bytes is a new command, and applied.
    let reply = device.send(Command::SetDecimation(4), commit_sequence + 2);
    assert_eq!(reply.status, Status::Ok);
    assert_eq!(device.take_controls().len(), 1);
}

#[test]
fn save_and_erase_go_through_the_store_and_are_refused_without_one() {
    let mut device = Device::new(Some(RamFlash::new()));
    device.ok(Command::Save, 1);
    let info = device.info(2);
    assert_eq!(
        (info.stored, info.calibration_source),
        (StoredState::Valid, CalibrationSource::Stored)
    );
    device.ok(Command::Erase, 3);
    assert_eq!(device.info(4).stored, StoredState::Empty);

    let mut none = Device::new(None);
    let reply = none.send(Command::Save, 1);
    assert_eq!(reply.status, Status::NotSupported);
    assert_eq!(none.send(Command::Erase, 2).status, Status::NotSupported);

    // A failing flash is a storage failure; the active calibration stays.
    let mut flash = RamFlash::new();
    flash.cut_after = Some(0);
    let mut broken = Device::new(Some(flash));
    let reply = broken.send(Command::Save, 1);
    assert_eq!(reply.status, Status::StorageFailure, "{}", reply.reason());
    assert_eq!(
        broken.info(2).calibration_source,
        CalibrationSource::BuiltIn
    );
}

#[test]
fn a_power_cut_at_every_operation_of_a_save_starts_the_old_or_the_new_calibration() {
    let old = valid_calibration(31, 0x0000_0A1D);
    let new = valid_calibration(32, 0x0000_0AE7);
    let built_in = blob::encode(&valid_calibration(7, BUILT_IN_ID));
    for cut in 0..200 {
        // A device with `old` saved, then `new` uploaded and saved with the
        // power cut at operation `cut` of that save.
        let mut device = Device::new(Some(RamFlash::new()));
        assert_eq!(device.upload(&blob::encode(&old), 1).status, Status::Ok);
        device.ok(Command::Save, 10);
        assert_eq!(device.upload(&blob::encode(&new), 20).status, Status::Ok);
        device.cut_power_after(cut);
        let reply = device.send(Command::Save, 30);
        let completed = reply.status == Status::Ok;
        // Restart: load, then choose as the firmware does.
        let flash = device.release_flash();
        let mut store = CalibrationStore::new(flash, BASE, SLOT_LEN).unwrap();
        let (stored, state) = load_stored(&mut store);
        let startup = start_calibration(
            stored.as_ref().map(|b| &b[..]),
            &built_in,
            &widest_scale(),
            Orientation::RotationNone,
        )
        .unwrap();
        assert_eq!(
            startup.source,
            CalibrationSource::Stored,
            "cut {cut}: {state:?}"
        );
        assert!(startup.stored_rejected.is_none(), "cut {cut}");
        let id = startup.corrector.calibration_id();
        assert!(id == old.id || id == new.id, "cut {cut}: id {id:#x}");
        if completed {
            assert_eq!(id, new.id, "cut {cut}: a completed save is the new one");
            // Past the last operation: every cut point was tried, before
            // the save's first operation and inside each of its 133 (one
            // erase, 128 + 4 writes of 4 bytes).
            assert_eq!(cut, 1 + 1 + (BLOB_LEN + 16) / WRITE_SIZE);
            return;
        }
        // Until the header's last unit is written, the old one stands.
        assert_eq!(id, old.id, "cut {cut}");
        assert_eq!(reply.status, Status::StorageFailure, "cut {cut}");
    }
    panic!("a save took more than 200 operations");
}

#[test]
fn a_self_test_is_handed_to_the_firmware_and_its_outcome_replied() {
    let mut device = Device::new(None);
    let packet = Command::SelfTest.to_packet(9).unwrap();
    let handled = device.wire(&on_wire(packet.as_bytes()));
    assert_eq!(handled, vec![Handled::SelfTest { sequence: 9 }]);
    let error: Result<triad::sensor::SelfTestReport, _> = Err(triad::sensor::SelfTestError {
        error: triad::sensor::Error::<()>::NoNewData { status: 0 },
        chip: triad::sensor::ChipLeft::AsConfigured,
    });
    let reply = device.handler.self_test_reply(9, &error);
    assert_eq!(
        (reply.sequence, reply.command, reply.status),
        (9, 0x0A, Status::SensorError)
    );
    assert!(
        reply.reason().contains("configured as before"),
        "{}",
        reply.reason()
    );
    assert_eq!(device.info(10).counters.commands, 2);
}

/// A device whose chip has not answered yet: identify says chip "none"
/// and what the handler was given; what needs the chip is refused with
/// SENSOR_ERROR saying so, changing nothing (no control queued, nothing
/// stored); once the chip is found the same commands are carried out.
#[test]
fn without_a_chip_identify_answers_and_what_needs_one_is_refused_until_it_answers() {
    let mut device = Device::new(Some(RamFlash::new()));
    let mut none = facts();
    none.chip = triad::device::NO_SENSOR;
    none.sample_rate_hz = 0.0;
    let nothing = ActiveCalibration {
        blob: None,
        id: 0,
        source: CalibrationSource::None,
    };
    let store = device.handler.into_store();
    device.handler =
        CommandHandler::new(none, nothing, 1, store, StoredState::Empty).awaiting_sensor();
    let info = device.info(1);
    assert_eq!(info.chip.as_str(), "none");
    assert_eq!(info.calibration_source, CalibrationSource::None);
    let blob = blob::encode(&valid_calibration(3, 0x0000_0A11));
    let refused = [
        Command::SetMode(Mode::Raw),
        Command::SetDecimation(2),
        Command::UploadChunk {
            offset: 0,
            data: Payload::new(&blob[..CHUNK_LEN]).unwrap(),
        },
        Command::Save,
        Command::Erase,
        Command::SelfTest,
    ];
    for (i, command) in refused.iter().enumerate() {
        let reply = device.send(*command, 10 + i as u16);
        assert_eq!(reply.status, Status::SensorError, "{}", command.name());
        assert!(reply.reason().contains("no sensor"), "{}", reply.reason());
    }
    assert!(device.take_controls().is_empty());
    device.ok(Command::ReadCalibration { offset: 0 }, 20);
    let flash = device.handler.store_mut().unwrap().flash_mut();
    assert!(
        flash.memory.iter().all(|&b| b == 0xFF),
        "the flash was written"
    );
    let c = device.info(21).counters;
    assert_eq!((c.commands, c.command_errors), (9, 6));

    let built_in = blob::encode(&valid_calibration(7, BUILT_IN_ID));
    let found = ActiveCalibration {
        blob: Some(built_in),
        id: BUILT_IN_ID,
        source: CalibrationSource::BuiltIn,
    };
    device.handler.sensor_found(
        facts(),
        found,
        StoredState::Empty,
        triad::protocol::StoredReason::None,
    );
    let info = device.info(30);
    assert_eq!(info.chip.as_str(), "icm42688");
    assert_eq!(
        (info.calibration_id, info.calibration_source),
        (BUILT_IN_ID, CalibrationSource::BuiltIn)
    );
    device.ok(Command::SetDecimation(2), 31);
    assert_eq!(device.upload(&blob, 32).status, Status::Ok);
    device.ok(Command::Save, 40);
}

/// docs/PROTOCOL.md's answers to the cases a client written from it alone
/// asks about (sections 12, 13, 15 and 17), as the handler gives them.
#[test]
fn the_documented_edge_cases_are_what_the_handler_does() {
    let mut device = Device::new(Some(RamFlash::new()));
    // §12: a 240-byte command is read; an upload chunk of 229 bytes in it
    // is refused for its length, naming the limit, not as unreadable.
    let mut args = vec![0u8, 0];
    args.resize(231, 0xAB);
    let mut body = vec![0x40, 0x00, 0x04];
    body.extend_from_slice(&args);
    let longest = sealed(2, 0x10, &body);
    assert_eq!(longest.len(), 240);
    let reply = device.packet(&longest);
    assert_eq!((reply.sequence, reply.status), (0x40, Status::Malformed));
    assert!(reply.reason().contains("130"), "{}", reply.reason());
    // 241 bytes: too long for any packet, still one reply.
    body.push(0xAB);
    let reply = device.packet(&sealed(2, 0x10, &body));
    assert_eq!((reply.sequence, reply.status), (0x40, Status::Malformed));

    // §13: bytes that did not arrive read as 0.
    let reply = device.packet(&[0x02, 0x10, 0x07]);
    assert_eq!(
        (reply.sequence, reply.command, reply.status),
        (7, 0, Status::Malformed)
    );
    let reply = device.packet(&[0x02]);
    assert_eq!(
        (reply.sequence, reply.command, reply.status),
        (0, 0, Status::Malformed)
    );
    // An empty packet is idle filler: nothing.
    assert!(device.wire(&[0, 0, 0]).is_empty());
    // Another version: good CRC, wrong version; bad CRC, bad CRC at 51
    // bytes and malformed at any other length.
    let mut other = sealed(3, 0x10, &[0x41, 0x00, 0x01]);
    assert_eq!(device.packet(&other).status, Status::WrongVersion);
    *other.last_mut().unwrap() ^= 1;
    assert_eq!(device.packet(&other).status, Status::Malformed);
    let mut v3_frame = sealed(3, 0x10, &[0x42, 0x00, 0x01]);
    v3_frame.splice(5..5, [0u8; 51 - 9]);
    assert_eq!(v3_frame.len(), 51);
    *v3_frame.last_mut().unwrap() ^= 1;
    let reply = device.packet(&v3_frame);
    assert_eq!((reply.sequence, reply.status), (0x42, Status::BadCrc));

    // §15: a read at offset = total is the end (ok, no bytes); past it, bad argument.
    let total = BLOB_LEN as u16;
    let at_end = device.ok(Command::ReadCalibration { offset: total }, 10);
    assert_eq!(at_end.as_slice(), &total.to_le_bytes());
    let past = device.send(Command::ReadCalibration { offset: total + 1 }, 11);
    assert_eq!(past.status, Status::BadArgument);
    // Reset counters counts itself: the identify after it says 2.
    device.ok(Command::ResetCounters, 12);
    let info = device.info(13);
    assert_eq!(
        (info.counters.commands, info.counters.command_errors),
        (2, 0)
    );

    // §17: after erase, the calibration read from flash stays in force
    // (source stored) while the flash is empty.
    device.ok(Command::Save, 14);
    device.ok(Command::Erase, 15);
    let info = device.info(16);
    assert_eq!(
        (info.calibration_source, info.stored),
        (CalibrationSource::Stored, StoredState::Empty)
    );
}

/// A device restarted on `flash` as the firmware starts (firmware/src/start.rs):
/// the store loaded, the calibration chosen, the handler told why.
fn restart(flash: RamFlash, built_in: &[u8; BLOB_LEN]) -> Device {
    let mut store = CalibrationStore::new(flash, BASE, SLOT_LEN).unwrap();
    let (stored, loaded) = load_stored(&mut store);
    let startup = start_calibration(
        stored.as_ref().map(|b| &b[..]),
        built_in,
        &widest_scale(),
        Orientation::RotationNone,
    )
    .unwrap();
    let handler = CommandHandler::new(
        facts(),
        startup.active(stored.as_ref(), built_in),
        1,
        Some(store),
        startup.stored_state(loaded),
    )
    .with_stored_reason(startup.stored_reason(loaded));
    Device {
        handler,
        counters: SharedCounters::new(),
        decoder: Decoder::new(),
        controls: Vec::new(),
        room: 2,
    }
}

/// A device that saved one calibration (in slot 0), powered off: its flash.
fn flash_with_one_record(record: &[u8; BLOB_LEN]) -> RamFlash {
    let mut store = CalibrationStore::new(RamFlash::new(), BASE, SLOT_LEN).unwrap();
    store.save(record).unwrap();
    let mut flash = store.release();
    flash.power_up();
    flash
}

#[test]
fn flash_gone_bad_is_rejected_at_start_up_with_the_reason_in_identify() {
    use triad::protocol::StoredReason;
    let built_in = blob::encode(&valid_calibration(7, BUILT_IN_ID));
    let saved = blob::encode(&valid_calibration(40, 0x5A7E_D000));
    let starts_built_in = |device: &mut Device, reason: StoredReason, what: &str| {
        let info = device.info(1);
        assert_eq!(
            (info.calibration_source, info.calibration_id),
            (CalibrationSource::BuiltIn, BUILT_IN_ID),
            "{what}"
        );
        assert_eq!(
            (info.stored, info.stored_reason),
            (StoredState::Rejected, reason),
            "{what}"
        );
    };
    // The record intact: it runs.
    let info = restart(flash_with_one_record(&saved), &built_in).info(1);
    assert_eq!(
        (info.calibration_id, info.stored, info.stored_reason),
        (0x5A7E_D000, StoredState::Valid, StoredReason::None)
    );

    // A bit flipped anywhere in the record: its header or its blob.
    for byte in [4, 12, 16 + 8, 16 + 300, 16 + 511] {
        let mut flash = flash_with_one_record(&saved);
        flash.memory[BASE as usize + byte] ^= 0x08;
        let what = format!("bit 3 of record byte {byte} flipped");
        starts_built_in(
            &mut restart(flash, &built_in),
            StoredReason::RecordDamaged,
            &what,
        );
    }

    // `erase` cut off inside the erase of the slot holding the record (the
    // empty slot is erased first and completes; the cut falls in the second
    // operation), what the cut leaves differing with the flash's noise:
    // never the record, never garbage.
    let mut rejected = 0;
    for noise in 1..=20u32 {
        let mut device = restart(flash_with_one_record(&saved), &built_in);
        device.cut_power_after(2);
        device.handler.store_mut().unwrap().flash_mut().noise = noise.wrapping_mul(0x9E37_79B9);
        assert_eq!(
            device.send(Command::Erase, 2).status,
            Status::StorageFailure
        );
        let mut after = restart(device.release_flash(), &built_in);
        let info = after.info(3);
        assert_eq!(
            info.calibration_source,
            CalibrationSource::BuiltIn,
            "noise {noise}"
        );
        match (info.stored, info.stored_reason) {
            (StoredState::Rejected, StoredReason::RecordDamaged) => rejected += 1,
            // The cut erased the whole header (and so the record).
            (StoredState::Empty, StoredReason::None) => {}
            other => panic!("noise {noise}: {other:?}"),
        }
    }
    assert!(
        rejected > 15,
        "{rejected} of 20 cut erases left a damaged record"
    );

    // A whole record whose blob is of a later version (its own CRC good).
    let mut future = saved;
    future[4] = blob::VERSION + 1;
    let crc = crc32c(&future[..BLOB_LEN - 4]);
    future[BLOB_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    let mut device = restart(flash_with_one_record(&future), &built_in);
    starts_built_in(
        &mut device,
        StoredReason::BlobVersion,
        "a later blob version",
    );
    // A save replaces it, and the reason goes with it.
    device.ok(Command::Save, 5);
    let info = device.info(6);
    assert_eq!(
        (info.stored, info.stored_reason),
        (StoredState::Valid, StoredReason::None)
    );
}

/// One command packet from arbitrary parts: a known or unknown code with
/// arguments of any length, or a valid upload of a blob damaged at random.
fn arbitrary_packet() -> impl proptest::strategy::Strategy<Value = Vec<u8>> {
    use proptest::prelude::*;
    let codes = prop_oneof![0x01u8..=0x09, Just(0x0B), any::<u8>()];
    let free = (
        any::<u16>(),
        codes,
        proptest::collection::vec(any::<u8>(), 0..=240),
    )
        .prop_filter("self-tests are the firmware's", |(_, code, _)| {
            *code != 0x0A
        })
        .prop_map(|(sequence, code, args)| {
            let mut body = sequence.to_le_bytes().to_vec();
            body.push(code);
            body.extend_from_slice(&args);
            sealed(2, 0x10, &body)
        });
    let raw = proptest::collection::vec(any::<u8>(), 0..=250);
    prop_oneof![4 => free, 1 => raw]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 64,
        failure_persistence: None,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// Any packets, then uploads of blobs damaged at random: one reply
    /// each, the counters add up, and a refused command leaves the
    /// calibration in force as it was.
    #[test]
    fn any_commands_get_one_reply_each_and_a_refused_one_changes_nothing(
        packets in proptest::collection::vec(arbitrary_packet(), 1..24),
        flips in proptest::collection::vec(proptest::prelude::any::<u16>(), 0..3),
    ) {
        let mut device = Device::new(Some(RamFlash::new()));
        let (mut replies, mut errors) = (0u32, 0u32);
        let mut reset_at = None;
        for bytes in &packets {
            let before = device.handler.active().clone();
            let handled = device.wire(&on_wire(bytes));
            match handled.as_slice() {
                [Handled::Reply(reply)] => {
                    replies += 1;
                    if reply.status != Status::Ok {
                        errors += 1;
                        let after = device.handler.active();
                        proptest::prop_assert_eq!(&after.blob, &before.blob);
                        proptest::prop_assert_eq!(after.id, before.id);
                    } else if reply.command == 0x09 {
                        reset_at = Some((replies, errors));
                    }
                }
                // A packet a device ignores (what devices send).
                [Handled::Nothing] | [] => {}
                other => proptest::prop_assert!(false, "{other:?}"),
            }
        }
        // An upload of a good blob with bits flipped: applied whole or not at all.
        let mut bytes = blob::encode(&valid_calibration(3, 0x00F0_F0F0));
        for f in &flips {
            bytes[usize::from(*f) % BLOB_LEN] ^= 1 << (f % 8);
        }
        let before = device.handler.active().clone();
        let commit = device.upload(&bytes, 0x7000);
        // Its chunks and the commit: one reply each.
        replies += BLOB_LEN.div_ceil(CHUNK_LEN) as u32 + 1;
        let after = device.handler.active().clone();
        if commit.status == Status::Ok {
            proptest::prop_assert_eq!(after.blob, Some(bytes));
        } else {
            errors += 1;
            proptest::prop_assert_eq!((after.blob, after.id), (before.blob, before.id));
        }
        // identify counts itself; a reset restarted the counts from its own.
        let info = device.info(0x7100);
        let (base_replies, base_errors) = reset_at.map_or((0, 0), |(r, e)| (r - 1, e));
        proptest::prop_assert_eq!(info.counters.commands, replies + 1 - base_replies);
        proptest::prop_assert_eq!(info.counters.command_errors, errors - base_errors);
    }
}

/// PROTOCOL.md §17: a retry answered again counts again, in `commands`
/// and, when its reply is an error, in `command_errors` (found by the
/// mutation run: the two counters disagreed).
#[test]
fn a_retried_error_counts_as_a_command_and_as_an_error() {
    let mut device = Device::new(None);
    let zero = Command::SetDecimation(0).to_packet(5).unwrap();
    let first = device.packet(zero.as_bytes());
    assert_eq!(first.status, Status::BadArgument);
    assert_eq!(device.packet(zero.as_bytes()), first);
    let info = device.info(6);
    assert_eq!(
        (info.counters.commands, info.counters.command_errors),
        (3, 2)
    );
}
