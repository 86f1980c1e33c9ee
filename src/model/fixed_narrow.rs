//! The 32-bit form of the fixed-point rows: every product and sum fits an
//! i32, so a core without a 32×32→64 multiply (Cortex-M0: MULS gives the low
//! word only, and an i64 product is a library call of dozens of
//! instructions) corrects a sample with single-instruction multiplies.
//!
//! Per row, with S the coefficient scale, F the output's fraction bits and
//! the split h = 16:
//!
//! ```text
//! K_q = round(K·2^S), |K_q| ≤ 2²⁹;   K_hi = K_q >> 16 (|K_hi| ≤ 2¹³),   K_lo = K_q & 0xFFFF
//! o   = round(k·2^(S−16)) + 2^(r−1),  r = S − 16 − F ≥ 1
//! out = (o + Σ_j [K_hi_j·x_j + ((K_lo_j·x_j) >> 16)]) >> r
//! ```
//!
//! K_q·x = K_hi·x·2¹⁶ + K_lo·x exactly, so the sum is K_q·x/2¹⁶ up to the
//! floor of each (K_lo·x) >> 16. Ranges, for any i16 x (|x| ≤ 2¹⁵):
//! |K_hi·x| ≤ 2²⁸; 0 ≤ K_lo ≤ 65535 so |K_lo·x| ≤ 65535·32768 < 2³¹;
//! construction checks that the largest possible |sum| is below 2³¹.
//!
//! Error against the exact K·x + k, in SI units (each line one source):
//! - coefficient rounding: ½·Σ|x_j|·2^−S ≤ ½·N·32768·2^−S;
//! - the N floors: each in (−1, 0] units of 2^(16−S): ≤ N·2^(16−S);
//! - offset rounding: ½·2^(16−S);
//! - the final shift (round half up): ≤ 2^−(F+1).
//!
//! The form exists only where r ≥ 1 with |K_q| ≤ 2²⁹, i.e. max|K| ≤
//! 2^(13−F): for the accelerometer (F = 16) up to 0.125 m/s² per LSB (a
//! ±400 g 16-bit chip with a 3× correction), for the gyroscope (F = 20) up to
//! 0.0078 rad/s per LSB. Beyond that [`super::fixed`] keeps the i64 form.

use super::fixed::pow2;

/// N rows in the 32-bit form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NarrowRows<const N: usize> {
    k_hi: [[i32; N]; N],
    k_lo: [[i32; N]; N],
    offset: [i32; N],
    /// r = S − 16 − F, in 1..=31.
    shift: u32,
    /// F, the output's fraction bits.
    fraction_bits: u32,
}

/// The split of K_q into high and low halves.
const SPLIT: i32 = 16;
/// |K_q| ≤ 2^COEFFICIENT_BITS.
const COEFFICIENT_BITS: i32 = 29;

impl<const N: usize> NarrowRows<N> {
    /// The rows for `k` (N×N) and `offset` with F = `fraction_bits`, or
    /// `None` where the 32-bit form cannot hold them (see the module doc).
    pub fn new(fraction_bits: u32, k: &[[f64; N]; N], offset: &[f64; N]) -> Option<Self> {
        let f = fraction_bits as i32;
        let max_k = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        if !max_k.is_finite() || offset.iter().any(|o| !o.is_finite()) {
            return None;
        }
        // The largest S with max|K|·2^S ≤ 2²⁹, capped so that 2^S stays exact and small.
        let mut s = f + SPLIT + 31;
        while s > f + SPLIT + 1 && max_k * pow2(s) > pow2(COEFFICIENT_BITS) {
            s -= 1;
        }
        if max_k * pow2(s) > pow2(COEFFICIENT_BITS) {
            return None;
        }
        let shift = s - SPLIT - f;
        let mut rows = NarrowRows {
            k_hi: [[0; N]; N],
            k_lo: [[0; N]; N],
            offset: [0; N],
            shift: shift as u32,
            fraction_bits,
        };
        for (i, (k_row, &k_off)) in k.iter().zip(offset).enumerate() {
            let mut max_sum = 0.0f64;
            for (j, &kij) in k_row.iter().enumerate() {
                let q = libm::round(kij * pow2(s)) as i32;
                rows.k_hi[i][j] = q >> SPLIT;
                rows.k_lo[i][j] = q & 0xFFFF;
                max_sum += f64::from(rows.k_hi[i][j]).abs() * 32768.0 + 32768.0;
            }
            let o = libm::round(k_off * pow2(s - SPLIT)) + pow2(shift - 1);
            max_sum += o.abs();
            if max_sum >= pow2(31) - 1.0 {
                return None;
            }
            rows.offset[i] = o as i32;
        }
        Some(rows)
    }

    /// The proven bound on |out·2^−F − (K·x + k)| in SI units (module doc).
    pub fn error_bound(&self) -> f64 {
        let f = self.fraction_bits as i32;
        let s = self.shift as i32 + SPLIT + f;
        let n = N as f64;
        0.5 * n * 32768.0 * pow2(-s) + (n + 0.5) * pow2(SPLIT - s) + pow2(-f - 1)
    }

    /// Row `i` of the correction of `x`.
    #[inline(always)]
    fn row(&self, i: usize, x: &[i32; N]) -> i32 {
        let mut acc = self.offset[i];
        for ((&hi, &lo), &xj) in self.k_hi[i].iter().zip(&self.k_lo[i]).zip(x) {
            // Wrapping ops: construction proved no overflow; they keep any
            // panic path out of the hot loop.
            acc = acc
                .wrapping_add(hi.wrapping_mul(xj))
                .wrapping_add(lo.wrapping_mul(xj) >> SPLIT);
        }
        acc >> self.shift
    }
}

impl NarrowRows<3> {
    /// The three corrected axes of `x`.
    #[inline(always)]
    pub fn apply(&self, x: &[i16; 3]) -> [i32; 3] {
        let x = [i32::from(x[0]), i32::from(x[1]), i32::from(x[2])];
        [self.row(0, &x), self.row(1, &x), self.row(2, &x)]
    }
}

impl NarrowRows<1> {
    /// The corrected single channel (temperature).
    #[inline(always)]
    pub fn apply_one(&self, x: i16) -> i32 {
        self.row(0, &[i32::from(x)])
    }
}
