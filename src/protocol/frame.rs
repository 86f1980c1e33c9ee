//! One streamed sample and its byte layout (before stuffing).
//!
//! Layout, all little-endian (docs/PROTOCOL.md has the table):
//!
//! | offset | field          | type     |
//! |-------:|----------------|----------|
//! |      0 | version (= 1)  | u8       |
//! |      1 | sequence       | u32      |
//! |      5 | timestamp_us   | u32      |
//! |      9 | flags          | u16      |
//! |     11 | overruns       | u16      |
//! |     13 | dropped        | u16      |
//! |     15 | calibration_id | u32      |
//! |     19 | accel          | 3 × f32  |
//! |     31 | gyro           | 3 × f32  |
//! |     43 | temperature    | f32      |
//! |     47 | CRC-32C        | u32      |

use super::error::DecodeError;
use super::flags::Flags;
use crate::protocol::crc32c::crc32c;

/// Version byte of the format this crate writes and reads.
pub const VERSION: u8 = 1;

/// Bytes covered by the CRC (everything before it).
pub const CHECKED_LEN: usize = 47;

/// Bytes of a frame before stuffing, CRC included.
pub const FRAME_LEN: usize = CHECKED_LEN + 4;

/// One streamed sample with its bookkeeping.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// Number of this frame among the frames sent; +1 per frame, wrapping
    /// from `u32::MAX` to 0. Frames the firmware drops take no number, so a
    /// gap means frames lost on the way.
    pub sequence: u32,
    /// Time of the (last) sample in the frame, µs since start, wrapping every
    /// 2³² µs ≈ 71.6 min.
    pub timestamp_us: u32,
    /// Status bits.
    pub flags: Flags,
    /// Sample steps that began before the previous one finished, since the
    /// previous frame (saturating at `u16::MAX`).
    pub overruns: u16,
    /// Frames the firmware dropped because the link was full, since the
    /// previous frame (saturating at `u16::MAX`).
    pub dropped: u16,
    /// Identity of the calibration applied.
    pub calibration_id: u32,
    /// Corrected specific force, m/s², sensor axes x, y, z.
    pub accel: [f32; 3],
    /// Corrected angular rate, rad/s, sensor axes x, y, z.
    pub gyro: [f32; 3],
    /// Sensor temperature, °C.
    pub temperature: f32,
}

impl Frame {
    /// The frame's bytes before stuffing, CRC included. Every field goes to
    /// a constant offset, so the copies compile to plain stores (no bounds
    /// checks: this runs once per frame on the device).
    pub fn to_bytes(&self) -> [u8; FRAME_LEN] {
        fn put<const N: usize>(bytes: &mut [u8; FRAME_LEN], at: usize, field: [u8; N]) {
            bytes[at..at + N].copy_from_slice(&field);
        }
        let mut b = [0u8; FRAME_LEN];
        b[0] = VERSION;
        put(&mut b, 1, self.sequence.to_le_bytes());
        put(&mut b, 5, self.timestamp_us.to_le_bytes());
        put(&mut b, 9, self.flags.bits().to_le_bytes());
        put(&mut b, 11, self.overruns.to_le_bytes());
        put(&mut b, 13, self.dropped.to_le_bytes());
        put(&mut b, 15, self.calibration_id.to_le_bytes());
        for (i, v) in self.accel.iter().chain(&self.gyro).enumerate() {
            put(&mut b, 19 + 4 * i, v.to_le_bytes());
        }
        put(&mut b, 43, self.temperature.to_le_bytes());
        const _: () = assert!(CHECKED_LEN == 47 && FRAME_LEN == 51);
        let crc = crc32c(&b[..CHECKED_LEN]);
        put(&mut b, CHECKED_LEN, crc.to_le_bytes());
        b
    }

    /// Reads a frame from its unstuffed bytes: checks the CRC first (nothing
    /// else can be trusted before), then the version.
    pub fn from_bytes(bytes: &[u8; FRAME_LEN]) -> Result<Frame, DecodeError> {
        let (checked, crc_bytes) = bytes.split_at(CHECKED_LEN);
        let computed = crc32c(checked);
        let mut r = Reader { rest: crc_bytes };
        let received = u32::from_le_bytes(r.take());
        if received != computed {
            return Err(DecodeError::Crc { received, computed });
        }
        let mut r = Reader { rest: checked };
        let [version] = r.take::<1>();
        if version != VERSION {
            return Err(DecodeError::Version { version });
        }
        let sequence = u32::from_le_bytes(r.take());
        let timestamp_us = u32::from_le_bytes(r.take());
        let flags = Flags::from_bits_retain(u16::from_le_bytes(r.take()));
        let overruns = u16::from_le_bytes(r.take());
        let dropped = u16::from_le_bytes(r.take());
        let calibration_id = u32::from_le_bytes(r.take());
        let mut triad = || {
            [
                f32::from_le_bytes(r.take()),
                f32::from_le_bytes(r.take()),
                f32::from_le_bytes(r.take()),
            ]
        };
        let accel = triad();
        let gyro = triad();
        let temperature = f32::from_le_bytes(r.take());
        Ok(Frame {
            sequence,
            timestamp_us,
            flags,
            overruns,
            dropped,
            calibration_id,
            accel,
            gyro,
            temperature,
        })
    }
}

/// Reads consecutive fields; past the end it yields zeros (never reached
/// with the constant layout).
struct Reader<'a> {
    rest: &'a [u8],
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        match self.rest.split_first_chunk::<N>() {
            Some((head, tail)) => {
                self.rest = tail;
                *head
            }
            None => [0; N],
        }
    }
}
