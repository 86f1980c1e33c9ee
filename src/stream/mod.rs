//! The wire format: frames, CRC, framing, sequence numbers, flags.
//!
//! Each streamed sample is one [`Frame`]: serialised little-endian
//! ([`frame`]), closed by a CRC-32C ([`crate::crc32c`]), byte-stuffed with COBS so it
//! holds no 0x00 ([`cobs`]) and ended by a 0x00 delimiter ([`encode`]). A
//! [`Decoder`] finds frames again at the delimiters, from any starting point
//! and after any corruption, and counts what it lost ([`DecoderStats`]).
//! docs/PROTOCOL.md specifies the format byte by byte.

pub mod cobs;
pub mod decoder;
pub mod encoder;
pub mod error;
pub mod flags;
pub mod frame;
pub mod timestamp;

pub use crate::crc32c::{crc32c, CRC32C_CHECK};
pub use decoder::{Decoder, DecoderStats, Feed};
pub use encoder::{encode, max_frame_rate, DELIMITER, MAX_ENCODED_LEN};
pub use error::DecodeError;
pub use flags::Flags;
pub use frame::{Frame, CHECKED_LEN, FRAME_LEN, VERSION};
pub use timestamp::TimestampUnwrapper;
