//! Device → host: W corrected samples in one packet (type `0x04`), so the
//! link carries every sample at the chip's full rate: one header per batch
//! and each 6-axis sample in 12 bytes of fixed point.
//!
//! Body (little-endian): `sequence u32 | timestamp_us u32` (the first
//! sample's) `| period_ns u32` (between samples: sample i is at timestamp +
//! i·period) `| flags u16 | overruns u16 | dropped u16 | calibration_id u32
//! | accel_lsb f32 | gyro_lsb f32` (m/s² and rad/s per count of the fixed
//! point) `| temperature f32` (°C, the batch's mean) `| count u8 | count × (6 ×
//! i16)` (accel x y z, gyro x y z). At most [`MAX_BATCH`] samples: 233 bytes
//! with the header and CRC, 235 on the wire, 14.7 bytes per sample.
//!
//! The fixed point: each corrected value is rounded to the nearest count of
//! its triad's `lsb` (ties to even; the device uses a power of two at least
//! 1.5 of the chip's LSBs, [`crate::model::batch_kernel::fixed_point_lsb`],
//! so the counts span at least 1.5 × the chip's range), an error of at most
//! lsb/2; a value beyond ±32767 counts is clipped to it, and the batch's
//! clip flag for that triad is set. Sequence numbers count packets,
//! one numbering with data and raw frames.

use super::bytes::{Reader, Writer};
use super::packet::{write_wire, PacketBuf, PacketType, TooLong, MAX_WIRE_LEN};
use crate::model::batch_kernel::BatchKernel;
use crate::protocol::{DecodeError, Flags};
use crate::sensor::RawSample;

/// Most samples in one batch packet.
pub const MAX_BATCH: usize = 16;

/// Bytes of the body before the samples.
pub const BATCH_HEADER_LEN: usize = 35;

/// Bytes per sample.
pub const BATCH_SAMPLE_LEN: usize = 12;

/// W corrected samples. Two batches are equal when their fields and the
/// samples in use are: what lies beyond `count` (left by an earlier batch
/// in a slot reused in place, [`BatchFrame::clear`]) is never sent.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BatchFrame {
    /// Packet number, one numbering with data and raw frames.
    pub sequence: u32,
    /// The first sample's time, µs since start, wrapping.
    pub timestamp_us: u32,
    /// Time between samples, ns.
    pub period_ns: u32,
    /// Status bits for the batch (a clip flag: some sample of it).
    pub flags: Flags,
    /// Lost sample steps since the previous packet.
    pub overruns: u16,
    /// Packets dropped by the firmware since the previous one.
    pub dropped: u16,
    /// The calibration applied.
    pub calibration_id: u32,
    /// m/s² per accelerometer count.
    pub accel_lsb: f32,
    /// rad/s per gyroscope count.
    pub gyro_lsb: f32,
    /// Mean temperature of the batch, °C.
    pub temperature: f32,
    /// Samples in use.
    pub count: u8,
    /// The samples' counts: accel x y z, gyro x y z.
    pub samples: [[i16; 6]; MAX_BATCH],
}

pub use crate::model::batch_kernel::to_counts;

impl PartialEq for BatchFrame {
    fn eq(&self, other: &Self) -> bool {
        self.sequence == other.sequence
            && self.timestamp_us == other.timestamp_us
            && self.period_ns == other.period_ns
            && self.flags == other.flags
            && self.overruns == other.overruns
            && self.dropped == other.dropped
            && self.calibration_id == other.calibration_id
            && self.accel_lsb == other.accel_lsb
            && self.gyro_lsb == other.gyro_lsb
            && self.temperature == other.temperature
            && self.count == other.count
            && self.samples() == other.samples()
    }
}

impl BatchFrame {
    /// An empty batch.
    pub const fn new(accel_lsb: f32, gyro_lsb: f32) -> Self {
        Self {
            sequence: 0,
            timestamp_us: 0,
            period_ns: 0,
            flags: Flags::empty(),
            overruns: 0,
            dropped: 0,
            calibration_id: 0,
            accel_lsb,
            gyro_lsb,
            temperature: 0.0,
            count: 0,
            samples: [[0; 6]; MAX_BATCH],
        }
    }

    /// Empties the batch for reuse where it lies (a queue's slot), with
    /// these LSBs, every other field to be set anew: no sample in use, no
    /// flag. The samples' array is left as it is (only `count` of it is
    /// ever read), so reuse costs no 192-byte zeroing.
    #[inline]
    pub fn clear(&mut self, accel_lsb: f32, gyro_lsb: f32) {
        self.accel_lsb = accel_lsb;
        self.gyro_lsb = gyro_lsb;
        self.flags = Flags::empty();
        self.count = 0;
    }

    /// Adds a corrected sample in fixed point; false when the batch is full.
    /// Clipping sets the triad's clip flag.
    pub fn push(&mut self, accel: [f32; 3], gyro: [f32; 3]) -> bool {
        let Some(slot) = self.samples.get_mut(usize::from(self.count)) else {
            return false;
        };
        for k in 0..3 {
            let (a, a_clip) = to_counts(accel[k], self.accel_lsb);
            let (g, g_clip) = to_counts(gyro[k], self.gyro_lsb);
            slot[k] = a;
            slot[3 + k] = g;
            if a_clip {
                self.flags.insert(Flags::ACCEL_CLIPPED);
            }
            if g_clip {
                self.flags.insert(Flags::GYRO_CLIPPED);
            }
        }
        self.count += 1;
        true
    }

    /// Corrects as many of `raw` as the batch has room for with `kernel`
    /// (whose LSBs the batch was made with) and appends them; gives how many.
    pub fn push_raw(&mut self, kernel: &BatchKernel, raw: &[RawSample]) -> usize {
        let start = usize::from(self.count);
        let room = self.samples.get_mut(start..).unwrap_or_default();
        let n = raw.len().min(room.len());
        let clip = kernel.correct(&raw[..n], &mut room[..n]);
        self.flags.set(
            Flags::ACCEL_CLIPPED,
            self.flags.contains(Flags::ACCEL_CLIPPED) | clip.accel,
        );
        self.flags.set(
            Flags::GYRO_CLIPPED,
            self.flags.contains(Flags::GYRO_CLIPPED) | clip.gyro,
        );
        self.count += n as u8;
        n
    }

    /// The samples in use.
    pub fn samples(&self) -> &[[i16; 6]] {
        &self.samples[..usize::from(self.count)]
    }

    /// Sample `i` in SI units (m/s², rad/s), computed in f32 as
    /// docs/PROTOCOL.md says, so every decoder gets the same bits.
    pub fn sample_si(&self, i: usize) -> Option<([f32; 3], [f32; 3])> {
        let s = self.samples().get(i)?;
        Some((
            [0, 1, 2].map(|k| f32::from(s[k]) * self.accel_lsb),
            [3, 4, 5].map(|k| f32::from(s[k]) * self.gyro_lsb),
        ))
    }

    /// Reads a batch body (after version and type, before the CRC).
    pub fn parse(body: &[u8]) -> Result<BatchFrame, DecodeError> {
        let bad = DecodeError::Body {
            kind: PacketType::Batch as u8,
            len: body.len(),
        };
        let mut r = Reader::new(body);
        let mut b = BatchFrame::new(0.0, 0.0);
        b.sequence = r.u32();
        b.timestamp_us = r.u32();
        b.period_ns = r.u32();
        b.flags = Flags::from_bits_retain(r.u16());
        b.overruns = r.u16();
        b.dropped = r.u16();
        b.calibration_id = r.u32();
        b.accel_lsb = r.f32();
        b.gyro_lsb = r.f32();
        b.temperature = r.f32();
        b.count = r.u8();
        let n = usize::from(b.count);
        if r.ran_short() || n > MAX_BATCH || r.remaining() != n * BATCH_SAMPLE_LEN {
            return Err(bad);
        }
        for slot in b.samples.iter_mut().take(n) {
            for v in slot.iter_mut() {
                *v = r.u16() as i16;
            }
        }
        Ok(b)
    }

    /// The batch as a sealed packet, written in place.
    pub fn to_packet(&self) -> Result<PacketBuf, TooLong> {
        PacketBuf::with_body(PacketType::Batch, |body| self.write_body(body))
    }

    /// The batch on the wire (stuffed, delimited) into `out`, written where
    /// it goes ([`write_wire`]): the transmitter's form; its length.
    pub fn to_wire(&self, out: &mut [u8; MAX_WIRE_LEN]) -> Result<usize, TooLong> {
        write_wire(PacketType::Batch, out, |body| self.write_body(body))
    }

    /// The body into `body`: the header field by field, then the counts
    /// (little-endian i16) straight from the array; its length, `None`
    /// when it does not fit.
    #[inline]
    fn write_body(&self, body: &mut [u8]) -> Option<usize> {
        let (header, samples) = body.split_at_mut_checked(BATCH_HEADER_LEN)?;
        let mut w = Writer::new(header);
        w.u32(self.sequence)
            .u32(self.timestamp_us)
            .u32(self.period_ns)
            .u16(self.flags.bits())
            .u16(self.overruns)
            .u16(self.dropped)
            .u32(self.calibration_id)
            .f32(self.accel_lsb)
            .f32(self.gyro_lsb)
            .f32(self.temperature)
            .u8(self.count);
        let counts = self.samples().as_flattened();
        let room = samples.get_mut(..counts.len() * 2)?;
        for (bytes, count) in room.chunks_exact_mut(2).zip(counts) {
            bytes.copy_from_slice(&count.to_le_bytes());
        }
        (!w.overflowed()).then_some(BATCH_HEADER_LEN + room.len())
    }
}
