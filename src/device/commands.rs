//! The device's command handler: one reply for every command, no allocation,
//! host-tested. The firmware feeds it the packets its receive decoder
//! completes ([`CommandHandler::on_packet`]) from a task below the data-ready
//! task; the handler never touches the sampling state itself, it queues
//! [`Control`]s that the data-ready task applies between two samples.
//!
//! What it guarantees (docs/PROTOCOL.md, "Commands"):
//! - every command packet, good or bad, gets exactly one reply naming its
//!   sequence number and code (read from the received bytes when the packet
//!   failed its checks);
//! - a command received again with the sequence number and CRC of the last
//!   one handled is answered with the same reply and not applied again;
//! - an uploaded calibration is checked as `triad calib check` checks it
//!   (blob CRC and version, then [`Corrector::new`] for this chip's ranges)
//!   and applied whole or not at all: a rejected upload changes nothing;
//! - a save goes through [`CalibrationStore`], which a power cut cannot
//!   leave half-written.

// Replies carry their payload inline (no heap on the device), so the enums
// and results holding one are a few hundred bytes; each is moved once per
// command, far from the sampling path.
#![allow(clippy::large_enum_variant, clippy::result_large_err)]

use core::fmt::Write;

use embedded_storage::nor_flash::{NorFlash, NorFlashError};

use super::{CalibrationStore, Control, SharedCounters, StorageError};
use crate::model::blob::{self, BlobError, BLOB_LEN};
use crate::model::{Corrector, FixedCorrector, Orientation};
use crate::protocol::bytes::Writer;
use crate::protocol::crc32c::crc32c;
use crate::protocol::DecodeError;
use crate::protocol::{
    CalibrationSource, Command, DeviceInfo, Mode, Packet, PacketType, Payload, RawScale, Reply,
    SelfTestResult, Status, StoredReason, StoredState, Text, CHUNK_LEN,
};
use crate::sensor::self_test::{ChipLeft, SelfTestError, SelfTestReport};
use crate::sensor::ImuScale;

/// The facts about the device that do not change while it runs.
#[derive(Clone, Copy, Debug)]
pub struct DeviceFacts {
    /// Firmware version.
    pub firmware: &'static str,
    /// Board name.
    pub board: &'static str,
    /// Chip name.
    pub chip: &'static str,
    /// Sensor bus ("spi" or "i2c").
    pub bus: &'static str,
    /// The chip's sample rate.
    pub sample_rate_hz: f32,
    /// The link's baud rate.
    pub baud: u32,
    /// The chip's configured scale (what calibrations are checked against).
    pub scale: ImuScale,
    /// How the chip is mounted.
    pub orientation: Orientation,
    /// The rate of the board's cycle counter (the load measurement's clock).
    pub cycles_hz: u32,
}

/// The calibration in force, as the handler knows it.
#[derive(Clone, Debug)]
pub struct ActiveCalibration {
    /// Its blob (`None`: the identity, uncalibrated).
    pub blob: Option<[u8; BLOB_LEN]>,
    /// Its identity.
    pub id: u32,
    /// Where it came from.
    pub source: CalibrationSource,
}

/// What the handler did with a packet.
#[derive(Clone, Debug, PartialEq)]
pub enum Handled {
    /// Send this reply.
    Reply(Reply),
    /// Run the chip's self-test (sampling paused), then send
    /// [`CommandHandler::self_test_reply`].
    SelfTest {
        /// The command's sequence number.
        sequence: u16,
    },
    /// Not a command (a packet a device ignores, or an error before the
    /// decoder was in step): nothing to send.
    Nothing,
}

/// The last reply sent, kept to answer a retry.
#[derive(Clone, Copy, Debug)]
struct LastReply {
    sequence: u16,
    crc: u32,
    reply: Reply,
}

/// The command handler's state.
pub struct CommandHandler<F> {
    facts: DeviceFacts,
    store: Option<CalibrationStore<F>>,
    stored: StoredState,
    stored_reason: StoredReason,
    active: ActiveCalibration,
    mode: Mode,
    decimation: u16,
    upload: [u8; BLOB_LEN],
    upload_len: usize,
    last: Option<LastReply>,
    commands: u32,
    errors: u32,
    baseline: crate::protocol::Counters,
    /// No chip has answered on the bus yet (the firmware keeps looking):
    /// the commands that need one are refused until [`CommandHandler::sensor_found`].
    awaiting_sensor: bool,
}

/// What `identify` says for the chip while none has answered on the bus.
pub const NO_SENSOR: &str = "none";

/// Where the step is in handling one command.
type Outcome = Result<Payload, (Status, Payload)>;

/// An error reply's status and its reason, formatted without allocating.
fn fail(status: Status, reason: core::fmt::Arguments<'_>) -> (Status, Payload) {
    let mut text = Payload::EMPTY;
    let _ = text.write_fmt(reason);
    (status, text)
}

/// Whether `command` needs the chip: its mode and decimation are the
/// sampler's, an upload is checked against the chip's ranges, and a save
/// or an erase changes the store the calibration is chosen from when the
/// chip answers.
fn needs_sensor(command: &Command) -> bool {
    !matches!(
        command,
        Command::Identify | Command::ReadCalibration { .. } | Command::ResetCounters
    )
}

/// The reply status for a blob the device cannot read.
fn blob_status(error: &BlobError) -> Status {
    match error {
        BlobError::CrcMismatch { .. } => Status::BadCrc,
        BlobError::UnsupportedVersion { .. } => Status::WrongVersion,
        _ => Status::InvalidCalibration,
    }
}

impl<F: NorFlash> CommandHandler<F> {
    /// A handler for a device described by `facts`, running `active` with
    /// `decimation`, over `store` (`None`: this board keeps nothing), whose
    /// content at start-up was `stored`.
    pub fn new(
        facts: DeviceFacts,
        active: ActiveCalibration,
        decimation: u16,
        store: Option<CalibrationStore<F>>,
        stored: StoredState,
    ) -> Self {
        Self {
            facts,
            store,
            stored,
            stored_reason: StoredReason::None,
            active,
            mode: Mode::Calibrated,
            decimation,
            upload: [0; BLOB_LEN],
            upload_len: 0,
            last: None,
            commands: 0,
            errors: 0,
            baseline: crate::protocol::Counters::default(),
            awaiting_sensor: false,
        }
    }

    /// The handler of a device whose chip has not answered on the bus yet
    /// (`facts` say chip [`NO_SENSOR`]): it answers identify, read-back and
    /// reset-counters, and refuses what needs the chip (mode, decimation,
    /// an upload, save, erase, the self-test) until
    /// [`CommandHandler::sensor_found`].
    pub fn awaiting_sensor(mut self) -> Self {
        self.awaiting_sensor = true;
        self
    }

    /// The chip answered (late): the device's facts for it, the calibration
    /// chosen for it, and what the store's record is for it and why (the
    /// store is as at start-up: nothing that changes it ran meanwhile).
    pub fn sensor_found(
        &mut self,
        facts: DeviceFacts,
        active: ActiveCalibration,
        stored: StoredState,
        stored_reason: StoredReason,
    ) {
        self.facts = facts;
        self.active = active;
        self.stored = stored;
        self.stored_reason = stored_reason;
        self.awaiting_sensor = false;
    }

    /// The handler, with why the flash's record was rejected at start-up
    /// (`identify` reports it until a save or an erase changes the flash).
    pub fn with_stored_reason(mut self, reason: StoredReason) -> Self {
        self.stored_reason = reason;
        self
    }

    /// The calibration in force as the handler last applied it.
    pub fn active(&self) -> &ActiveCalibration {
        &self.active
    }

    /// The calibration store, if the device has one (tests arm a power cut
    /// in its flash).
    pub fn store_mut(&mut self) -> Option<&mut CalibrationStore<F>> {
        self.store.as_mut()
    }

    /// The store, given back.
    pub fn into_store(self) -> Option<CalibrationStore<F>> {
        self.store
    }

    /// What the flash holds.
    pub fn stored(&self) -> StoredState {
        self.stored
    }

    /// Handles one decoded packet (or decoding error); `bytes` are its
    /// unstuffed bytes as received (for the sequence number of a packet that
    /// failed its checks), `counters` what identify reports. `submit` queues a change for the data-ready task
    /// and says whether it had room.
    pub fn on_packet(
        &mut self,
        decoded: &Result<Packet, DecodeError>,
        bytes: &[u8],
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
    ) -> Handled {
        let packet = match decoded {
            Ok(Packet::Command(packet)) => packet,
            // A device ignores what devices send (a looped-back line).
            Ok(_) => return Handled::Nothing,
            Err(error) => return self.rejected(error, bytes),
        };
        // The packet's own CRC tells two commands with one number apart (a
        // CRC over bytes that end in their CRC would not: it is a constant).
        let crc = match bytes.split_last_chunk::<4>() {
            Some((_, crc)) => u32::from_le_bytes(*crc),
            None => 0,
        };
        if let Some(last) = &self.last {
            if last.sequence == packet.sequence && last.crc == crc {
                // Answered again, counted again: as an error when it is one,
                // so `commands` and `command_errors` count the same replies.
                self.commands = self.commands.wrapping_add(1);
                if last.reply.status != Status::Ok {
                    self.errors = self.errors.wrapping_add(1);
                }
                return Handled::Reply(last.reply);
            }
        }
        let outcome = match packet.command() {
            Ok(command) if self.awaiting_sensor && needs_sensor(&command) => Err(fail(
                Status::SensorError,
                format_args!(
                    "no sensor: no known chip has answered on the {} bus yet (the firmware \
                     keeps looking)",
                    self.facts.bus
                ),
            )),
            Ok(Command::SelfTest) => {
                // Counted when its reply is made (`self_test_reply`).
                self.last = None;
                return Handled::SelfTest {
                    sequence: packet.sequence,
                };
            }
            Ok(command) => self.run(command, counters, submit),
            Err(error) => Err(fail(
                match error {
                    crate::protocol::CommandError::Unknown { .. } => Status::UnknownCommand,
                    crate::protocol::CommandError::Length { .. } => Status::Malformed,
                    crate::protocol::CommandError::Value { .. } => Status::BadArgument,
                },
                format_args!("{error}"),
            )),
        };
        let reply = self.reply(packet.sequence, packet.code, outcome);
        self.last = Some(LastReply {
            sequence: packet.sequence,
            crc,
            reply,
        });
        Handled::Reply(reply)
    }

    /// The reply to a packet that failed its checks: its sequence number
    /// and code are read from the bytes as received, which may be wrong.
    fn rejected(&mut self, error: &DecodeError, bytes: &[u8]) -> Handled {
        let status = match error {
            DecodeError::Crc { .. } => Status::BadCrc,
            DecodeError::Version { .. } => Status::WrongVersion,
            DecodeError::Type { .. } => Status::UnknownCommand,
            DecodeError::Stuffing | DecodeError::Length { .. } | DecodeError::Body { .. } => {
                Status::Malformed
            }
        };
        // A packet that says it is a reply or a raw frame with a bad CRC is
        // a device's, not a command: nothing to answer.
        let kind = bytes.get(1).copied();
        if matches!(error, DecodeError::Crc { .. })
            && kind != Some(PacketType::Command as u8)
            && bytes.first() == Some(&crate::protocol::packet::VERSION)
        {
            return Handled::Nothing;
        }
        let sequence = u16::from_le_bytes([
            bytes.get(2).copied().unwrap_or(0),
            bytes.get(3).copied().unwrap_or(0),
        ]);
        let code = bytes.get(4).copied().unwrap_or(0);
        Handled::Reply(self.reply(sequence, code, Err(fail(status, format_args!("{error}")))))
    }

    /// Counts the outcome and makes the reply.
    fn reply(&mut self, sequence: u16, command: u8, outcome: Outcome) -> Reply {
        self.commands = self.commands.wrapping_add(1);
        let (status, payload) = match outcome {
            Ok(payload) => (Status::Ok, payload),
            Err((status, reason)) => {
                self.errors = self.errors.wrapping_add(1);
                (status, reason)
            }
        };
        Reply {
            sequence,
            command,
            status,
            payload,
        }
    }

    /// The reply to the self-test the firmware ran after
    /// [`Handled::SelfTest`] (with sampling paused): the report, or why it
    /// did not finish and what state it left the chip in.
    pub fn self_test_reply<E: core::fmt::Debug>(
        &mut self,
        sequence: u16,
        result: &Result<SelfTestReport, SelfTestError<E>>,
    ) -> Reply {
        let outcome = match result {
            Ok(report) => Ok(SelfTestResult::of(report).to_payload()),
            Err(e) => Err(fail(
                Status::SensorError,
                format_args!(
                    "the self-test did not finish: {:?}; the chip is {}",
                    e.error,
                    match e.chip {
                        ChipLeft::AsConfigured => "configured as before",
                        ChipLeft::NeedsInit => "being restarted",
                    }
                ),
            )),
        };
        self.reply(sequence, crate::protocol::command::code::SELF_TEST, outcome)
    }

    fn run(
        &mut self,
        command: Command,
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
    ) -> Outcome {
        match command {
            Command::Identify => Ok(self.info(counters).to_payload()),
            Command::SetMode(mode) => {
                queue(submit, Control::SetMode(mode))?;
                self.mode = mode;
                Ok(Payload::EMPTY)
            }
            Command::SetDecimation(n) => {
                queue(submit, Control::SetDecimation(n))?;
                self.decimation = n;
                Ok(Payload::EMPTY)
            }
            Command::UploadChunk { offset, data } => self.upload_chunk(offset, data.as_slice()),
            Command::UploadCommit { len, crc } => self.commit(len, crc, submit),
            Command::ReadCalibration { offset } => self.read_back(offset),
            Command::Save => self.save(),
            Command::Erase => self.erase(),
            Command::ResetCounters => {
                self.baseline = counters.snapshot();
                self.commands = 0;
                self.errors = 0;
                Ok(Payload::EMPTY)
            }
            // Never reached: on_packet hands self-tests to the firmware.
            Command::SelfTest => Err(fail(
                Status::Busy,
                format_args!("self-test is run by the firmware"),
            )),
        }
    }

    /// The identify reply.
    pub fn info(&self, counters: &SharedCounters) -> DeviceInfo {
        let now = counters.snapshot();
        let b = &self.baseline;
        let mut c = now;
        c.frames_sent = now.frames_sent.wrapping_sub(b.frames_sent);
        c.frames_dropped = now.frames_dropped.wrapping_sub(b.frames_dropped);
        c.overruns = now.overruns.wrapping_sub(b.overruns);
        c.read_failures = now.read_failures.wrapping_sub(b.read_failures);
        c.rx_overflows = now.rx_overflows.wrapping_sub(b.rx_overflows);
        c.sensor_stalls = now.sensor_stalls.wrapping_sub(b.sensor_stalls);
        c.sensor_restarts = now.sensor_restarts.wrapping_sub(b.sensor_restarts);
        c.flash_stalls = now.flash_stalls.wrapping_sub(b.flash_stalls);
        // This command is counted once its reply is made.
        c.commands = self.commands.wrapping_add(1);
        c.command_errors = self.errors;
        DeviceInfo {
            protocol: crate::protocol::packet::VERSION,
            firmware: Text::new(self.facts.firmware),
            board: Text::new(self.facts.board),
            chip: Text::new(self.facts.chip),
            bus: Text::new(self.facts.bus),
            sample_rate_hz: self.facts.sample_rate_hz,
            decimation: self.decimation,
            mode: self.mode,
            baud: self.facts.baud,
            calibration_id: self.active.id,
            calibration_source: self.active.source,
            stored: self.stored,
            stored_reason: self.stored_reason,
            uptime_ms: counters.uptime_ms(),
            counters: c,
            scale: RawScale::of(&self.facts.scale),
            load: counters.load.load(self.facts.cycles_hz),
        }
    }

    fn upload_chunk(&mut self, offset: u16, data: &[u8]) -> Outcome {
        let offset = usize::from(offset);
        if offset == 0 {
            self.upload_len = 0;
        }
        if offset != self.upload_len {
            return Err(fail(
                Status::BadArgument,
                format_args!(
                    "upload chunk at offset {offset}, expected {} (chunks come in order from 0)",
                    self.upload_len
                ),
            ));
        }
        let end = offset + data.len();
        let Some(slot) = self.upload.get_mut(offset..end) else {
            return Err(fail(
                Status::BadArgument,
                format_args!("upload chunk ends at byte {end}, past the {BLOB_LEN}-byte blob"),
            ));
        };
        slot.copy_from_slice(data);
        self.upload_len = end;
        Ok(Payload::EMPTY)
    }

    fn commit(&mut self, len: u16, crc: u32, submit: &mut dyn FnMut(Control) -> bool) -> Outcome {
        let uploaded = core::mem::take(&mut self.upload_len);
        if usize::from(len) != uploaded {
            return Err(fail(
                Status::BadArgument,
                format_args!("commit of {len} bytes, but {uploaded} were uploaded"),
            ));
        }
        let bytes = &self.upload[..uploaded];
        let computed = crc32c(bytes);
        if computed != crc {
            return Err(fail(
                Status::BadCrc,
                format_args!(
                    "the uploaded bytes have CRC-32C {computed:#010x}, the commit says {crc:#010x}"
                ),
            ));
        }
        let cal = blob::decode(bytes)
            .map_err(|e| fail(blob_status(&e), format_args!("not a calibration blob: {e}")))?;
        // The checks of `triad calib check`: the calibration folded for this
        // chip, and its fixed-point form (which the Cortex-M0 path runs).
        // The control is built around the corrector in place: one corrector
        // on the stack (the Cortex-M0's 16 KiB).
        let id = cal.id;
        let control = Control::Calibrate(
            Corrector::new(&cal, &self.facts.scale, self.facts.orientation)
                .map_err(|e| fail(Status::InvalidCalibration, format_args!("{e}")))?,
        );
        if let Control::Calibrate(corrector) = &control {
            FixedCorrector::new(corrector)
                .map_err(|e| fail(Status::InvalidCalibration, format_args!("{e}")))?;
        }
        // A version-2 blob is kept (read back, saved) in the current layout,
        // encoded over the upload buffer: no more blob copies on the stack
        // (the Cortex-M0's 16 KiB), and `cal` is dead before the queue's.
        if uploaded != BLOB_LEN {
            blob::encode_into(&cal, &mut self.upload);
        }
        queue(submit, control)?;
        self.active = ActiveCalibration {
            blob: Some(self.upload),
            id,
            source: CalibrationSource::Uploaded,
        };
        let mut p = Payload::EMPTY;
        let mut w = Writer::new(p.buffer());
        w.u32(id);
        p.set_len(4);
        Ok(p)
    }

    fn read_back(&self, offset: u16) -> Outcome {
        let Some(blob) = &self.active.blob else {
            let mut p = Payload::EMPTY;
            Writer::new(p.buffer()).u16(0);
            p.set_len(2);
            return Ok(p);
        };
        let offset = usize::from(offset);
        let Some(rest) = blob.get(offset..) else {
            return Err(fail(
                Status::BadArgument,
                format_args!("read from byte {offset}, past the {BLOB_LEN}-byte blob"),
            ));
        };
        let chunk = &rest[..rest.len().min(CHUNK_LEN)];
        let mut p = Payload::EMPTY;
        let mut w = Writer::new(p.buffer());
        w.u16(BLOB_LEN as u16).bytes(chunk);
        let n = w.len();
        p.set_len(n);
        Ok(p)
    }

    fn no_storage() -> (Status, Payload) {
        fail(
            Status::NotSupported,
            format_args!("this board has no calibration storage"),
        )
    }

    fn save(&mut self) -> Outcome {
        let Some(blob) = self.active.blob else {
            return Err(fail(
                Status::BadArgument,
                format_args!(
                    "no calibration is active (the identity is not saved); upload one first"
                ),
            ));
        };
        let store = self.store.as_mut().ok_or_else(Self::no_storage)?;
        match store.save(&blob) {
            Ok(stored) => {
                self.stored = StoredState::Valid;
                self.stored_reason = StoredReason::None;
                self.active.source = CalibrationSource::Stored;
                let mut p = Payload::EMPTY;
                let mut w = Writer::new(p.buffer());
                w.u32(stored.generation).u8(stored.slot);
                p.set_len(5);
                Ok(p)
            }
            Err(e) => {
                // A failed save may have erased the other slot: what the flash
                // holds is re-read at the next start-up; the active
                // calibration is unchanged.
                Err(storage_failure("save", &e))
            }
        }
    }

    fn erase(&mut self) -> Outcome {
        let store = self.store.as_mut().ok_or_else(Self::no_storage)?;
        store.erase().map_err(|e| storage_failure("erase", &e))?;
        self.stored = StoredState::Empty;
        self.stored_reason = StoredReason::None;
        Ok(Payload::EMPTY)
    }
}

/// Offers `control` to the data-ready task; a full queue is a busy reply.
fn queue(
    submit: &mut dyn FnMut(Control) -> bool,
    control: Control,
) -> Result<(), (Status, Payload)> {
    if submit(control) {
        Ok(())
    } else {
        Err(fail(
            Status::Busy,
            format_args!("the sampling task has not taken the previous change yet"),
        ))
    }
}

/// A storage error as a reply.
fn storage_failure<E: NorFlashError>(what: &str, error: &StorageError<E>) -> (Status, Payload) {
    match error {
        StorageError::Flash(e) => fail(
            Status::StorageFailure,
            format_args!("{what} failed: flash error {:?}", e.kind()),
        ),
        StorageError::Layout { what: why, value } => fail(
            Status::StorageFailure,
            format_args!("{what} failed: {why} (value {value})"),
        ),
    }
}
