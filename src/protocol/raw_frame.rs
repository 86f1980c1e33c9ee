//! Device → host in raw mode: one sample in the chip's own counts, with the
//! scale that turns them into SI units, so a recording is self-describing.
//!
//! Body (little-endian, 58 bytes): `sequence u32 | timestamp_us u32 |
//! flags u16 | overruns u16 | dropped u16 | accel 3×f32 | gyro 3×f32 |
//! temperature f32` (counts: exact integers without averaging, the mean of N
//! readings with decimation N) `| accel SI per LSB f32 | gyro SI per LSB f32
//! | °C per temperature LSB f32 | °C at temperature 0 f32`. Sequence
//! numbers, flags and counters are the data frames' (one numbering for both
//! kinds), and the RAW and UNCALIBRATED flags are always set.

use super::bytes::{Reader, Writer};
use super::packet::{write_wire, PacketBuf, PacketType, TooLong, MAX_WIRE_LEN};
use crate::protocol::{DecodeError, Flags};
use crate::sensor::ImuScale;

/// Bytes of a raw frame's body.
pub const RAW_BODY_LEN: usize = 58;

/// The chip's nominal sensitivities as a raw frame carries them.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawScale {
    /// m/s² per accelerometer count.
    pub accel_si_per_lsb: f32,
    /// rad/s per gyroscope count.
    pub gyro_si_per_lsb: f32,
    /// °C per temperature count.
    pub temperature_per_lsb: f32,
    /// °C at temperature count 0.
    pub temperature_offset: f32,
}

impl RawScale {
    /// The scale of a configured chip.
    pub fn of(scale: &ImuScale) -> RawScale {
        RawScale {
            accel_si_per_lsb: scale.accel.si_per_lsb as f32,
            gyro_si_per_lsb: scale.gyro.si_per_lsb as f32,
            temperature_per_lsb: scale.temperature_per_lsb as f32,
            temperature_offset: scale.temperature_offset as f32,
        }
    }
}

/// One raw sample (or the mean of N).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawFrame {
    /// Frame number, shared with data frames.
    pub sequence: u32,
    /// Time of the (last) sample, µs since start, wrapping.
    pub timestamp_us: u32,
    /// Status bits (RAW and UNCALIBRATED always set).
    pub flags: Flags,
    /// Lost sample steps since the previous frame.
    pub overruns: u16,
    /// Frames dropped by the firmware since the previous frame.
    pub dropped: u16,
    /// Accelerometer counts, chip axes.
    pub accel: [f32; 3],
    /// Gyroscope counts, chip axes.
    pub gyro: [f32; 3],
    /// Temperature counts.
    pub temperature: f32,
    /// The chip's nominal scale.
    pub scale: RawScale,
}

impl RawFrame {
    /// Reads a raw frame body (after version and type, before the CRC).
    pub fn parse(body: &[u8]) -> Result<RawFrame, DecodeError> {
        if body.len() != RAW_BODY_LEN {
            return Err(DecodeError::Body {
                kind: PacketType::Raw as u8,
                len: body.len(),
            });
        }
        let mut r = Reader::new(body);
        let sequence = r.u32();
        let timestamp_us = r.u32();
        let flags = Flags::from_bits_retain(r.u16());
        let overruns = r.u16();
        let dropped = r.u16();
        let mut triad = || [r.f32(), r.f32(), r.f32()];
        let accel = triad();
        let gyro = triad();
        let temperature = r.f32();
        let scale = RawScale {
            accel_si_per_lsb: r.f32(),
            gyro_si_per_lsb: r.f32(),
            temperature_per_lsb: r.f32(),
            temperature_offset: r.f32(),
        };
        Ok(RawFrame {
            sequence,
            timestamp_us,
            flags,
            overruns,
            dropped,
            accel,
            gyro,
            temperature,
            scale,
        })
    }

    /// The frame as a sealed packet.
    pub fn to_packet(&self) -> Result<PacketBuf, TooLong> {
        PacketBuf::with_body(PacketType::Raw, |body| self.write_body(body))
    }

    /// The frame on the wire (stuffed, delimited) into `out`, written where
    /// it goes ([`write_wire`]): the transmitter's form; its length.
    pub fn to_wire(&self, out: &mut [u8; MAX_WIRE_LEN]) -> Result<usize, TooLong> {
        write_wire(PacketType::Raw, out, |body| self.write_body(body))
    }

    /// The body into `body`; its length, `None` when it does not fit.
    #[inline]
    fn write_body(&self, body: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(body.get_mut(..RAW_BODY_LEN)?);
        w.u32(self.sequence)
            .u32(self.timestamp_us)
            .u16(self.flags.bits())
            .u16(self.overruns)
            .u16(self.dropped);
        for v in self.accel.iter().chain(&self.gyro) {
            w.f32(*v);
        }
        w.f32(self.temperature)
            .f32(self.scale.accel_si_per_lsb)
            .f32(self.scale.gyro_si_per_lsb)
            .f32(self.scale.temperature_per_lsb)
            .f32(self.scale.temperature_offset);
        (!w.overflowed() && w.len() == RAW_BODY_LEN).then_some(RAW_BODY_LEN)
    }

    /// The counts in SI units with the chip's nominal scale, as
    /// `(accel m/s², gyro rad/s, temperature °C)`; computed in `f32`, as
    /// documented in docs/PROTOCOL.md, so every decoder gets the same bits.
    pub fn to_si(&self) -> ([f32; 3], [f32; 3], f32) {
        let s = &self.scale;
        (
            self.accel.map(|c| c * s.accel_si_per_lsb),
            self.gyro.map(|c| c * s.gyro_si_per_lsb),
            self.temperature * s.temperature_per_lsb + s.temperature_offset,
        )
    }
}
