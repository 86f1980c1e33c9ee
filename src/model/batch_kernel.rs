//! The batch hot path: W raw samples from a FIFO corrected straight into the
//! fixed-point counts a batch frame carries (docs/PROTOCOL.md §20), with
//! clip flags.
//!
//! The frame's LSB is a power of two ([`fixed_point_lsb`]), so dividing by it
//! is exact: the kernel multiplies K and k by 1/LSB once, at construction,
//! and every product and sum of the f32 kernel is then the f32 kernel's own
//! scaled by that power of two, rounding included. A sample's counts are
//! therefore exactly [`to_counts`] of [`Corrector::correct`]'s value, on the
//! device and on the host: the decoder's value (counts × LSB) is the f32
//! correction rounded to the nearest count, an error of at most LSB/2.

use super::corrector::{ClipFlags, Corrector};
use super::Triad;
use crate::sensor::RawSample;

/// Most counts a corrected value takes: ±32767 (−32768 is left unused so the
/// range is symmetric, as the clip flag's meaning is).
pub const MAX_COUNTS: i16 = 32767;

/// Adding then subtracting this rounds an f32 of magnitude below 2²² to the
/// nearest integer, ties to even (the IEEE default rounding, the same on
/// every core): 1.5·2²³.
const ROUND_MAGIC: f32 = 12_582_912.0;

/// The batch frame's LSB for a chip's `si_per_lsb`: the smallest power of two
/// at least 1.5 chip LSBs, so the counts span at least 1.5 × the chip's full
/// scale (room for a corrected value beyond the raw range) and the rounding
/// error is at most 1.5 chip LSBs (LSB/2 of a step below 3 chip LSBs).
pub fn fixed_point_lsb(si_per_lsb: f64) -> f32 {
    let exponent = libm::ceil(libm::log2(1.5 * si_per_lsb));
    libm::ldexp(1.0, exponent as i32) as f32
}

/// `value / lsb` rounded to the nearest count, ties to even, within
/// ±[`MAX_COUNTS`]; and whether it was clipped (beyond the range, or NaN,
/// which gives 0). `lsb` must be a power of two for the division to be exact.
#[inline(always)]
pub fn to_counts(value: f32, lsb: f32) -> (i16, bool) {
    counts_of_scaled(value * (1.0 / lsb))
}

/// An already scaled value to counts (see [`to_counts`]).
#[inline(always)]
fn counts_of_scaled(scaled: f32) -> (i16, bool) {
    let limit = f32::from(MAX_COUNTS);
    if scaled.abs() <= limit {
        // |scaled| < 2²²: the magic rounding holds; the result is integral.
        (((scaled + ROUND_MAGIC) - ROUND_MAGIC) as i16, false)
    } else if scaled > limit {
        (MAX_COUNTS, true)
    } else if scaled < -limit {
        (-MAX_COUNTS, true)
    } else {
        (0, true)
    }
}

/// One triad's K and k scaled to counts.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ScaledTriad {
    k: [[f32; 3]; 3],
    offset: [f32; 3],
}

impl ScaledTriad {
    fn new(corrector: &Corrector, triad: Triad, lsb: f32) -> Self {
        let (k, offset) = corrector.folded_f32(triad);
        let per_lsb = 1.0 / lsb;
        ScaledTriad {
            k: k.map(|row| row.map(|c| c * per_lsb)),
            offset: offset.map(|c| c * per_lsb),
        }
    }

    /// One raw triad to counts, in the f32 kernel's order (offset first,
    /// then the three products, left to right); true when a value clipped.
    #[inline(always)]
    fn apply(&self, raw: &[i16; 3], out: &mut [i16]) -> bool {
        let x = raw.map(f32::from);
        let mut clipped = false;
        for ((row, offset), slot) in self.k.iter().zip(self.offset).zip(out.iter_mut()) {
            let v = offset + row[0] * x[0] + row[1] * x[1] + row[2] * x[2];
            let (counts, clip) = counts_of_scaled(v);
            *slot = counts;
            clipped |= clip;
        }
        clipped
    }
}

/// A corrector's f32 kernel scaled to a batch frame's counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BatchKernel {
    accel: ScaledTriad,
    gyro: ScaledTriad,
    accel_lsb: f32,
    gyro_lsb: f32,
}

impl BatchKernel {
    /// The kernel of `corrector` as currently folded, to counts of the
    /// batch frame's LSBs for the corrector's chip scale.
    pub fn new(corrector: &Corrector) -> Self {
        let scale = corrector.scale();
        let accel_lsb = fixed_point_lsb(scale.accel.si_per_lsb);
        let gyro_lsb = fixed_point_lsb(scale.gyro.si_per_lsb);
        BatchKernel {
            accel: ScaledTriad::new(corrector, Triad::Accel, accel_lsb),
            gyro: ScaledTriad::new(corrector, Triad::Gyro, gyro_lsb),
            accel_lsb,
            gyro_lsb,
        }
    }

    /// m/s² per accelerometer count.
    pub fn accel_lsb(&self) -> f32 {
        self.accel_lsb
    }

    /// rad/s per gyroscope count.
    pub fn gyro_lsb(&self) -> f32 {
        self.gyro_lsb
    }

    /// Corrects `raw` into the front of `out` (accel x y z, gyro x y z
    /// counts; as many as both hold), and gives the batch's clip flags: a
    /// triad is flagged when any of its raw axes is at the chip's limit code
    /// or any corrected value clipped to ±[`MAX_COUNTS`].
    pub fn correct(&self, raw: &[RawSample], out: &mut [[i16; 6]]) -> ClipFlags {
        let mut clip = ClipFlags::default();
        for (r, o) in raw.iter().zip(out.iter_mut()) {
            let (accel_out, gyro_out) = o.split_at_mut(3);
            let at_limit = ClipFlags::of(r);
            clip.accel |= self.accel.apply(&r.accel, accel_out) | at_limit.accel;
            clip.gyro |= self.gyro.apply(&r.gyro, gyro_out) | at_limit.gyro;
        }
        clip
    }
}
