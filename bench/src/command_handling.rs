//! What a command costs the firmware's `link` task: the receive decoder
//! over the command's wire bytes ([`Decoder::push_command`]: the command
//! read where it lies), the handler ([`CommandHandler::answer_received`],
//! its reply written where the handler keeps it) and the reply encoded from there to wire bytes where they go
//! ([`triad::protocol::Reply::to_wire`]), as the task runs them
//! (firmware/src/main.rs), over a [`RamFlash`] that counts its operations.
//! Sending the reply (the transmitter) is not counted: it is the link's time.
//!
//! Each repetition starts a device afresh, with two records already stored
//! (so a save reads and checks both slots: its most expensive case), and
//! sends every command of [`BenchCommand::ALL`] in order: identify, set mode,
//! set decimation, an upload of the calibration with temperature terms in
//! 128-byte chunks, its commit (blob decode, `Corrector::new`,
//! `FixedCorrector::new`: the most validation an upload costs), a read-back
//! chunk, save, erase, reset counters, and an identify whose CRC is wrong.

// Replies and commands carry their payloads inline, as in the core.
#![allow(clippy::large_enum_variant)]

use super::digest::Digest;
use super::inputs;
use super::kernels::Meter;
use super::ram_flash::{FlashOps, RamFlash, ERASE_SIZE, UNITS};
use triad::device::{
    ActiveCalibration, Answer, CalibrationStore, CommandHandler, Control, DeviceFacts,
    SharedCounters, StorageError,
};
use triad::model::blob::{self, BLOB_LEN};
use triad::model::Orientation;
use triad::protocol::cobs::stuff;
use triad::protocol::{
    CalibrationSource, Command, Mode, Packet, Payload, StoredState, CHUNK_LEN, MAX_PACKET_LEN,
    MAX_WIRE_LEN,
};
use triad::protocol::{Decoder, DELIMITER};
use triad::protocol::{PacketBuf, Status};

/// Times each device is started afresh and sent every command.
pub const REPETITIONS: usize = 8;

/// The link's baud rate (the NUCLEO's, boards/nucleo-f401re).
pub const LINK_BAUD: u32 = 921_600;

/// Chunks an upload of one blob takes.
pub const UPLOAD_CHUNKS: usize = BLOB_LEN.div_ceil(CHUNK_LEN);

/// One row: a command sent to the handler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchCommand {
    /// Identify (the reply is the device's description and counters).
    Identify,
    /// Set mode (raw).
    SetMode,
    /// Set decimation (4).
    SetDecimation,
    /// One upload chunk of up to 128 bytes (each of the blob's five is timed).
    UploadChunk,
    /// The upload's commit: CRC, blob decode, `Corrector::new`,
    /// `FixedCorrector::new`, the calibration queued for the sampling task.
    UploadCommit,
    /// Read back one 128-byte chunk of the active calibration.
    ReadCalibration,
    /// Save to flash (both slots holding a record).
    Save,
    /// Erase the flash's records.
    Erase,
    /// Reset the counters.
    ResetCounters,
    /// An identify whose CRC is wrong (rejected with a bad-CRC reply).
    BadCrc,
}

/// Rows.
pub const COMMANDS: usize = 10;

impl BenchCommand {
    /// Every row, in the order a device is sent them.
    pub const ALL: [BenchCommand; COMMANDS] = [
        BenchCommand::Identify,
        BenchCommand::SetMode,
        BenchCommand::SetDecimation,
        BenchCommand::UploadChunk,
        BenchCommand::UploadCommit,
        BenchCommand::ReadCalibration,
        BenchCommand::Save,
        BenchCommand::Erase,
        BenchCommand::ResetCounters,
        BenchCommand::BadCrc,
    ];

    /// The row's name in reports and in the firmware's output.
    pub fn name(self) -> &'static str {
        match self {
            BenchCommand::Identify => "identify",
            BenchCommand::SetMode => "set_mode",
            BenchCommand::SetDecimation => "set_decimation",
            BenchCommand::UploadChunk => "upload_chunk",
            BenchCommand::UploadCommit => "upload_commit",
            BenchCommand::ReadCalibration => "read_calibration",
            BenchCommand::Save => "save",
            BenchCommand::Erase => "erase",
            BenchCommand::ResetCounters => "reset_counters",
            BenchCommand::BadCrc => "bad_crc",
        }
    }

    /// The row named `name`.
    pub fn from_name(name: &str) -> Option<BenchCommand> {
        BenchCommand::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The reply status every run of this row must get.
    pub fn expected_status(self) -> Status {
        match self {
            BenchCommand::BadCrc => Status::BadCrc,
            _ => Status::Ok,
        }
    }

    /// Packets this row sends per repetition (each timed on its own).
    pub fn packets(self) -> usize {
        match self {
            BenchCommand::UploadChunk => UPLOAD_CHUNKS,
            _ => 1,
        }
    }

    /// The command this row sends as its `part`-th packet, of `upload`.
    fn command(self, part: usize, upload: &[u8; BLOB_LEN]) -> Command {
        match self {
            BenchCommand::Identify | BenchCommand::BadCrc => Command::Identify,
            BenchCommand::SetMode => Command::SetMode(Mode::Raw),
            BenchCommand::SetDecimation => Command::SetDecimation(4),
            BenchCommand::UploadChunk => {
                let start = part * CHUNK_LEN;
                let end = (start + CHUNK_LEN).min(BLOB_LEN);
                Command::UploadChunk {
                    offset: start as u16,
                    data: Payload::new(&upload[start..end]).unwrap_or(Payload::EMPTY),
                }
            }
            BenchCommand::UploadCommit => Command::UploadCommit {
                len: BLOB_LEN as u16,
                crc: triad::protocol::crc32c(upload),
            },
            BenchCommand::ReadCalibration => Command::ReadCalibration { offset: 0 },
            BenchCommand::Save => Command::Save,
            BenchCommand::Erase => Command::Erase,
            BenchCommand::ResetCounters => Command::ResetCounters,
        }
    }
}

/// Why the benchmark could not set a device up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetupError {
    /// The store refused the RAM flash or could not save to it.
    Storage(StorageError<super::ram_flash::RamFlashError>),
    /// A command did not fit a packet.
    TooLong,
    /// The command numbered this was not answered with status ok.
    Refused(u16),
}

/// What every run of one row gave, summed over the runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CommandStats {
    /// Timed packets.
    pub runs: u32,
    /// Digest of every reply's wire bytes, in order.
    pub digest: Digest,
    /// Runs whose reply did not decode as a reply to the command's sequence
    /// number and code with the row's expected status.
    pub wrong_replies: u32,
    /// The flash's operations.
    pub flash: FlashOps,
    /// Wire bytes of the commands.
    pub command_bytes: u32,
    /// Wire bytes of the replies.
    pub reply_bytes: u32,
}

/// The names of [`CommandStats::counts`], as the firmware prints them.
pub const COUNT_KEYS: [&str; 7] = [
    "erases",
    "writes",
    "written",
    "reads",
    "read",
    "command_bytes",
    "reply_bytes",
];

impl CommandStats {
    /// The flash's operations and the wire bytes, in [`COUNT_KEYS`]' order.
    pub fn counts(&self) -> [u32; 7] {
        [
            self.flash.erases,
            self.flash.writes,
            self.flash.bytes_written,
            self.flash.reads,
            self.flash.bytes_read,
            self.command_bytes,
            self.reply_bytes,
        ]
    }
}

/// The link task's state: its receive decoder, the handler over a store in
/// RAM flash, the counters identify reads, and the slot of the control
/// queue (the firmware's holds Controls for the data-ready task).
pub struct Link {
    decoder: Decoder,
    handler: CommandHandler<RamFlash>,
    counters: SharedCounters,
    control: Option<Control>,
}

/// The device's facts: the NUCLEO's, with the ICM-42688-P of the benchmark.
fn facts() -> DeviceFacts {
    DeviceFacts {
        firmware: "0.1.0",
        board: "nucleo-f401re",
        chip: "icm42688",
        bus: "spi",
        sample_rate_hz: 1000.0,
        baud: LINK_BAUD,
        scale: inputs::scale(),
        orientation: Orientation::RotationNone,
        cycles_hz: 84_000_000,
    }
}

impl Link {
    /// A device started with the realistic calibration built in, whose
    /// flash holds `records` saved records of it (0, 1 or 2 slots used).
    /// Out of line: its temporaries live in its own stack frame.
    #[inline(never)]
    pub fn new(records: u32) -> Result<Link, SetupError> {
        let built_in = blob::encode(&inputs::realistic());
        let mut store = CalibrationStore::new(RamFlash::new(), 0, ERASE_SIZE as u32)
            .map_err(SetupError::Storage)?;
        for _ in 0..records {
            store.save(&built_in).map_err(SetupError::Storage)?;
        }
        let stored = if records > 0 {
            StoredState::Valid
        } else {
            StoredState::Empty
        };
        let active = ActiveCalibration {
            blob: Some(built_in),
            id: inputs::realistic().id,
            source: CalibrationSource::BuiltIn,
        };
        let mut decoder = Decoder::new();
        // A delimiter first, as the line's idle start: the decoder is in step.
        decoder.push(DELIMITER);
        Ok(Link {
            decoder,
            handler: CommandHandler::new(facts(), active, 1, Some(store), stored),
            counters: SharedCounters::new(),
            control: None,
        })
    }

    /// The flash's operations so far.
    pub fn flash_ops(&mut self) -> FlashOps {
        self.flash().map_or(FlashOps::default(), |f| f.ops())
    }

    /// Erases of each flash unit so far.
    pub fn unit_erases(&mut self) -> [u32; UNITS] {
        self.flash().map_or([0; UNITS], |f| f.unit_erases())
    }

    fn flash(&mut self) -> Option<&mut RamFlash> {
        self.handler.store_mut().map(|s| s.flash_mut())
    }
}

/// A packet on the wire.
struct Wire {
    bytes: [u8; MAX_WIRE_LEN],
    len: usize,
}

impl Wire {
    /// What `row` sends as its `part`-th packet (of `upload`), numbered
    /// `sequence` (its CRC broken for the bad-CRC row): the command's code
    /// and its wire bytes.
    #[inline(never)]
    fn for_row(
        row: BenchCommand,
        part: usize,
        upload: &[u8; BLOB_LEN],
        sequence: u16,
    ) -> Result<(u8, Wire), SetupError> {
        let command = row.command(part, upload);
        let packet = command
            .to_packet(sequence)
            .map_err(|_| SetupError::TooLong)?;
        let wire = if row == BenchCommand::BadCrc {
            Wire::with_bad_crc(&packet)
        } else {
            Wire::of(&packet)
        };
        Ok((command.code(), wire))
    }

    fn of(packet: &PacketBuf) -> Wire {
        let mut bytes = [0u8; MAX_WIRE_LEN];
        let len = packet.to_wire(&mut bytes);
        Wire { bytes, len }
    }

    /// `packet` with its last CRC byte changed, stuffed and delimited.
    fn with_bad_crc(packet: &PacketBuf) -> Wire {
        let mut raw = [0u8; MAX_PACKET_LEN];
        let n = packet.as_bytes().len();
        raw[..n].copy_from_slice(packet.as_bytes());
        raw[n - 1] ^= 0x5A;
        let mut bytes = [0u8; MAX_WIRE_LEN];
        // MAX_WIRE_LEN holds any packet stuffed, and its delimiter.
        let len = stuff(&raw[..n], &mut bytes).unwrap_or(0);
        bytes[len] = DELIMITER;
        Wire {
            bytes,
            len: len + 1,
        }
    }

    fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// The link task's work for one command's wire bytes: each byte through the
/// decoder, the packet through the handler, its reply encoded to `reply`;
/// returns the reply's length on the wire (0: nothing to send).
#[inline(never)]
pub fn handle_command(link: &mut Link, wire: &[u8], reply: &mut [u8; MAX_WIRE_LEN]) -> usize {
    let mut len = 0;
    for &byte in wire {
        let Some(completed) = link.decoder.push_command(byte) else {
            continue;
        };
        let control = &mut link.control;
        let answer = link
            .handler
            .answer_received(&completed, &link.counters, &mut |c| {
                *control = Some(c);
                true
            });
        if let Answer::Reply(r) = answer {
            len = r.to_wire(reply).unwrap_or(0);
        }
    }
    len
}

/// True when `reply` decodes as a reply to `sequence`'s command `code`
/// with `status`.
fn reply_is(reply: &[u8], sequence: u16, code: u8, status: Status) -> bool {
    let mut decoder = Decoder::new();
    decoder.push(DELIMITER);
    let mut decoded = None;
    for &b in reply {
        decoded = decoder.push(b).or(decoded);
    }
    matches!(decoded, Some(Ok(Packet::Reply(r)))
        if r.sequence == sequence && r.command == code && r.status == status)
}

/// Runs every row [`REPETITIONS`] times, each packet timed by its row's
/// meter (`meters[i]` for `BenchCommand::ALL[i]`), adding to `stats[i]`
/// (in the caller's frame, as the meters: the Cortex-M0 core's RAM is short).
#[inline(never)]
pub fn run_commands<M: Meter>(
    meters: &mut [M; COMMANDS],
    stats: &mut [CommandStats; COMMANDS],
) -> Result<(), SetupError> {
    let upload = upload_blob();
    for _ in 0..REPETITIONS {
        repetition(&upload, meters, stats)?;
    }
    Ok(())
}

/// The blob the rows upload. Out of line, so that its calibration is off
/// the stack while the rows run (the Cortex-M0's 16 KiB).
#[inline(never)]
fn upload_blob() -> [u8; BLOB_LEN] {
    blob::encode(&inputs::with_temperature_terms())
}

/// One device started afresh and sent every row's packets. Out of line and
/// with the device matched in place (not moved out of its `Result`), so that
/// the Cortex-M0 core's 16 KiB hold one copy of it.
#[inline(never)]
fn repetition<M: Meter>(
    upload: &[u8; BLOB_LEN],
    meters: &mut [M; COMMANDS],
    stats: &mut [CommandStats; COMMANDS],
) -> Result<(), SetupError> {
    let mut started = Link::new(2);
    let link = match &mut started {
        Ok(link) => link,
        Err(e) => return Err(*e),
    };
    let mut reply = [0u8; MAX_WIRE_LEN];
    let mut sequence = 0u16;
    for (i, row) in BenchCommand::ALL.into_iter().enumerate() {
        for part in 0..row.packets() {
            sequence += 1;
            let (code, wire) = Wire::for_row(row, part, upload, sequence)?;
            let before = link.flash_ops();
            meters[i].start();
            let n = handle_command(link, wire.as_slice(), &mut reply);
            meters[i].stop();
            let s = &mut stats[i];
            s.runs += 1;
            reply[..n].iter().for_each(|&b| s.digest.word(u32::from(b)));
            let ok = reply_is(&reply[..n], sequence, code, row.expected_status());
            s.wrong_replies += u32::from(!ok);
            let ops = link.flash_ops().since(&before);
            s.flash = s.flash.plus(&ops);
            s.command_bytes += wire.len as u32;
            s.reply_bytes += n as u32;
        }
    }
    Ok(())
}

/// Erases of each flash unit after `saves` save commands on a device
/// started with an empty store: what wears the sectors.
pub fn save_wear(saves: u16) -> Result<[u32; UNITS], SetupError> {
    let mut link = Link::new(0)?;
    let mut reply = [0u8; MAX_WIRE_LEN];
    let no_upload = [0u8; BLOB_LEN];
    for sequence in 1..=saves {
        let (_, wire) = Wire::for_row(BenchCommand::Save, 0, &no_upload, sequence)?;
        let n = handle_command(&mut link, wire.as_slice(), &mut reply);
        if !reply_is(&reply[..n], sequence, Command::Save.code(), Status::Ok) {
            return Err(SetupError::Refused(sequence));
        }
    }
    Ok(link.unit_erases())
}
