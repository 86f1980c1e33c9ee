//! Host → device: commands.
//!
//! Body: `sequence u16 | code u8 | arguments`. The host numbers its
//! commands; the device's reply carries the number back, and a command that
//! arrives again with the number and bytes of the last one handled (the host
//! retrying after a lost reply) gets the same reply again without being
//! applied twice.

// An upload chunk travels inline (no heap on the device): the enum is the
// size of a payload, moved once per command.
#![allow(clippy::large_enum_variant)]

use super::byte_enum::byte_enum;
use super::bytes::{Reader, Writer};
use super::packet::{PacketBuf, PacketType, TooLong};
use super::payload::{Payload, MAX_PAYLOAD};
use crate::protocol::DecodeError;

/// Most calibration bytes one upload or read-back packet carries.
pub const CHUNK_LEN: usize = 128;

byte_enum! {
    /// What the device streams.
    pub enum Mode {
        /// Corrected samples (data frames).
        Calibrated = 0 => "calibrated",
        /// The chip's counts and temperature (raw frames), for calibration.
        Raw = 1 => "raw",
    }
}

/// The command codes (byte 2 of a command body).
pub mod code {
    /// [`super::Command::Identify`].
    pub const IDENTIFY: u8 = 0x01;
    /// [`super::Command::SetMode`].
    pub const SET_MODE: u8 = 0x02;
    /// [`super::Command::SetDecimation`].
    pub const SET_DECIMATION: u8 = 0x03;
    /// [`super::Command::UploadChunk`].
    pub const UPLOAD_CHUNK: u8 = 0x04;
    /// [`super::Command::UploadCommit`].
    pub const UPLOAD_COMMIT: u8 = 0x05;
    /// [`super::Command::ReadCalibration`].
    pub const READ_CALIBRATION: u8 = 0x06;
    /// [`super::Command::Save`].
    pub const SAVE: u8 = 0x07;
    /// [`super::Command::Erase`].
    pub const ERASE: u8 = 0x08;
    /// [`super::Command::ResetCounters`].
    pub const RESET_COUNTERS: u8 = 0x09;
    /// [`super::Command::SelfTest`].
    pub const SELF_TEST: u8 = 0x0A;
}

/// One command, its arguments parsed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// Who the device is and what it is doing (reply: a
    /// [`DeviceInfo`](super::DeviceInfo)).
    Identify,
    /// Stream corrected or raw samples from the next sample on.
    SetMode(Mode),
    /// Average this many samples per streamed frame (≥ 1).
    SetDecimation(u16),
    /// Bytes `offset..offset + data.len()` of a calibration blob being
    /// uploaded; chunks come in order from offset 0, which starts afresh.
    UploadChunk {
        /// Where the bytes go in the blob.
        offset: u16,
        /// At most [`CHUNK_LEN`] bytes.
        data: Payload,
    },
    /// The upload is complete: `len` bytes whose CRC-32C is `crc`. The
    /// device checks them as `triad calib check` does and, if they pass,
    /// applies the calibration between two samples.
    UploadCommit {
        /// Bytes uploaded.
        len: u16,
        /// CRC-32C of those bytes.
        crc: u32,
    },
    /// Up to [`CHUNK_LEN`] bytes of the active calibration's blob from
    /// `offset` (reply: `total length u16 | bytes`).
    ReadCalibration {
        /// First byte wanted.
        offset: u16,
    },
    /// Store the active calibration in flash.
    Save,
    /// Erase the stored calibration (the active one stays until restart).
    Erase,
    /// Zero the device's counters.
    ResetCounters,
    /// Run the chip's accelerometer and gyroscope self-test (sampling
    /// pauses while it runs).
    SelfTest,
}

/// Why a command packet's arguments are not a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommandError {
    /// A code this version does not define.
    Unknown {
        /// The code received.
        code: u8,
    },
    /// The arguments have the wrong length for the command.
    Length {
        /// The code received.
        code: u8,
        /// Bytes the command takes (for an upload chunk: the most).
        expected: usize,
        /// Bytes received.
        got: usize,
    },
    /// An argument's value is not allowed.
    Value {
        /// The code received.
        code: u8,
        /// What is wrong.
        reason: &'static str,
    },
}

impl core::fmt::Display for CommandError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            CommandError::Unknown { code } => write!(f, "unknown command code {code:#04x}"),
            CommandError::Length {
                code,
                expected,
                got,
            } => write!(
                f,
                "command {code:#04x} takes {expected} argument bytes, got {got}"
            ),
            CommandError::Value { code, reason } => {
                write!(f, "command {code:#04x}: {reason}")
            }
        }
    }
}

/// A command as it arrives: its number, its code and its argument bytes,
/// not yet interpreted (so that a bad argument still gets a reply that
/// names the command).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CommandPacket {
    /// The host's number for this command.
    pub sequence: u16,
    /// The command code.
    pub code: u8,
    /// The argument bytes.
    pub args: Payload,
}

impl CommandPacket {
    /// Reads a command body (after the version and type bytes, before the CRC).
    pub fn parse(body: &[u8]) -> Result<CommandPacket, DecodeError> {
        let malformed = DecodeError::Body {
            kind: PacketType::Command as u8,
            len: body.len(),
        };
        let packet = CommandRef::parse(body).ok_or(malformed)?;
        Ok(CommandPacket {
            sequence: packet.sequence,
            code: packet.code,
            args: Payload::new(packet.args).map_err(|_| malformed)?,
        })
    }

    /// The packet where it lies.
    pub fn as_ref(&self) -> CommandRef<'_> {
        CommandRef {
            sequence: self.sequence,
            code: self.code,
            args: self.args.as_slice(),
        }
    }

    /// The command its code and arguments give.
    pub fn command(&self) -> Result<Command, CommandError> {
        self.as_ref().command()
    }
}

/// A command packet read where it lies (a device's receive buffer): the
/// fields of [`CommandPacket`], its arguments not copied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CommandRef<'a> {
    /// The host's number for this command.
    pub sequence: u16,
    /// The command code.
    pub code: u8,
    /// The argument bytes.
    pub args: &'a [u8],
}

impl<'a> CommandRef<'a> {
    /// Reads a command body (after the version and type bytes, before the
    /// CRC); `None` when it is shorter than its sequence number and code.
    pub fn parse(body: &'a [u8]) -> Option<CommandRef<'a>> {
        let (&[s0, s1, code], args) = body.split_first_chunk::<3>()?;
        Some(CommandRef {
            sequence: u16::from_le_bytes([s0, s1]),
            code,
            args,
        })
    }

    /// The command its code and arguments give.
    pub fn command(&self) -> Result<Command, CommandError> {
        let args = self.args;
        let code = self.code;
        let exactly = |expected: usize| {
            if args.len() == expected {
                Ok(Reader::new(args))
            } else {
                Err(CommandError::Length {
                    code,
                    expected,
                    got: args.len(),
                })
            }
        };
        Ok(match code {
            code::IDENTIFY => exactly(0).map(|_| Command::Identify)?,
            code::SET_MODE => {
                let byte = exactly(1)?.u8();
                Command::SetMode(Mode::from_byte(byte).ok_or(CommandError::Value {
                    code,
                    reason: "mode must be 0 (calibrated) or 1 (raw)",
                })?)
            }
            code::SET_DECIMATION => match exactly(2)?.u16() {
                0 => {
                    return Err(CommandError::Value {
                        code,
                        reason: "decimation must be at least 1",
                    })
                }
                n => Command::SetDecimation(n),
            },
            code::UPLOAD_CHUNK => {
                if args.len() < 2 || args.len() > 2 + CHUNK_LEN {
                    return Err(CommandError::Length {
                        code,
                        expected: 2 + CHUNK_LEN,
                        got: args.len(),
                    });
                }
                let mut r = Reader::new(args);
                let offset = r.u16();
                let data = Payload::new(r.rest()).unwrap_or(Payload::EMPTY);
                Command::UploadChunk { offset, data }
            }
            code::UPLOAD_COMMIT => {
                let mut r = exactly(6)?;
                Command::UploadCommit {
                    len: r.u16(),
                    crc: r.u32(),
                }
            }
            code::READ_CALIBRATION => Command::ReadCalibration {
                offset: exactly(2)?.u16(),
            },
            code::SAVE => exactly(0).map(|_| Command::Save)?,
            code::ERASE => exactly(0).map(|_| Command::Erase)?,
            code::RESET_COUNTERS => exactly(0).map(|_| Command::ResetCounters)?,
            code::SELF_TEST => exactly(0).map(|_| Command::SelfTest)?,
            _ => return Err(CommandError::Unknown { code }),
        })
    }
}

impl Command {
    /// Its code on the wire.
    pub const fn code(&self) -> u8 {
        match self {
            Command::Identify => code::IDENTIFY,
            Command::SetMode(_) => code::SET_MODE,
            Command::SetDecimation(_) => code::SET_DECIMATION,
            Command::UploadChunk { .. } => code::UPLOAD_CHUNK,
            Command::UploadCommit { .. } => code::UPLOAD_COMMIT,
            Command::ReadCalibration { .. } => code::READ_CALIBRATION,
            Command::Save => code::SAVE,
            Command::Erase => code::ERASE,
            Command::ResetCounters => code::RESET_COUNTERS,
            Command::SelfTest => code::SELF_TEST,
        }
    }

    /// Its name, as replies and `triad device` name it.
    pub const fn name(&self) -> &'static str {
        name_of(self.code())
    }

    /// The command as it is sent, numbered `sequence`.
    pub fn to_packet(&self, sequence: u16) -> Result<PacketBuf, TooLong> {
        let mut body = [0u8; 3 + MAX_PAYLOAD];
        let mut w = Writer::new(&mut body);
        w.u16(sequence).u8(self.code());
        match self {
            Command::SetMode(mode) => {
                w.u8(*mode as u8);
            }
            Command::SetDecimation(n) => {
                w.u16(*n);
            }
            Command::UploadChunk { offset, data } => {
                w.u16(*offset).bytes(data.as_slice());
            }
            Command::UploadCommit { len, crc } => {
                w.u16(*len).u32(*crc);
            }
            Command::ReadCalibration { offset } => {
                w.u16(*offset);
            }
            Command::Identify
            | Command::Save
            | Command::Erase
            | Command::ResetCounters
            | Command::SelfTest => {}
        }
        if w.overflowed() {
            return Err(TooLong);
        }
        let len = w.len();
        PacketBuf::new(PacketType::Command, &body[..len])
    }
}

/// The name of a command code ("unknown" for a code not defined).
pub const fn name_of(code: u8) -> &'static str {
    match code {
        code::IDENTIFY => "identify",
        code::SET_MODE => "set mode",
        code::SET_DECIMATION => "set decimation",
        code::UPLOAD_CHUNK => "upload chunk",
        code::UPLOAD_COMMIT => "upload commit",
        code::READ_CALIBRATION => "read calibration",
        code::SAVE => "save",
        code::ERASE => "erase",
        code::RESET_COUNTERS => "reset counters",
        code::SELF_TEST => "self-test",
        _ => "unknown",
    }
}
