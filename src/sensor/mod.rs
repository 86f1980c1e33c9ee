//! Sensors: the raw sample, the IMU trait the firmware and the model see,
//! the [`Chip`] trait (what differs between chips), the one generic
//! [`Driver`] over it, and one module per chip.

pub mod accel_range;
pub mod chip;
pub mod config;
pub mod detect;
pub mod driver;
pub mod error;
pub mod fifo;
pub mod icm42688;
pub mod interface;
pub mod interrupt;
pub mod lsm6dsox;
pub mod self_test;
pub mod settings;

pub use accel_range::AccelRange;
pub use chip::{Chip, DataRate, FullScale};
pub use config::Config;
pub use detect::{AnyChip, DetectError, Undetected, CHIP_NAMES};
pub use driver::Driver;
pub use error::Error;
pub use fifo::{FifoConfig, FifoImu, FifoMode, FifoRead};
pub use interrupt::InterruptPin;
pub use self_test::{Axis, ChipLeft, ChipSelfTest, SelfTestError, SelfTestReport};
pub use settings::Settings;

/// One raw reading of both triads, in the chip's own counts (LSB). i32, as
/// the ICM-42688-P's high-resolution FIFO gives 20-bit values; a 16-bit
/// chip's counts are its i16 codes (the range each triad's codes take, and
/// at which they clip, is its [`TriadScale::codes`]). `repr(C)`: the
/// Cortex-M4F's batch loop reads it as words (src/model/fused_pass.rs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawSample {
    /// Accelerometer x, y, z in LSB.
    pub accel: [i32; 3],
    /// Gyroscope x, y, z in LSB.
    pub gyro: [i32; 3],
    /// Die temperature in LSB (see [`ImuScale::temperature_c`]).
    pub temperature: i16,
}

/// The codes one triad's axes take: a code at or beyond `low` or `high` is
/// at the chip's limit (saturated, or the chip's "no data" marker), and no
/// code exceeds `magnitude` in absolute value. The corrector flags a triad
/// with an axis at its limit as clipped; the fixed-point corrector proves
/// its overflow bounds for inputs within `magnitude`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CodeRange {
    /// At or below this code an axis is at its limit.
    pub low: i32,
    /// At or above this code an axis is at its limit.
    pub high: i32,
    /// The largest |code| the chip gives, markers included.
    pub magnitude: u32,
}

impl CodeRange {
    /// A 16-bit chip's: -32768 (the saturated or "no data" code) and 32767.
    pub const I16: CodeRange = CodeRange {
        low: i16::MIN as i32,
        high: i16::MAX as i32,
        magnitude: 1 << 15,
    };

    /// The code of an axis with no sample, the most negative: -32768 on
    /// both chips' 16-bit outputs, -524288 in the ICM-42688-P's 20-bit FIFO
    /// packets (DS-000347 §6.1). It is at the limit, so a triad that never
    /// had a sample is flagged clipped rather than passed off as a measurement.
    pub fn no_data(&self) -> i32 {
        // magnitude ≤ 2¹⁹ for every chip: the negation fits.
        -(self.magnitude as i32)
    }

    /// Whether any of the axes `v` is at the limit, branch-free.
    #[inline(always)]
    pub fn at_limit(&self, v: &[i32; 3]) -> bool {
        #[cfg(triad_dsp)]
        let out = self.outside_reflected(v);
        #[cfg(not(triad_dsp))]
        let out = self.outside_compared(v);
        out != 0
    }

    /// [`CodeRange::I16`]'s `at_limit` for i16 codes, in three instructions
    /// per axis ([`Self::i16_limit_bit`]).
    #[inline(always)]
    pub fn at_i16_limit(v: &[i32; 3]) -> bool {
        let bit = Self::i16_limit_bit;
        (bit(v[0]) | bit(v[1]) | bit(v[2])) & (1 << 15) != 0
    }

    /// Bit 15 set exactly for the limit codes of an i16 `x` (32767 and
    /// −32768): x ^ (x >> 15) is x for x ≥ 0 and −x − 1 below, so 32767 for
    /// both limits and less for any other code; adding 1 reaches 2¹⁵ only
    /// from there.
    #[inline(always)]
    pub fn i16_limit_bit(x: i32) -> u32 {
        ((x ^ (x >> 15)) + 1) as u32
    }

    /// Non-zero when an axis of `v` is at the limit: with base = low + 1, v
    /// is strictly inside exactly when v − base, as u32, is below
    /// high − low − 1 (a code below base wraps to a large u32). The form
    /// for cores without shifted operands (the Cortex-M0's Thumb-1), and
    /// the host.
    #[cfg(any(not(triad_dsp), test))]
    #[inline(always)]
    fn outside_compared(&self, v: &[i32; 3]) -> u32 {
        let base = self.low.wrapping_add(1);
        let span = self.high.wrapping_sub(self.low).wrapping_sub(1) as u32;
        let out = |x: i32| (x.wrapping_sub(base) as u32 >= span) as u32;
        out(v[0]) | out(v[1]) | out(v[2])
    }

    /// [`Self::outside_compared`]'s answer in bit 31, in four instructions
    /// per axis on the Cortex-M4F (where the compared form takes six, the
    /// comparison's flag turned into a bit). Reflected about the range's
    /// centre, y = 2v − (low + high) is at the limit exactly when y ≤ −D or
    /// y ≥ D (D = high − low); z = y ^ (y >> 31) is −y − 1 for y < 0 and y
    /// else, so the test is z ≥ D − 1 on the negative side and z ≥ D on the
    /// other, where y's parity (that of low + high) is never D − 1's, so
    /// z ≥ D − 1 decides both. Then D − 2 − z (0 ≤ z < 2³¹) is negative
    /// exactly there: bit 31. Exact for |low|, |high| and |v| below 2³⁰.
    #[cfg(any(triad_dsp, test))]
    #[inline(always)]
    fn outside_reflected(&self, v: &[i32; 3]) -> u32 {
        let sum = self.low.wrapping_add(self.high);
        let inside = self.high.wrapping_sub(self.low).wrapping_sub(2);
        let bit_31 = |x: i32| {
            let y = x.wrapping_mul(2).wrapping_sub(sum);
            inside.wrapping_sub(y ^ (y >> 31)) as u32
        };
        (bit_31(v[0]) | bit_31(v[1]) | bit_31(v[2])) >> 31
    }
}

/// How one triad's counts map to SI units, for the configured range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadScale {
    /// SI units per LSB: m/s² per LSB (accelerometer) or rad/s per LSB (gyroscope).
    pub si_per_lsb: f64,
    /// The configured measurement range, ± this many SI units.
    pub full_scale: f64,
    /// The codes the triad's axes take ([`CodeRange::I16`] for a 16-bit chip).
    pub codes: CodeRange,
}

/// The sensitivities of a configured chip: what the model folds into K.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuScale {
    /// Accelerometer counts → m/s².
    pub accel: TriadScale,
    /// Gyroscope counts → rad/s.
    pub gyro: TriadScale,
    /// °C per temperature LSB.
    pub temperature_per_lsb: f64,
    /// °C at temperature reading 0.
    pub temperature_offset: f64,
}

impl ImuScale {
    /// The die temperature in °C of a raw temperature reading.
    pub fn temperature_c(&self, raw: i16) -> f64 {
        f64::from(raw) * self.temperature_per_lsb + self.temperature_offset
    }
}

/// What the firmware and the model see of a chip, whatever its bus.
pub trait Imu {
    /// The driver's error (bus failures, identity mismatches, ...).
    type Error;
    /// Reads the latest accelerometer, gyroscope and temperature sample in one burst.
    fn read_sample(&mut self) -> Result<RawSample, Self::Error>;
    /// The LSB → SI sensitivities of the configured ranges.
    fn scale(&self) -> ImuScale;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both forms of the limit test agree with its definition (v ≤ low or
    /// v ≥ high) on every code of a 16-bit chip, every code up to past the
    /// 20-bit FIFO's magnitude for its two ranges, and around the edges of
    /// ranges of every parity and offset.
    #[test]
    fn both_limit_forms_are_the_definition() {
        let check = |codes: CodeRange, x: i32| {
            let limit = x <= codes.low || x >= codes.high;
            let inside = codes.low + (codes.high - codes.low) / 2;
            let v = [inside, x, inside];
            assert_eq!(codes.outside_compared(&v) != 0, limit, "{codes:?} {x}");
            assert_eq!(codes.outside_reflected(&v) != 0, limit, "{codes:?} {x}");
            assert_eq!(codes.at_limit(&[x; 3]), limit, "{codes:?} {x}");
        };
        for x in -40_000..40_000 {
            check(CodeRange::I16, x);
        }
        for x in i32::from(i16::MIN)..=i32::from(i16::MAX) {
            let limit = CodeRange::I16.at_limit(&[x; 3]);
            assert_eq!(CodeRange::at_i16_limit(&[0, x, 1]), limit, "{x}");
        }
        let hires = crate::sensor::icm42688::config::high_resolution_scale();
        for codes in [hires.accel.codes, hires.gyro.codes] {
            for x in -(1 << 19) - 5..(1 << 19) + 5 {
                check(codes, x);
            }
        }
        for low in [-(1 << 29), -70_000, -32_769, -32_768, -5, 0, 3] {
            for width in [1, 2, 3, 4, 65_535, 65_536, 1 << 20, (1 << 29) + 1] {
                let codes = CodeRange {
                    low,
                    high: low + width,
                    magnitude: 1 << 29,
                };
                for x in (low - 3..low + 4).chain(low + width - 3..low + width + 4) {
                    check(codes, x);
                }
            }
        }
    }
}
