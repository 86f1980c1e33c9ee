//! The variable part of a command or reply, held inline (no allocation).

use super::packet::MAX_PACKET_LEN;

/// Longest payload: a command's arguments in a packet of
/// [`MAX_PACKET_LEN`] bytes, after the version and type (2 bytes), the
/// sequence number and command code (3) and the CRC (4). PROTOCOL.md §12
/// promises packets of up to 240 bytes; every one of them is read.
pub const MAX_PAYLOAD: usize = MAX_PACKET_LEN - 9;

/// Longest payload of a reply: one byte less than [`MAX_PAYLOAD`], for the
/// reply's status byte.
pub const MAX_REPLY_PAYLOAD: usize = MAX_PAYLOAD - 1;

/// Up to [`MAX_PAYLOAD`] bytes. Word-aligned: the payload and the
/// commands and replies holding it are copied by words (4 bytes an
/// instruction pair) where a byte-aligned one is copied a byte at a time,
/// about four times the instructions on the Cortex-M4F (1 000 per copy).
#[derive(Clone, Copy, PartialEq, Eq)]
#[repr(align(4))]
pub struct Payload {
    bytes: [u8; MAX_PAYLOAD],
    len: u8,
}

impl Default for Payload {
    fn default() -> Self {
        Payload::EMPTY
    }
}

impl core::fmt::Debug for Payload {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Payload({:02x?})", self.as_slice())
    }
}

/// `bytes` is longer than [`MAX_PAYLOAD`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PayloadTooLong {
    /// The length offered.
    pub len: usize,
}

impl Payload {
    /// No bytes.
    pub const EMPTY: Payload = Payload {
        bytes: [0; MAX_PAYLOAD],
        len: 0,
    };

    /// A copy of `bytes`.
    pub fn new(bytes: &[u8]) -> Result<Payload, PayloadTooLong> {
        let mut p = Payload::EMPTY;
        let slot = p
            .bytes
            .get_mut(..bytes.len())
            .ok_or(PayloadTooLong { len: bytes.len() })?;
        slot.copy_from_slice(bytes);
        p.len = bytes.len() as u8;
        Ok(p)
    }

    /// A copy of `bytes`, cut at [`MAX_REPLY_PAYLOAD`] (for reasons, which
    /// are text: a cut reason is still a reason).
    pub fn truncated(bytes: &[u8]) -> Payload {
        let n = bytes.len().min(MAX_REPLY_PAYLOAD);
        Payload::new(&bytes[..n]).unwrap_or(Payload::EMPTY)
    }

    /// A buffer the caller fills; see [`Payload::set_len`].
    pub fn buffer(&mut self) -> &mut [u8; MAX_PAYLOAD] {
        &mut self.bytes
    }

    /// Keeps the first `len` bytes of the buffer (at most [`MAX_PAYLOAD`]).
    pub fn set_len(&mut self, len: usize) {
        self.len = len.min(MAX_PAYLOAD) as u8;
    }

    /// The bytes.
    pub fn as_slice(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len)]
    }

    /// The bytes as text, when they are UTF-8 (error reasons are).
    pub fn as_text(&self) -> Option<&str> {
        core::str::from_utf8(self.as_slice()).ok()
    }
}

/// Formats into a payload without allocating (a reply's reason); text past
/// [`MAX_REPLY_PAYLOAD`] bytes is dropped at a character boundary.
impl core::fmt::Write for Payload {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let at = usize::from(self.len);
        let room = MAX_REPLY_PAYLOAD.saturating_sub(at);
        let mut n = s.len().min(room);
        while !s.is_char_boundary(n) {
            n -= 1;
        }
        self.bytes[at..at + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len = (at + n) as u8;
        Ok(())
    }
}
