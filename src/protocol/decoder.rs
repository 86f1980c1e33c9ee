//! Bytes on the wire → frames, with resynchronisation and loss accounting.

use super::cobs::Unstuffer;
use super::encoder::DELIMITER;
use super::error::DecodeError;
use super::frame::Frame;
use super::packet::{CRC_LEN, HEADER_LEN};
use crate::protocol::{CommandRef, Packet, PacketRef, PacketType, MAX_PACKET_LEN};

/// A frame's end, as [`Decoder::take`] saw it.
struct Ended {
    /// Its bytes on the wire, the delimiter included.
    frame_bytes: u64,
    /// A rejection is reported: the decoder was in step and the frame
    /// was not empty.
    reported: bool,
}

/// What a device received ([`Decoder::push_command`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Received<'a> {
    /// A command, where it lies.
    Command(CommandRef<'a>),
    /// A good packet of another kind (a device ignores it).
    Other,
}

/// A packet a delimiter completed, as [`Decoder::push_command`] gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Completed<'a> {
    /// What it was, or why it was rejected.
    pub decoded: Result<Received<'a>, DecodeError>,
    /// Its unstuffed bytes as received ([`Decoder::last_packet_bytes`]).
    pub bytes: &'a [u8],
}

/// What a [`Decoder`] has seen so far. Counters saturate, never wrap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Bytes received.
    pub bytes: u64,
    /// Data frames decoded (CRC good, version known).
    pub frames: u64,
    /// Raw frames decoded (protocol version 2, raw mode).
    pub raw_frames: u64,
    /// Batch frames decoded (protocol version 2), and the samples in them.
    pub batch_frames: u64,
    /// Samples the batch frames carried.
    pub batch_samples: u64,
    /// Replies and commands decoded (protocol version 2).
    pub messages: u64,
    /// Bytes on the wire of the good packets of every kind, delimiters
    /// included.
    pub packet_bytes: u64,
    /// Delimited frames of the right length whose CRC did not match.
    pub crc_errors: u64,
    /// Delimited frames rejected for broken stuffing, wrong length or an
    /// unknown version.
    pub malformed: u64,
    /// Times the sequence number jumped forward between two good frames.
    pub sequence_gaps: u64,
    /// Sequence numbers missing in those jumps: frames sent but not decoded.
    pub frames_lost: u64,
    /// Times the sequence number went backwards or repeated (the device
    /// restarted); not counted as lost frames.
    pub sequence_restarts: u64,
    /// Bytes that were not part of a good frame: the partial frame before
    /// the first delimiter, rejected frames and their delimiters, and extra
    /// delimiters between frames.
    pub bytes_skipped: u64,
    /// Sum of the `overruns` the device reported in good frames.
    pub device_overruns: u64,
    /// Sum of the `dropped` frames the device reported in good frames.
    pub device_dropped: u64,
}

/// Decodes a byte stream into packets (data frames of version 1, and the
/// raw frames, replies and commands of version 2), one byte at a time, with
/// a fixed [`MAX_PACKET_LEN`]-byte buffer: no allocation, no panic on any
/// input.
///
/// Until the first delimiter the decoder does not know where it joined the
/// stream: if those bytes do not form a good frame they are counted as
/// skipped, not as an error. After that every rejected frame is reported.
#[derive(Clone, Debug)]
pub struct Decoder {
    raw: [u8; MAX_PACKET_LEN],
    /// Unstuffed bytes of the current frame (may exceed MAX_PACKET_LEN; saturates).
    len: usize,
    /// Stuffed bytes received since the last delimiter.
    pending: u64,
    /// Unstuffed bytes of the packet last completed (kept up to
    /// MAX_PACKET_LEN).
    finished: usize,
    unstuffer: Unstuffer,
    synced: bool,
    last_sequence: Option<u32>,
    stats: DecoderStats,
}

impl Default for Decoder {
    fn default() -> Decoder {
        Decoder::new()
    }
}

impl Decoder {
    /// A decoder that has seen nothing.
    pub const fn new() -> Decoder {
        Decoder {
            raw: [0; MAX_PACKET_LEN],
            len: 0,
            pending: 0,
            finished: 0,
            unstuffer: Unstuffer::new(),
            synced: false,
            last_sequence: None,
            stats: DecoderStats {
                bytes: 0,
                frames: 0,
                raw_frames: 0,
                batch_frames: 0,
                batch_samples: 0,
                messages: 0,
                packet_bytes: 0,
                crc_errors: 0,
                malformed: 0,
                sequence_gaps: 0,
                frames_lost: 0,
                sequence_restarts: 0,
                bytes_skipped: 0,
                device_overruns: 0,
                device_dropped: 0,
            },
        }
    }

    /// Counters so far.
    pub const fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Sequence number of the last good frame.
    pub const fn last_sequence(&self) -> Option<u32> {
        self.last_sequence
    }

    /// The unstuffed bytes of the packet the last delimiter completed, as
    /// received (at most [`MAX_PACKET_LEN`]; broken stuffing may have left
    /// them short): a device reads a rejected command's sequence number
    /// from them. Valid until the next byte is pushed.
    pub fn last_packet_bytes(&self) -> &[u8] {
        &self.raw[..self.finished]
    }

    /// Bytes received since the last delimiter (a frame in progress).
    pub const fn pending_bytes(&self) -> u64 {
        self.pending
    }

    /// Takes one byte. At a delimiter that ends a packet, returns the packet
    /// or why it was rejected; otherwise `None`.
    pub fn push(&mut self, byte: u8) -> Option<Result<Packet, DecodeError>> {
        let ended = self.take(byte)?;
        let result = self
            .finish_frame()
            .and_then(|len| PacketRef::check(&self.raw[..len]))
            .and_then(PacketRef::parse);
        match result {
            Ok(packet) => {
                self.accept(&packet, ended.frame_bytes);
                Some(Ok(packet))
            }
            Err(error) => self.rejected(error, &ended).map(Err),
        }
    }

    /// [`Decoder::push`] as a device takes commands: a command is read
    /// where it lies in the decoder's buffer ([`Received::Command`]), not
    /// copied into a [`Packet`]; any other good packet is read whole as
    /// `push` reads it and given as [`Received::Other`] (a device ignores
    /// it), and every rejection is `push`'s. With the packet's unstuffed
    /// bytes ([`Decoder::last_packet_bytes`]).
    pub fn push_command(&mut self, byte: u8) -> Option<Completed<'_>> {
        let ended = self.take(byte)?;
        // Checked, then read again below for the borrow's sake: a command
        // is its checked bytes less the version, type and CRC. Any other
        // packet is read whole (`None`: a command).
        let checked =
            self.finish_frame()
                .and_then(|len| match PacketRef::check(&self.raw[..len])? {
                    PacketRef::V2 {
                        kind: PacketType::Command,
                        body,
                    } => match CommandRef::parse(body) {
                        Some(_) => Ok(None),
                        None => Err(DecodeError::Body {
                            kind: PacketType::Command as u8,
                            len: body.len(),
                        }),
                    },
                    other => other.parse().map(Some),
                });
        let other = match checked {
            Ok(other) => other,
            Err(error) => {
                let error = self.rejected(error, &ended)?;
                return Some(Completed {
                    decoded: Err(error),
                    bytes: self.last_packet_bytes(),
                });
            }
        };
        let command = other.is_none();
        match other {
            Some(packet) => self.accept(&packet, ended.frame_bytes),
            None => {
                let s = &mut self.stats;
                s.packet_bytes = s.packet_bytes.saturating_add(ended.frame_bytes);
                s.messages = s.messages.saturating_add(1);
            }
        }
        let bytes = self.last_packet_bytes();
        let body = bytes
            .get(HEADER_LEN..bytes.len().saturating_sub(CRC_LEN))
            .unwrap_or_default();
        let received = match CommandRef::parse(body) {
            Some(packet) if command => Received::Command(packet),
            _ => Received::Other,
        };
        Some(Completed {
            decoded: Ok(received),
            bytes,
        })
    }

    /// One byte into the frame in progress; at a delimiter, the frame's
    /// bytes on the wire and whether a rejection is reported.
    fn take(&mut self, byte: u8) -> Option<Ended> {
        self.stats.bytes = self.stats.bytes.saturating_add(1);
        if byte != DELIMITER {
            self.pending = self.pending.saturating_add(1);
            if let Some(data) = self.unstuffer.push(byte) {
                if let Some(slot) = self.raw.get_mut(self.len) {
                    *slot = data;
                }
                self.len = self.len.saturating_add(1);
            }
            return None;
        }
        let was_synced = core::mem::replace(&mut self.synced, true);
        Some(Ended {
            frame_bytes: self.pending.saturating_add(1),
            reported: self.pending != 0 && was_synced,
        })
    }

    /// A frame rejected for `error`: skipped, and counted and reported once
    /// the decoder is in step (before, and for an empty frame, `None`).
    fn rejected(&mut self, error: DecodeError, ended: &Ended) -> Option<DecodeError> {
        self.skip(ended.frame_bytes);
        if !ended.reported {
            return None;
        }
        if error.is_crc() {
            self.stats.crc_errors = self.stats.crc_errors.saturating_add(1);
        } else {
            self.stats.malformed = self.stats.malformed.saturating_add(1);
        }
        Some(error)
    }

    /// Feeds a slice; the iterator yields each packet or error as its
    /// delimiter is reached. Bytes after the last delimiter stay pending for
    /// the next call. The bytes are consumed as the iterator advances: drop
    /// it early and the bytes it had not reached are not decoded.
    pub fn feed_packets<'a>(&'a mut self, bytes: &'a [u8]) -> Feed<'a> {
        Feed {
            decoder: self,
            bytes: bytes.iter(),
        }
    }

    /// As [`Decoder::feed_packets`], yielding the data frames and the errors
    /// only (other packets are decoded, counted and passed over): what a
    /// reader of corrected samples wants.
    pub fn feed<'a>(
        &'a mut self,
        bytes: &'a [u8],
    ) -> impl Iterator<Item = Result<Frame, DecodeError>> + 'a {
        self.feed_packets(bytes).filter_map(|item| match item {
            Ok(Packet::Data(frame)) => Some(Ok(frame)),
            Ok(_) => None,
            Err(error) => Some(Err(error)),
        })
    }

    /// Ends the bytes since the last delimiter and resets for the next
    /// frame; the frame's length, within the buffer.
    fn finish_frame(&mut self) -> Result<usize, DecodeError> {
        let len = core::mem::take(&mut self.len);
        self.finished = len.min(MAX_PACKET_LEN);
        self.pending = 0;
        self.unstuffer.finish().map_err(|_| DecodeError::Stuffing)?;
        match len <= MAX_PACKET_LEN {
            true => Ok(len),
            false => Err(DecodeError::Length { len }),
        }
    }

    fn accept(&mut self, packet: &Packet, wire_bytes: u64) {
        let s = &mut self.stats;
        s.packet_bytes = s.packet_bytes.saturating_add(wire_bytes);
        let (sequence, overruns, dropped) = match packet {
            Packet::Data(frame) => {
                s.frames = s.frames.saturating_add(1);
                (frame.sequence, frame.overruns, frame.dropped)
            }
            Packet::Raw(raw) => {
                s.raw_frames = s.raw_frames.saturating_add(1);
                (raw.sequence, raw.overruns, raw.dropped)
            }
            Packet::Batch(batch) => {
                s.batch_frames = s.batch_frames.saturating_add(1);
                s.batch_samples = s.batch_samples.saturating_add(u64::from(batch.count));
                (batch.sequence, batch.overruns, batch.dropped)
            }
            Packet::Reply(_) | Packet::Command(_) => {
                s.messages = s.messages.saturating_add(1);
                return;
            }
        };
        s.device_overruns = s.device_overruns.saturating_add(u64::from(overruns));
        s.device_dropped = s.device_dropped.saturating_add(u64::from(dropped));
        if let Some(last) = self.last_sequence {
            // Forward distance modulo 2³²: 0 is the expected next frame;
            // below 2³¹ is a jump over lost frames (wrap-around included);
            // the upper half means the sequence went back (a restart).
            let missing = sequence.wrapping_sub(last.wrapping_add(1));
            if missing == 0 {
                // In order.
            } else if missing < 1 << 31 {
                s.sequence_gaps = s.sequence_gaps.saturating_add(1);
                s.frames_lost = s.frames_lost.saturating_add(u64::from(missing));
            } else {
                s.sequence_restarts = s.sequence_restarts.saturating_add(1);
            }
        }
        self.last_sequence = Some(sequence);
    }

    fn skip(&mut self, bytes: u64) {
        self.stats.bytes_skipped = self.stats.bytes_skipped.saturating_add(bytes);
    }
}

/// Iterator over the packets and errors completed by a slice of bytes; see
/// [`Decoder::feed_packets`].
pub struct Feed<'a> {
    decoder: &'a mut Decoder,
    bytes: core::slice::Iter<'a, u8>,
}

impl Iterator for Feed<'_> {
    type Item = Result<Packet, DecodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        for &byte in self.bytes.by_ref() {
            if let Some(item) = self.decoder.push(byte) {
                return Some(item);
            }
        }
        None
    }
}
