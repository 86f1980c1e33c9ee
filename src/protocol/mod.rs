//! The wire protocol, version 2, in one place: what the device streams
//! (corrected-sample frames, batch frames, raw frames), what it answers
//! (replies) and what the host sends it (commands), and how each travels.
//! docs/PROTOCOL.md specifies every byte; this module is its code.
//!
//! Layers, bottom up:
//! - [`mod@crc32c`]: the one CRC of the project (it also closes the calibration
//!   and scene blobs).
//! - [`cobs`] and [`encoder`]: byte stuffing so a frame holds no 0x00, and a
//!   0x00 delimiter after it.
//! - [`frame`], [`flags`], [`timestamp`]: the streamed sample (version 1's
//!   data frame) and its sequence numbers, flags and time.
//! - [`packet`], [`payload`], [`bytes`]: every other packet is framed as the
//!   data frame is (COBS, delimiter, CRC-32C in its last four bytes, the
//!   version in its first); [`Packet::parse`] reads any of them.
//! - [`command`], [`reply`], [`device_info`], [`self_test`], [`batch_frame`],
//!   [`raw_frame`]: the packet types' contents.
//! - [`decoder`]: finds frames and packets again in a byte stream, from any
//!   starting point and after any corruption, and counts what it lost
//!   ([`DecoderStats`]).
//!
//! The device side (the command handler) is [`crate::device::commands`].

pub mod batch_frame;
mod byte_enum;
pub mod bytes;
pub mod cobs;
pub mod command;
pub mod crc32c;
pub mod decoder;
pub mod device_info;
pub mod encoder;
pub mod error;
pub mod flags;
pub mod frame;
pub mod packet;
pub mod payload;
pub mod raw_frame;
pub mod reply;
pub mod self_test;
pub mod timestamp;

pub use batch_frame::{BatchFrame, MAX_BATCH};
pub use command::{Command, CommandError, CommandPacket, CommandRef, Mode, CHUNK_LEN};
pub use crc32c::{crc32c, CRC32C_CHECK};
pub use decoder::{Completed, Decoder, DecoderStats, Feed, Received};
pub use device_info::{
    CalibrationSource, Counters, DeviceInfo, Load, StoredReason, StoredState, Text,
};
pub use encoder::{encode, max_frame_rate, DELIMITER, MAX_ENCODED_LEN};
pub use error::DecodeError;
pub use flags::Flags;
pub use frame::{Frame, CHECKED_LEN, FRAME_LEN, VERSION};
pub use packet::{Packet, PacketBuf, PacketRef, PacketType, MAX_PACKET_LEN, MAX_WIRE_LEN};
pub use payload::{Payload, MAX_PAYLOAD, MAX_REPLY_PAYLOAD};
pub use raw_frame::{RawFrame, RawScale};
pub use reply::{Reply, Status};
pub use self_test::{AxisResult, SelfTestResult};
pub use timestamp::TimestampUnwrapper;
