//! Protocol version 2's packets: every unstuffed frame on the link, whatever
//! it carries, and its checks.
//!
//! A version-2 packet is `2 | type | body | CRC-32C`, COBS-stuffed and ended
//! by 0x00 like a version-1 frame (docs/PROTOCOL.md, "Version 2"). The
//! version-1 data frame is itself a packet of protocol 2, unchanged: a device
//! speaking version 2 streams corrected samples exactly as before, so a
//! version-1 decoder still reads them (and rejects the new types).

use super::batch_frame::BatchFrame;
use super::byte_enum::byte_enum;
use super::command::CommandPacket;
use super::raw_frame::RawFrame;
use super::reply::Reply;
use crate::protocol::cobs::{max_stuffed_len, stuff_block, InPlaceStuffer};
use crate::protocol::crc32c::{crc32c, crc32c_byte, crc32c_word};
use crate::protocol::{DecodeError, Frame, DELIMITER, FRAME_LEN};

/// Byte 0 of every packet this version adds.
pub const VERSION: u8 = 2;

/// Longest packet before stuffing, CRC included. Long enough for a
/// 128-byte calibration chunk with its header; a decoder stops storing
/// bytes past it and rejects the packet as too long.
pub const MAX_PACKET_LEN: usize = 240;

/// Longest packet on the wire: stuffed, with its delimiter.
pub const MAX_WIRE_LEN: usize = max_stuffed_len(MAX_PACKET_LEN) + 1;

/// Version byte, type byte.
pub const HEADER_LEN: usize = 2;

/// The CRC-32C closing every packet.
pub const CRC_LEN: usize = 4;

/// Shortest packet: header and CRC with an empty body.
pub const MIN_PACKET_LEN: usize = HEADER_LEN + CRC_LEN;

byte_enum! {
    /// Byte 1 of a version-2 packet: what the body is.
    pub enum PacketType {
        /// Device → host: one sample in the chip's counts, with its scale.
        Raw = 0x02 => "raw frame",
        /// Device → host: the answer to one command.
        Reply = 0x03 => "reply",
        /// Device → host: W corrected samples in fixed point.
        Batch = 0x04 => "batch frame",
        /// Host → device: one command.
        Command = 0x10 => "command",
    }
}

/// One decoded packet.
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    /// A corrected sample: the version-1 data frame.
    Data(Frame),
    /// A raw sample (raw mode).
    Raw(RawFrame),
    /// A reply to a command.
    Reply(Reply),
    /// W corrected samples.
    Batch(BatchFrame),
    /// A command (what the device decodes).
    Command(CommandPacket),
}

impl Packet {
    /// Reads a packet from its unstuffed bytes: the CRC first (nothing else
    /// can be trusted before it), then the version, then the type and body.
    pub fn parse(bytes: &[u8]) -> Result<Packet, DecodeError> {
        PacketRef::check(bytes)?.parse()
    }
}

/// A packet whose length, CRC, version and type are checked, its body not
/// read yet: where it lies in the receive buffer (a device reads a command
/// from there, [`crate::protocol::CommandRef`], without copying it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PacketRef<'a> {
    /// A version-1 data frame.
    Data(&'a [u8; FRAME_LEN]),
    /// A version-2 packet of `kind`, its body between the type and the CRC.
    V2 {
        /// The packet's type.
        kind: PacketType,
        /// Its body.
        body: &'a [u8],
    },
}

impl<'a> PacketRef<'a> {
    /// Checks a packet's unstuffed bytes, as [`Packet::parse`] does before
    /// it reads the body: the CRC first, then the version, then the type.
    pub fn check(bytes: &'a [u8]) -> Result<PacketRef<'a>, DecodeError> {
        if !plausible_length(bytes) {
            return Err(DecodeError::Length { len: bytes.len() });
        }
        let body = checked_body(bytes)?;
        match bytes.first() {
            Some(1) => match <&[u8; FRAME_LEN]>::try_from(bytes) {
                Ok(frame) => Ok(PacketRef::Data(frame)),
                Err(_) => Err(DecodeError::Length { len: bytes.len() }),
            },
            Some(&VERSION) => {
                let (kind, body) = body
                    .split_first()
                    .ok_or(DecodeError::Length { len: bytes.len() })?;
                match PacketType::from_byte(*kind) {
                    Some(kind) => Ok(PacketRef::V2 { kind, body }),
                    None => Err(DecodeError::Type { kind: *kind }),
                }
            }
            Some(&version) => Err(DecodeError::Version { version }),
            None => Err(DecodeError::Length { len: 0 }),
        }
    }

    /// Reads the body.
    pub fn parse(self) -> Result<Packet, DecodeError> {
        match self {
            PacketRef::Data(frame) => Frame::from_bytes(frame).map(Packet::Data),
            PacketRef::V2 { kind, body } => match kind {
                PacketType::Raw => RawFrame::parse(body).map(Packet::Raw),
                PacketType::Reply => Reply::parse(body).map(Packet::Reply),
                PacketType::Batch => BatchFrame::parse(body).map(Packet::Batch),
                PacketType::Command => CommandPacket::parse(body).map(Packet::Command),
            },
        }
    }
}

/// False when the length cannot be that of the packet bytes 0 and 1 name (a
/// version-1 frame is 51 bytes, a raw frame 64, a reply or command at
/// least its header). Bytes that name no packet this decoder knows are
/// plausible at version 1's length (as version 1 decoded them: CRC, then
/// version) or with a good CRC (a later version's packet). So damage that
/// cuts or merges frames is counted as malformed, as in version 1, rather
/// than as a CRC error. The bytes are not trusted yet, but they only choose
/// how a rejection is counted: nothing is accepted without its CRC.
fn plausible_length(bytes: &[u8]) -> bool {
    let len = bytes.len();
    let kind = bytes.get(1).copied().and_then(PacketType::from_byte);
    match (bytes.first(), kind) {
        (Some(1), _) => len == FRAME_LEN,
        (Some(&VERSION), Some(PacketType::Raw)) => {
            len == HEADER_LEN + super::raw_frame::RAW_BODY_LEN + CRC_LEN
        }
        (Some(&VERSION), Some(PacketType::Reply)) => {
            len >= HEADER_LEN + super::reply::REPLY_HEADER_LEN + CRC_LEN
        }
        (Some(&VERSION), Some(PacketType::Command)) => len >= HEADER_LEN + 3 + CRC_LEN,
        (Some(&VERSION), Some(PacketType::Batch)) => {
            len >= HEADER_LEN + super::batch_frame::BATCH_HEADER_LEN + CRC_LEN
        }
        _ => len == FRAME_LEN || checked_body(bytes).is_ok(),
    }
}

/// The bytes between the version byte and the CRC, once the length and the
/// CRC are good.
fn checked_body(bytes: &[u8]) -> Result<&[u8], DecodeError> {
    if bytes.len() < 1 + CRC_LEN || bytes.len() > MAX_PACKET_LEN {
        return Err(DecodeError::Length { len: bytes.len() });
    }
    let (checked, crc) = bytes.split_at(bytes.len() - CRC_LEN);
    let received = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
    let computed = crc32c(checked);
    if received != computed {
        return Err(DecodeError::Crc { received, computed });
    }
    Ok(&checked[1..])
}

/// A packet being built: header, body, and the CRC that [`PacketBuf::new`] adds.
#[derive(Clone, Debug)]
pub struct PacketBuf {
    bytes: [u8; MAX_PACKET_LEN],
    len: usize,
}

/// A body longer than [`MAX_PACKET_LEN`] allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TooLong;

/// Writes the packet of `kind` whose body `write` puts in place straight
/// in its wire form into `out` (stuffed, delimited), and returns the wire
/// length: the packet is built at `out[1..]`, where stuffing leaves its
/// non-zero bytes ([`InPlaceStuffer`]), so no byte is copied after `write`
/// wrote it, and one pass over the bytes computes the CRC and finds the
/// zeros. `write` gets the room for the longest body and returns the
/// length it wrote (`None`: it did not fit). The same bytes as
/// [`PacketBuf::with_body`] then [`PacketBuf::to_wire`]: the transmitter's
/// form, where a packet built apart costs its zeroing and two copies.
#[inline]
pub fn write_wire(
    kind: PacketType,
    out: &mut [u8; MAX_WIRE_LEN],
    write: impl FnOnce(&mut [u8]) -> Option<usize>,
) -> Result<usize, TooLong> {
    const _: () = assert!(MAX_WIRE_LEN == MAX_PACKET_LEN + 2);
    const _: () = assert!(MAX_PACKET_LEN <= crate::protocol::cobs::MAX_BLOCK);
    let (header, body) = out[1..].split_at_mut(HEADER_LEN);
    header.copy_from_slice(&[VERSION, kind as u8]);
    let body_len = write(&mut body[..MAX_PACKET_LEN - HEADER_LEN - CRC_LEN]).ok_or(TooLong)?;
    let len = HEADER_LEN + body_len + CRC_LEN;
    if len > MAX_PACKET_LEN {
        return Err(TooLong);
    }
    // The packet is out[1..=len]; its CRC covers all but its last four bytes.
    let crc_end = len - CRC_LEN + 1;
    let mut crc = !0;
    let mut stuffer = InPlaceStuffer::new();
    let mut at = 1;
    // `at + 4 <= crc_end < MAX_WIRE_LEN`: the word is inside `out`.
    while at + 4 <= crc_end {
        let Some(&[b0, b1, b2, b3]) = out.get(at..at + 4) else {
            break;
        };
        let word = u32::from_le_bytes([b0, b1, b2, b3]);
        crc = crc32c_word(crc, word);
        stuffer.word(out, at, word);
        at += 4;
    }
    while let Some(&byte) = out.get(at).filter(|_| at < crc_end) {
        crc = crc32c_byte(crc, byte);
        stuffer.byte(out, at);
        at += 1;
    }
    let crc = (!crc).to_le_bytes();
    out[crc_end..crc_end + CRC_LEN].copy_from_slice(&crc);
    stuffer.word(out, crc_end, u32::from_le_bytes(crc));
    stuffer.finish(out, len + 1);
    Ok(len + 2)
}

impl PacketBuf {
    /// The packet of `kind` with `body`, sealed with its CRC.
    pub fn new(kind: PacketType, body: &[u8]) -> Result<PacketBuf, TooLong> {
        Self::with_body(kind, |room| {
            let slot = room.get_mut(..body.len())?;
            slot.copy_from_slice(body);
            Some(body.len())
        })
    }

    /// A sealed packet whose body `write` puts in place: it gets the room
    /// for the longest body and returns the length it wrote (`None`: it did
    /// not fit). No copy of the body: the encoders of long packets use it.
    #[inline]
    pub fn with_body(
        kind: PacketType,
        write: impl FnOnce(&mut [u8]) -> Option<usize>,
    ) -> Result<PacketBuf, TooLong> {
        let mut bytes = [0u8; MAX_PACKET_LEN];
        bytes[0] = VERSION;
        bytes[1] = kind as u8;
        let body_len = write(&mut bytes[HEADER_LEN..MAX_PACKET_LEN - CRC_LEN]).ok_or(TooLong)?;
        let len = HEADER_LEN + body_len + CRC_LEN;
        if len > MAX_PACKET_LEN {
            return Err(TooLong);
        }
        let crc_at = len - CRC_LEN;
        let crc = crc32c(&bytes[..crc_at]);
        bytes[crc_at..len].copy_from_slice(&crc.to_le_bytes());
        Ok(PacketBuf { bytes, len })
    }

    /// The packet's bytes before stuffing, CRC included.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len]
    }

    /// The packet on the wire (stuffed, then the delimiter) into `out`;
    /// returns the number of bytes.
    pub fn to_wire(&self, out: &mut [u8; MAX_WIRE_LEN]) -> usize {
        let (stuffed, _) = out.split_at_mut(MAX_WIRE_LEN - 1);
        // The packet is never longer than MAX_PACKET_LEN, which the buffer
        // is sized for, so stuffing cannot fail.
        let n = stuff_block(self.as_bytes(), stuffed).unwrap_or(0);
        out[n] = DELIMITER;
        n + 1
    }
}
