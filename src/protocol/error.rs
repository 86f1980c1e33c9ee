//! Why a frame was rejected.

use core::fmt;

/// Why the bytes between two delimiters are not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The byte stuffing is broken: the last block's code byte promised more
    /// bytes than arrived before the delimiter (bytes were lost).
    Stuffing,
    /// The unstuffed frame is `len` bytes long; version 1 frames are exactly
    /// [`FRAME_LEN`](super::FRAME_LEN) bytes (`len` saturates at
    /// `usize::MAX`).
    Length {
        /// Unstuffed length received.
        len: usize,
    },
    /// The CRC-32C in the frame does not match the one computed over it.
    Crc {
        /// CRC carried by the frame.
        received: u32,
        /// CRC computed over the frame's other bytes.
        computed: u32,
    },
    /// The CRC is good but the version byte names a format this decoder does
    /// not know.
    Version {
        /// Version byte received.
        version: u8,
    },
    /// The CRC and version are good but the packet type (byte 1 of a
    /// version-2 packet) is not one this decoder knows.
    Type {
        /// Type byte received.
        kind: u8,
    },
    /// The CRC, version and type are good but the body's length does not
    /// fit the type (or a field holds an undefined code).
    Body {
        /// Type byte received.
        kind: u8,
        /// Body length received.
        len: usize,
    },
}

impl DecodeError {
    /// True for a checksum failure; every other error is a malformed frame.
    pub const fn is_crc(&self) -> bool {
        matches!(self, DecodeError::Crc { .. })
    }
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            DecodeError::Stuffing => write!(f, "frame ends inside a COBS block (bytes lost)"),
            DecodeError::Length { len } => write!(
                f,
                "frame is {len} bytes after unstuffing: a version-1 data frame is {} bytes, \
                 a version-2 packet {} to {}",
                super::FRAME_LEN,
                crate::protocol::packet::MIN_PACKET_LEN,
                crate::protocol::MAX_PACKET_LEN
            ),
            DecodeError::Crc { received, computed } => write!(
                f,
                "CRC mismatch: frame carries {received:#010x}, bytes give {computed:#010x}"
            ),
            DecodeError::Version { version } => write!(
                f,
                "unsupported frame version {version} (this decoder reads versions 1 and 2)"
            ),
            DecodeError::Type { kind } => {
                write!(f, "unknown version-2 packet type {kind:#04x}")
            }
            DecodeError::Body { kind, len } => write!(
                f,
                "version-2 packet of type {kind:#04x} has a {len}-byte body that does not fit its type"
            ),
        }
    }
}
