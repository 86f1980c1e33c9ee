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
    CalibrationSource, Command, Completed, DeviceInfo, Mode, Packet, PacketType, Payload, RawScale,
    Received, Reply, SelfTestResult, Status, StoredReason, StoredState, Text, CHUNK_LEN,
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

/// What the handler did with a packet, its reply where the handler wrote
/// it ([`CommandHandler::answer`]): the firmware encodes it from there
/// straight to wire bytes, so no reply is copied on the way.
#[derive(Debug, PartialEq)]
pub enum Answer<'a> {
    /// Send this reply.
    Reply(&'a Reply),
    /// Run the chip's self-test, as [`Handled::SelfTest`].
    SelfTest {
        /// The command's sequence number.
        sequence: u16,
    },
    /// Nothing to send, as [`Handled::Nothing`].
    Nothing,
}

/// The command the kept reply answers: a retry is known by both.
#[derive(Clone, Copy, Debug)]
struct LastCommand {
    sequence: u16,
    crc: u32,
}

/// The command handler's state. Its replies are written where they are
/// kept (a few hundred bytes each: no copy per command), in slots apart
/// from the state the commands change, so that a command's work can write
/// its reply's payload in place.
pub struct CommandHandler<F> {
    state: State<F>,
    /// The last command's reply; a retry of that command gets it again.
    answered: Reply,
    /// The command `answered` answers (`None`: no reply kept).
    last: Option<LastCommand>,
    /// The reply to a packet that failed its checks (apart from
    /// `answered`, which a retry of the last command still gets).
    rejected: Reply,
}

/// What the commands read and change.
struct State<F> {
    facts: DeviceFacts,
    store: Option<CalibrationStore<F>>,
    stored: StoredState,
    stored_reason: StoredReason,
    active: ActiveCalibration,
    mode: Mode,
    decimation: u16,
    upload: [u8; BLOB_LEN],
    upload_len: usize,
    commands: u32,
    errors: u32,
    baseline: crate::protocol::Counters,
    /// No chip has answered on the bus yet (the firmware keeps looking):
    /// the commands that need one are refused until [`CommandHandler::sensor_found`].
    awaiting_sensor: bool,
}

/// What `identify` says for the chip while none has answered on the bus.
pub const NO_SENSOR: &str = "none";

/// How a command ended; its result or reason is in the reply's payload.
type Outcome = Result<(), Status>;

/// Writes an error's reason into `out` (formatted without allocating)
/// and gives its status.
fn fail(out: &mut Payload, status: Status, reason: core::fmt::Arguments<'_>) -> Status {
    out.set_len(0);
    let _ = out.write_fmt(reason);
    status
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

/// A reply to nothing yet: what the slots hold before their first.
const NO_REPLY: Reply = Reply {
    sequence: 0,
    command: 0,
    status: Status::Ok,
    payload: Payload::EMPTY,
};

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
            state: State {
                facts,
                store,
                stored,
                stored_reason: StoredReason::None,
                active,
                mode: Mode::Calibrated,
                decimation,
                upload: [0; BLOB_LEN],
                upload_len: 0,
                commands: 0,
                errors: 0,
                baseline: crate::protocol::Counters::default(),
                awaiting_sensor: false,
            },
            answered: NO_REPLY,
            last: None,
            rejected: NO_REPLY,
        }
    }

    /// The handler of a device whose chip has not answered on the bus yet
    /// (`facts` say chip [`NO_SENSOR`]): it answers identify, read-back and
    /// reset-counters, and refuses what needs the chip (mode, decimation,
    /// an upload, save, erase, the self-test) until
    /// [`CommandHandler::sensor_found`].
    pub fn awaiting_sensor(mut self) -> Self {
        self.state.awaiting_sensor = true;
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
        self.state.facts = facts;
        self.state.active = active;
        self.state.stored = stored;
        self.state.stored_reason = stored_reason;
        self.state.awaiting_sensor = false;
    }

    /// The handler, with why the flash's record was rejected at start-up
    /// (`identify` reports it until a save or an erase changes the flash).
    pub fn with_stored_reason(mut self, reason: StoredReason) -> Self {
        self.state.stored_reason = reason;
        self
    }

    /// The calibration in force as the handler last applied it.
    pub fn active(&self) -> &ActiveCalibration {
        &self.state.active
    }

    /// The calibration store, if the device has one (tests arm a power cut
    /// in its flash).
    pub fn store_mut(&mut self) -> Option<&mut CalibrationStore<F>> {
        self.state.store.as_mut()
    }

    /// The store, given back.
    pub fn into_store(self) -> Option<CalibrationStore<F>> {
        self.state.store
    }

    /// What the flash holds.
    pub fn stored(&self) -> StoredState {
        self.state.stored
    }

    /// The identify reply.
    pub fn info(&self, counters: &SharedCounters) -> DeviceInfo {
        self.state.info(counters)
    }

    /// Handles one decoded packet (or decoding error); `bytes` are its
    /// unstuffed bytes as received (for the sequence number of a packet that
    /// failed its checks), `counters` what identify reports. `submit` queues a change for the data-ready task
    /// and says whether it had room. [`CommandHandler::answer`], the reply
    /// copied out.
    pub fn on_packet(
        &mut self,
        decoded: &Result<Packet, DecodeError>,
        bytes: &[u8],
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
    ) -> Handled {
        match self.answer(decoded, bytes, counters, submit) {
            Answer::Reply(reply) => Handled::Reply(*reply),
            Answer::SelfTest { sequence } => Handled::SelfTest { sequence },
            Answer::Nothing => Handled::Nothing,
        }
    }

    /// [`CommandHandler::on_packet`] with the reply where the handler
    /// wrote it.
    pub fn answer(
        &mut self,
        decoded: &Result<Packet, DecodeError>,
        bytes: &[u8],
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
    ) -> Answer<'_> {
        let received = match decoded {
            Ok(Packet::Command(packet)) => Ok(Received::Command(packet.as_ref())),
            Ok(_) => Ok(Received::Other),
            Err(error) => Err(*error),
        };
        self.answer_received(
            &Completed {
                decoded: received,
                bytes,
            },
            counters,
            submit,
        )
    }

    /// [`CommandHandler::answer`] for a packet as the device's decoder
    /// completed it ([`crate::protocol::Decoder::push_command`]: a command
    /// read where it lies): the firmware's form, no packet or reply copied.
    pub fn answer_received(
        &mut self,
        completed: &Completed<'_>,
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
    ) -> Answer<'_> {
        let bytes = completed.bytes;
        let packet = match &completed.decoded {
            Ok(Received::Command(packet)) => packet,
            // A device ignores what devices send (a looped-back line).
            Ok(Received::Other) => return Answer::Nothing,
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
                self.state.count(self.answered.status);
                return Answer::Reply(&self.answered);
            }
        }
        let command = packet.command();
        // Without a chip the self-test is refused below, as what needs one.
        if let (Ok(Command::SelfTest), false) = (&command, self.state.awaiting_sensor) {
            // Counted when its reply is made (`self_test_reply`).
            self.last = None;
            return Answer::SelfTest {
                sequence: packet.sequence,
            };
        }
        let reply = &mut self.answered;
        reply.sequence = packet.sequence;
        reply.command = packet.code;
        reply.payload.set_len(0);
        let outcome = match command {
            Ok(command) if self.state.awaiting_sensor && needs_sensor(&command) => Err(fail(
                &mut reply.payload,
                Status::SensorError,
                format_args!(
                    "no sensor: no known chip has answered on the {} bus yet (the firmware \
                     keeps looking)",
                    self.state.facts.bus
                ),
            )),
            Ok(command) => self
                .state
                .run(command, counters, submit, &mut reply.payload),
            Err(error) => Err(fail(
                &mut reply.payload,
                match error {
                    crate::protocol::CommandError::Unknown { .. } => Status::UnknownCommand,
                    crate::protocol::CommandError::Length { .. } => Status::Malformed,
                    crate::protocol::CommandError::Value { .. } => Status::BadArgument,
                },
                format_args!("{error}"),
            )),
        };
        reply.status = outcome.err().unwrap_or(Status::Ok);
        self.state.count(reply.status);
        self.last = Some(LastCommand {
            sequence: packet.sequence,
            crc,
        });
        Answer::Reply(&self.answered)
    }

    /// The reply to a packet that failed its checks: its sequence number
    /// and code are read from the bytes as received, which may be wrong.
    fn rejected(&mut self, error: &DecodeError, bytes: &[u8]) -> Answer<'_> {
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
            return Answer::Nothing;
        }
        let reply = &mut self.rejected;
        reply.sequence = u16::from_le_bytes([
            bytes.get(2).copied().unwrap_or(0),
            bytes.get(3).copied().unwrap_or(0),
        ]);
        reply.command = bytes.get(4).copied().unwrap_or(0);
        reply.status = fail(&mut reply.payload, status, format_args!("{error}"));
        self.state.count(reply.status);
        Answer::Reply(&self.rejected)
    }

    /// The reply to the self-test the firmware ran after
    /// [`Handled::SelfTest`] (with sampling paused): the report, or why it
    /// did not finish and what state it left the chip in.
    pub fn self_test_reply<E: core::fmt::Debug>(
        &mut self,
        sequence: u16,
        result: &Result<SelfTestReport, SelfTestError<E>>,
    ) -> Reply {
        let mut reply = Reply {
            sequence,
            command: crate::protocol::command::code::SELF_TEST,
            ..NO_REPLY
        };
        reply.status = match result {
            Ok(report) => {
                reply.payload = SelfTestResult::of(report).to_payload();
                Status::Ok
            }
            Err(e) => fail(
                &mut reply.payload,
                Status::SensorError,
                format_args!(
                    "the self-test did not finish: {:?}; the chip is {}",
                    e.error,
                    match e.chip {
                        ChipLeft::AsConfigured => "configured as before",
                        ChipLeft::NeedsInit => "being restarted",
                    }
                ),
            ),
        };
        self.state.count(reply.status);
        reply
    }
}

impl<F: NorFlash> State<F> {
    /// Counts a reply of `status`.
    fn count(&mut self, status: Status) {
        self.commands = self.commands.wrapping_add(1);
        if status != Status::Ok {
            self.errors = self.errors.wrapping_add(1);
        }
    }

    /// Runs `command`, its result or its reason written into `out`
    /// (empty on entry).
    fn run(
        &mut self,
        command: Command,
        counters: &SharedCounters,
        submit: &mut dyn FnMut(Control) -> bool,
        out: &mut Payload,
    ) -> Outcome {
        match command {
            Command::Identify => self.identify(counters, out),
            Command::SetMode(mode) => {
                queue(submit, Control::SetMode(mode), out)?;
                self.mode = mode;
                Ok(())
            }
            Command::SetDecimation(n) => {
                queue(submit, Control::SetDecimation(n), out)?;
                self.decimation = n;
                Ok(())
            }
            Command::UploadChunk { offset, data } => {
                self.upload_chunk(offset, data.as_slice(), out)
            }
            Command::UploadCommit { len, crc } => self.commit(len, crc, submit, out),
            Command::ReadCalibration { offset } => self.read_back(offset, out),
            Command::Save => self.save(out),
            Command::Erase => self.erase(out),
            Command::ResetCounters => {
                self.baseline = counters.snapshot();
                self.commands = 0;
                self.errors = 0;
                Ok(())
            }
            // Never reached: on_packet hands self-tests to the firmware.
            Command::SelfTest => Err(fail(
                out,
                Status::Busy,
                format_args!("self-test is run by the firmware"),
            )),
        }
    }

    /// The identify reply's payload into `out`. Out of line, as each
    /// command that holds more than a few bytes on the stack: a command's
    /// frame is then its own, and the trivial ones stay small (the link
    /// task's share of the one stack).
    #[inline(never)]
    fn identify(&self, counters: &SharedCounters, out: &mut Payload) -> Outcome {
        *out = self.info(counters).to_payload();
        Ok(())
    }

    fn info(&self, counters: &SharedCounters) -> DeviceInfo {
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
        c.sensor_restart_failures = now
            .sensor_restart_failures
            .wrapping_sub(b.sensor_restart_failures);
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

    fn upload_chunk(&mut self, offset: u16, data: &[u8], out: &mut Payload) -> Outcome {
        let offset = usize::from(offset);
        if offset == 0 {
            self.upload_len = 0;
        }
        if offset != self.upload_len {
            return Err(fail(
                out,
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
                out,
                Status::BadArgument,
                format_args!("upload chunk ends at byte {end}, past the {BLOB_LEN}-byte blob"),
            ));
        };
        slot.copy_from_slice(data);
        self.upload_len = end;
        Ok(())
    }

    #[inline(never)]
    fn commit(
        &mut self,
        len: u16,
        crc: u32,
        submit: &mut dyn FnMut(Control) -> bool,
        out: &mut Payload,
    ) -> Outcome {
        let uploaded = core::mem::take(&mut self.upload_len);
        if usize::from(len) != uploaded {
            return Err(fail(
                out,
                Status::BadArgument,
                format_args!("commit of {len} bytes, but {uploaded} were uploaded"),
            ));
        }
        let bytes = &self.upload[..uploaded];
        let computed = crc32c(bytes);
        if computed != crc {
            return Err(fail(
                out,
                Status::BadCrc,
                format_args!(
                    "the uploaded bytes have CRC-32C {computed:#010x}, the commit says {crc:#010x}"
                ),
            ));
        }
        let cal = blob::decode(bytes).map_err(|e| {
            fail(
                out,
                blob_status(&e),
                format_args!("not a calibration blob: {e}"),
            )
        })?;
        // The checks of `triad calib check`: the calibration folded for this
        // chip, and its fixed-point form (which the Cortex-M0 path runs).
        // The control is built around the corrector in place: one corrector
        // on the stack (the Cortex-M0's 16 KiB).
        let id = cal.id;
        let control = Control::Calibrate(
            Corrector::new(&cal, &self.facts.scale, self.facts.orientation)
                .map_err(|e| fail(out, Status::InvalidCalibration, format_args!("{e}")))?,
        );
        if let Control::Calibrate(corrector) = &control {
            FixedCorrector::new(corrector)
                .map_err(|e| fail(out, Status::InvalidCalibration, format_args!("{e}")))?;
        }
        // A version-2 blob is kept (read back, saved) in the current layout,
        // encoded over the upload buffer: no more blob copies on the stack
        // (the Cortex-M0's 16 KiB), and `cal` is dead before the queue's.
        if uploaded != BLOB_LEN {
            blob::encode_into(&cal, &mut self.upload);
        }
        queue(submit, control, out)?;
        self.active = ActiveCalibration {
            blob: Some(self.upload),
            id,
            source: CalibrationSource::Uploaded,
        };
        Writer::new(out.buffer()).u32(id);
        out.set_len(4);
        Ok(())
    }

    #[inline(never)]
    fn read_back(&self, offset: u16, out: &mut Payload) -> Outcome {
        let Some(blob) = &self.active.blob else {
            Writer::new(out.buffer()).u16(0);
            out.set_len(2);
            return Ok(());
        };
        let offset = usize::from(offset);
        let Some(rest) = blob.get(offset..) else {
            return Err(fail(
                out,
                Status::BadArgument,
                format_args!("read from byte {offset}, past the {BLOB_LEN}-byte blob"),
            ));
        };
        let chunk = &rest[..rest.len().min(CHUNK_LEN)];
        let mut w = Writer::new(out.buffer());
        w.u16(BLOB_LEN as u16).bytes(chunk);
        let n = w.len();
        out.set_len(n);
        Ok(())
    }

    fn no_storage(out: &mut Payload) -> Status {
        fail(
            out,
            Status::NotSupported,
            format_args!("this board has no calibration storage"),
        )
    }

    #[inline(never)]
    fn save(&mut self, out: &mut Payload) -> Outcome {
        let Some(blob) = self.active.blob else {
            return Err(fail(
                out,
                Status::BadArgument,
                format_args!(
                    "no calibration is active (the identity is not saved); upload one first"
                ),
            ));
        };
        let Some(store) = self.store.as_mut() else {
            return Err(Self::no_storage(out));
        };
        match store.save(&blob) {
            Ok(stored) => {
                self.stored = StoredState::Valid;
                self.stored_reason = StoredReason::None;
                self.active.source = CalibrationSource::Stored;
                Writer::new(out.buffer())
                    .u32(stored.generation)
                    .u8(stored.slot);
                out.set_len(5);
                Ok(())
            }
            Err(e) => {
                // A failed save may have erased the other slot: what the flash
                // holds is re-read at the next start-up; the active
                // calibration is unchanged.
                Err(storage_failure("save", &e, out))
            }
        }
    }

    #[inline(never)]
    fn erase(&mut self, out: &mut Payload) -> Outcome {
        let Some(store) = self.store.as_mut() else {
            return Err(Self::no_storage(out));
        };
        store
            .erase()
            .map_err(|e| storage_failure("erase", &e, out))?;
        self.stored = StoredState::Empty;
        self.stored_reason = StoredReason::None;
        Ok(())
    }
}

/// Offers `control` to the data-ready task; a full queue is a busy reply
/// (its reason written into `out`).
fn queue(submit: &mut dyn FnMut(Control) -> bool, control: Control, out: &mut Payload) -> Outcome {
    if submit(control) {
        Ok(())
    } else {
        Err(fail(
            out,
            Status::Busy,
            format_args!("the sampling task has not taken the previous change yet"),
        ))
    }
}

/// A storage error as a reply.
fn storage_failure<E: NorFlashError>(
    what: &str,
    error: &StorageError<E>,
    out: &mut Payload,
) -> Status {
    match error {
        StorageError::Flash(e) => fail(
            out,
            Status::StorageFailure,
            format_args!("{what} failed: flash error {:?}", e.kind()),
        ),
        StorageError::Layout { what: why, value } => fail(
            out,
            Status::StorageFailure,
            format_args!("{what} failed: {why} (value {value})"),
        ),
    }
}
