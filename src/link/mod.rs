//! The two-way link of protocol version 2: what the device sends besides
//! corrected samples (raw frames, replies) and what the host sends it
//! (commands). docs/PROTOCOL.md specifies every byte.
//!
//! Every packet is framed as version 1's data frame is (COBS, a 0x00
//! delimiter, a CRC-32C in its last four bytes, the version in its first):
//! [`Packet::parse`] reads any of them, and the stream's
//! [`Decoder`](crate::stream::Decoder) finds them in a byte stream. The
//! device side (the command handler) is [`crate::device::commands`].

pub mod batch_frame;
mod byte_enum;
pub mod bytes;
pub mod command;
pub mod device_info;
pub mod packet;
pub mod payload;
pub mod raw_frame;
pub mod reply;
pub mod self_test;

pub use batch_frame::{BatchFrame, MAX_BATCH};
pub use command::{Command, CommandError, CommandPacket, Mode, CHUNK_LEN};
pub use device_info::{
    CalibrationSource, Counters, DeviceInfo, Load, StoredReason, StoredState, Text,
};
pub use packet::{Packet, PacketBuf, PacketType, MAX_PACKET_LEN, MAX_WIRE_LEN};
pub use payload::{Payload, MAX_PAYLOAD, MAX_REPLY_PAYLOAD};
pub use raw_frame::{RawFrame, RawScale};
pub use reply::{Reply, Status};
pub use self_test::{AxisResult, SelfTestResult};
