//! The reply to `identify`: who the device is, what it streams, where its
//! calibration came from, and its counters.

use super::byte_enum::byte_enum;
use super::bytes::{Reader, Writer};
use super::command::Mode;
use super::payload::Payload;
use super::raw_frame::RawScale;

/// Longest name a [`Text`] holds.
pub const TEXT_LEN: usize = 24;

/// A short name, held inline.
#[derive(Clone, Copy, PartialEq, Eq, Default)]
pub struct Text {
    bytes: [u8; TEXT_LEN],
    len: u8,
}

impl Text {
    /// `s`, cut at [`TEXT_LEN`] bytes on a character boundary.
    pub fn new(s: &str) -> Text {
        let mut n = s.len().min(TEXT_LEN);
        while !s.is_char_boundary(n) {
            n -= 1;
        }
        let mut bytes = [0; TEXT_LEN];
        bytes[..n].copy_from_slice(&s.as_bytes()[..n]);
        Text {
            bytes,
            len: n as u8,
        }
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        core::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("?")
    }
}

impl core::fmt::Debug for Text {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl core::fmt::Display for Text {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

byte_enum! {
    /// Where the active calibration came from.
    pub enum CalibrationSource {
        /// None: the identity, and every frame is flagged UNCALIBRATED.
        None = 0 => "none",
        /// Built into the firmware image.
        BuiltIn = 1 => "built in",
        /// Stored on the device (flash).
        Stored = 2 => "stored",
        /// Uploaded over the link since start-up and not saved (lost at restart).
        Uploaded = 3 => "uploaded",
    }
}

byte_enum! {
    /// What the device's flash holds.
    pub enum StoredState {
        /// This device has no calibration storage.
        NoStorage = 0 => "no storage",
        /// Nothing stored.
        Empty = 1 => "empty",
        /// A valid calibration is stored.
        Valid = 2 => "valid",
        /// A record is stored but was rejected at start-up (CRC, version or
        /// validation), and ignored.
        Rejected = 3 => "rejected",
        /// The flash could not be read.
        Failed = 4 => "unreadable",
    }
}

byte_enum! {
    /// Why the flash's record was not applied at start-up ([`StoredState::Rejected`]).
    pub enum StoredReason {
        /// Nothing was rejected (or the flash changed since: a save or an erase).
        None = 0 => "none",
        /// No slot holds a whole record: a flipped bit, a save or an erase
        /// cut off, or data that is not a record (the record's magic,
        /// length or CRC fails).
        RecordDamaged = 1 => "the record fails its check (a flipped bit, a cut save or erase, foreign data)",
        /// The record is whole, its blob of a version this firmware does not read.
        BlobVersion = 2 => "the record's calibration blob is of a version this firmware does not read",
        /// The record is whole, its blob not a calibration blob (magic, CRC, reserved bits).
        NotABlob = 3 => "the record's blob is not a calibration blob",
        /// The blob reads, but the calibration is not valid for this chip.
        Invalid = 4 => "the stored calibration is not valid for this chip",
    }
}

/// The device's counters since start (or the last reset).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Frames handed to the link.
    pub frames_sent: u32,
    /// Frames dropped because the link's queue was full.
    pub frames_dropped: u32,
    /// Sample steps lost (late or overrun).
    pub overruns: u32,
    /// Sensor reads that failed.
    pub read_failures: u32,
    /// Commands handled (retries answered from the last reply included).
    pub commands: u32,
    /// Commands answered with an error.
    pub command_errors: u32,
    /// Received bytes lost because the receive queue was full.
    pub rx_overflows: u32,
    /// Times the sensor's data-ready went silent long enough to be checked
    /// (`src/device/sensor_health.rs`; 0 from firmware that does not send it).
    pub sensor_stalls: u32,
    /// Times the sensor was found again by its identity and configured
    /// after a stall or a run of failed reads.
    pub sensor_restarts: u32,
    /// Flash operations (each sector erase, each write) that stalled the
    /// CPU: on a board whose one flash bank holds the program and the
    /// calibration, sampling pauses for each (0 from a board whose flash
    /// does not stall, and from firmware that does not send it).
    pub flash_stalls: u32,
    /// Restarts the firmware tried that did not work (the chip did not
    /// answer with its identity, or refused its configuration); 0 from
    /// firmware that does not send it.
    pub sensor_restart_failures: u32,
}

impl Load {
    /// Share of the core `task` (index as in `busy_cycles`) took, 0..=1.
    pub fn share(&self, task: usize) -> f64 {
        let busy = self.busy_cycles.get(task).copied().unwrap_or(0);
        f64::from(busy) / f64::from(self.window_cycles.max(1))
    }

    /// The idle task's share: what the tasks left, 0..=1.
    pub fn idle_share(&self) -> f64 {
        let busy: u64 = self.busy_cycles.iter().map(|&c| u64::from(c)).sum();
        let window = u64::from(self.window_cycles.max(1));
        window.saturating_sub(busy) as f64 / window as f64
    }
}

/// Tasks whose load `identify` reports: data-ready, link, receive, and the
/// emulated board's chip model (0 on hardware).
pub const TASKS: usize = 4;

/// What the firmware's tasks cost (`src/device/load.rs` measures it): the
/// shares of the last full second, and the longest runs since start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Load {
    /// Cycles each task took over the last full window (data-ready, link,
    /// receive, chip model), its own time without preemptions.
    pub busy_cycles: [u32; TASKS],
    /// Cycles the window lasted (about one second's worth); what the tasks
    /// left was the idle task's, asleep.
    pub window_cycles: u32,
    /// The rate of the cycle counter, Hz.
    pub cycles_hz: u32,
    /// Each task's longest single run since start, µs (`reset counters`
    /// leaves it: only its task may write it).
    pub max_run_us: [u32; TASKS],
}

/// The reply to `identify`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceInfo {
    /// The link protocol version the device speaks.
    pub protocol: u8,
    /// Firmware version.
    pub firmware: Text,
    /// Board name.
    pub board: Text,
    /// Chip name.
    pub chip: Text,
    /// Sensor bus ("spi" or "i2c").
    pub bus: Text,
    /// The chip's sample rate.
    pub sample_rate_hz: f32,
    /// Samples averaged per streamed frame.
    pub decimation: u16,
    /// What is streamed.
    pub mode: Mode,
    /// The link's baud rate.
    pub baud: u32,
    /// The active calibration's identity.
    pub calibration_id: u32,
    /// Where it came from.
    pub calibration_source: CalibrationSource,
    /// What the flash holds.
    pub stored: StoredState,
    /// Why a stored record was rejected at start-up (sent last, after the
    /// load; a device that does not send it: [`StoredReason::None`]).
    pub stored_reason: StoredReason,
    /// Milliseconds since start, wrapping every 2³² ms (49.7 days).
    pub uptime_ms: u32,
    /// The counters.
    pub counters: Counters,
    /// The chip's nominal scale (what raw frames carry).
    pub scale: RawScale,
    /// What the firmware's tasks cost.
    pub load: Load,
}

impl DeviceInfo {
    /// The reply payload.
    pub fn to_payload(&self) -> Payload {
        let mut p = Payload::EMPTY;
        let mut w = Writer::new(p.buffer());
        w.u8(self.protocol)
            .str(self.firmware.as_str())
            .str(self.board.as_str())
            .str(self.chip.as_str())
            .str(self.bus.as_str())
            .f32(self.sample_rate_hz)
            .u16(self.decimation)
            .u8(self.mode as u8)
            .u32(self.baud)
            .u32(self.calibration_id)
            .u8(self.calibration_source as u8)
            .u8(self.stored as u8)
            .u32(self.uptime_ms);
        let c = &self.counters;
        for v in [
            c.frames_sent,
            c.frames_dropped,
            c.overruns,
            c.read_failures,
            c.commands,
            c.command_errors,
            c.rx_overflows,
        ] {
            w.u32(v);
        }
        let s = &self.scale;
        w.f32(s.accel_si_per_lsb)
            .f32(s.gyro_si_per_lsb)
            .f32(s.temperature_per_lsb)
            .f32(s.temperature_offset);
        let l = &self.load;
        for c in l.busy_cycles {
            w.u32(c);
        }
        w.u32(l.window_cycles).u32(l.cycles_hz);
        for us in l.max_run_us {
            w.u32(us);
        }
        w.u8(self.stored_reason as u8);
        w.u32(c.sensor_stalls).u32(c.sensor_restarts);
        w.u32(c.flash_stalls);
        w.u32(c.sensor_restart_failures);
        let len = w.len();
        p.set_len(len);
        p
    }

    /// Reads an identify payload; `None` when it is short or a code is
    /// undefined.
    pub fn parse(payload: &[u8]) -> Option<DeviceInfo> {
        let mut r = Reader::new(payload);
        let protocol = r.u8();
        let firmware = Text::new(r.str());
        let board = Text::new(r.str());
        let chip = Text::new(r.str());
        let bus = Text::new(r.str());
        let sample_rate_hz = r.f32();
        let decimation = r.u16();
        let mode = Mode::from_byte(r.u8())?;
        let baud = r.u32();
        let calibration_id = r.u32();
        let calibration_source = CalibrationSource::from_byte(r.u8())?;
        let stored = StoredState::from_byte(r.u8())?;
        let uptime_ms = r.u32();
        let counters = Counters {
            frames_sent: r.u32(),
            frames_dropped: r.u32(),
            overruns: r.u32(),
            read_failures: r.u32(),
            commands: r.u32(),
            command_errors: r.u32(),
            rx_overflows: r.u32(),
            sensor_stalls: 0,
            sensor_restarts: 0,
            flash_stalls: 0,
            sensor_restart_failures: 0,
        };
        let scale = RawScale {
            accel_si_per_lsb: r.f32(),
            gyro_si_per_lsb: r.f32(),
            temperature_per_lsb: r.f32(),
            temperature_offset: r.f32(),
        };
        let load = Load {
            busy_cycles: [r.u32(), r.u32(), r.u32(), r.u32()],
            window_cycles: r.u32(),
            cycles_hz: r.u32(),
            max_run_us: [r.u32(), r.u32(), r.u32(), r.u32()],
        };
        if r.ran_short() {
            return None;
        }
        // Added after the load figures: absent from older firmware's reply.
        let rest = r.rest();
        let stored_reason = match rest.first() {
            Some(&byte) => StoredReason::from_byte(byte)?,
            None => StoredReason::None,
        };
        let mut counters = counters;
        // Added after the stored reason: absent from older firmware's reply.
        if let Some(health) = rest.get(1..) {
            let mut r = Reader::new(health);
            let (stalls, restarts) = (r.u32(), r.u32());
            if !r.ran_short() {
                counters.sensor_stalls = stalls;
                counters.sensor_restarts = restarts;
            }
        }
        // Added after the sensor's health: absent from older firmware's reply.
        if let Some(flash) = rest.get(9..) {
            let mut r = Reader::new(flash);
            let stalls = r.u32();
            if !r.ran_short() {
                counters.flash_stalls = stalls;
            }
        }
        // Added after the flash stalls: absent from older firmware's reply.
        if let Some(failed) = rest.get(13..) {
            let mut r = Reader::new(failed);
            let failures = r.u32();
            if !r.ran_short() {
                counters.sensor_restart_failures = failures;
            }
        }
        Some(DeviceInfo {
            protocol,
            firmware,
            board,
            chip,
            bus,
            sample_rate_hz,
            decimation,
            mode,
            baud,
            calibration_id,
            calibration_source,
            stored,
            stored_reason,
            uptime_ms,
            counters,
            scale,
            load,
        })
    }
}
