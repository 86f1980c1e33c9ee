//! Device → host: the one reply every command gets.
//!
//! Body: `sequence u16 | command u8 | status u8 | payload`. The sequence
//! number and command code are the command's, so the host knows which
//! command a reply answers. With status [`Status::Ok`] the payload is the
//! command's result (empty for most); with any other status it is the
//! reason, as UTF-8 text.

use super::byte_enum::byte_enum;
use super::bytes::Reader;
use super::packet::{write_wire, PacketBuf, PacketType, TooLong, MAX_WIRE_LEN};
use super::payload::Payload;
use crate::protocol::DecodeError;

/// Bytes of a reply body before its payload.
pub const REPLY_HEADER_LEN: usize = 4;

byte_enum! {
    /// How a command ended.
    pub enum Status {
        /// Done; the payload is the result.
        Ok = 0 => "ok",
        /// The command packet's CRC did not match (its sequence number, read
        /// from bytes that failed the check, may be wrong), or an uploaded
        /// calibration's CRC did not.
        BadCrc = 1 => "bad CRC",
        /// The packet or the uploaded calibration is of a version the device
        /// does not read.
        WrongVersion = 2 => "wrong version",
        /// The packet type or command code is not one the device knows.
        UnknownCommand = 3 => "unknown command",
        /// The packet is too short, too long or its arguments have the wrong
        /// length for the command.
        Malformed = 4 => "malformed",
        /// The uploaded calibration decodes but is not valid for this chip
        /// (the reason is the one `triad calib check` gives).
        InvalidCalibration = 5 => "invalid calibration",
        /// The flash could not be read, written or erased.
        StorageFailure = 6 => "storage failure",
        /// The device cannot take the command now (another is in progress);
        /// retry later with a new sequence number.
        Busy = 7 => "busy",
        /// An argument is out of range (decimation 0, a chunk out of order, ...).
        BadArgument = 8 => "bad argument",
        /// This device cannot do it (no storage on this board, a chip
        /// without a self-test).
        NotSupported = 9 => "not supported",
        /// The sensor failed during the command (the self-test could not
        /// finish: a bus error, or the chip produced no new sample).
        SensorError = 10 => "sensor error",
    }
}

/// One reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reply {
    /// The sequence number of the command answered.
    pub sequence: u16,
    /// The code of the command answered (as received, even if unknown).
    pub command: u8,
    /// How it ended.
    pub status: Status,
    /// The result, or the reason as text.
    pub payload: Payload,
}

impl Reply {
    /// Reads a reply body (after the version and type bytes, before the CRC).
    pub fn parse(body: &[u8]) -> Result<Reply, DecodeError> {
        let mut r = Reader::new(body);
        let sequence = r.u16();
        let command = r.u8();
        let status_byte = r.u8();
        if r.ran_short() {
            return Err(DecodeError::Body {
                kind: PacketType::Reply as u8,
                len: body.len(),
            });
        }
        let status = Status::from_byte(status_byte).ok_or(DecodeError::Body {
            kind: PacketType::Reply as u8,
            len: body.len(),
        })?;
        let payload = Payload::new(r.rest()).map_err(|_| DecodeError::Body {
            kind: PacketType::Reply as u8,
            len: body.len(),
        })?;
        Ok(Reply {
            sequence,
            command,
            status,
            payload,
        })
    }

    /// The reply as a sealed packet.
    pub fn to_packet(&self) -> Result<PacketBuf, TooLong> {
        PacketBuf::with_body(PacketType::Reply, |body| self.write_body(body))
    }

    /// The reply on the wire (stuffed, delimited) into `out`, written where
    /// it goes ([`write_wire`]): the transmitter's form; its length.
    pub fn to_wire(&self, out: &mut [u8; MAX_WIRE_LEN]) -> Result<usize, TooLong> {
        write_wire(PacketType::Reply, out, |body| self.write_body(body))
    }

    /// The body into `body`; its length, `None` when it does not fit.
    #[inline]
    fn write_body(&self, body: &mut [u8]) -> Option<usize> {
        let payload = self.payload.as_slice();
        let len = REPLY_HEADER_LEN + payload.len();
        let (header, rest) = body.get_mut(..len)?.split_at_mut(REPLY_HEADER_LEN);
        let sequence = self.sequence.to_le_bytes();
        header.copy_from_slice(&[sequence[0], sequence[1], self.command, self.status as u8]);
        rest.copy_from_slice(payload);
        Some(len)
    }

    /// The reason of a failed command, as text.
    pub fn reason(&self) -> &str {
        self.payload.as_text().unwrap_or("(reason not UTF-8)")
    }
}
