//! The 32-bit form of the fixed-point rows: every product and sum fits an
//! i32, so a core without a 32×32→64 multiply (Cortex-M0: MULS gives the low
//! word only, and an i64 product is a library call of dozens of
//! instructions) corrects a sample with single-instruction multiplies.
//!
//! Per row, with S the coefficient scale, F the output's fraction bits and
//! the split h = 14:
//!
//! ```text
//! K_q = round(K·2^S), |K_q| ≤ 2²⁸;   K_hi = K_q >> 14 (|K_hi| ≤ 2¹⁴),   K_lo = K_q & 0x3FFF
//! o   = round(k·2^(S−14)) + 2^(r−1),  r = S − 14 − F ≥ 1
//! out = (o + Σ_j K_hi_j·x_j + ((Σ_j K_lo_j·x_j) >> 14)) >> r
//! ```
//!
//! K_q·x = K_hi·x·2¹⁴ + K_lo·x exactly, so the sum is K_q·x/2¹⁴ up to the
//! one floor of the low products' sum >> 14. Ranges, for any 16-bit x (|x| ≤
//! 2¹⁵; wider inputs, the ICM-42688-P's 20-bit FIFO values, would overflow
//! the products, so construction refuses them and [`super::fixed`] keeps
//! the i64 form): |K_hi·x| ≤ 2²⁹; 0 ≤ K_lo < 2¹⁴ so |Σ_j K_lo_j·x_j| < N·2²⁹ ≤ 3·2²⁹
//! < 2³¹; construction checks that the largest possible |sum| is below 2³¹.
//! One shift of the low sum per row rather than one per product, and one
//! MULS per half: a Cortex-M0 has no shifted operands.
//!
//! Error against the exact K·x + k, in SI units (each line one source):
//! - coefficient rounding: ½·Σ|x_j|·2^−S ≤ ½·N·32768·2^−S;
//! - the floor of the low sum: in (−1, 0] units of 2^(14−S): ≤ 2^(14−S);
//! - offset rounding: ½·2^(14−S);
//! - the final shift (round half up): ≤ 2^−(F+1).
//!
//! The form exists only where r ≥ 1 with |K_q| ≤ 2²⁸, i.e. max|K| ≤
//! 2^(13−F): for the accelerometer (F = 16) up to 0.125 m/s² per LSB (a
//! ±200 g 16-bit chip with a 1/0.55 correction), for the gyroscope (F = 20)
//! up to 0.0078 rad/s per LSB (±4000 °/s with a 3.6× correction). Beyond that [`super::fixed`] keeps the i64 form.

use super::fixed::pow2;

/// N rows in the 32-bit form. `repr(C)`: the Cortex-M0 row
/// (`row_armv6m`, in this file) reads the fields at fixed offsets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct NarrowRows<const N: usize> {
    k_hi: [[i32; N]; N],
    k_lo: [[i32; N]; N],
    offset: [i32; N],
    /// r = S − 14 − F, in 1..=31.
    shift: u32,
    /// F, the output's fraction bits.
    fraction_bits: u32,
}

/// The split of K_q into high and low halves.
const SPLIT: i32 = 14;
/// |K_q| ≤ 2^COEFFICIENT_BITS.
const COEFFICIENT_BITS: i32 = 28;
/// The largest |input| the ranges hold for: a 16-bit chip's codes.
const MAX_INPUT_MAGNITUDE: u32 = 1 << 15;

impl<const N: usize> NarrowRows<N> {
    /// The rows for `k` (N×N) and `offset` with F = `fraction_bits` on
    /// inputs up to `max_input` in magnitude, or `None` where the 32-bit
    /// form cannot hold them (see the module doc).
    pub fn new(
        fraction_bits: u32,
        k: &[[f64; N]; N],
        offset: &[f64; N],
        max_input: u32,
    ) -> Option<Self> {
        if max_input > MAX_INPUT_MAGNITUDE {
            return None;
        }
        let f = fraction_bits as i32;
        let max_k = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        if !max_k.is_finite() || offset.iter().any(|o| !o.is_finite()) {
            return None;
        }
        // The largest S with max|K|·2^S ≤ 2²⁸, capped so that 2^S stays exact and small.
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
                rows.k_lo[i][j] = q & ((1 << SPLIT) - 1);
                // The hi product, and the lo product's share after the shift.
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
        0.5 * n * 32768.0 * pow2(-s) + 1.5 * pow2(SPLIT - s) + pow2(-f - 1)
    }

    /// Row `i` of the correction of `x`.
    #[inline(always)]
    fn row(&self, i: usize, x: &[i32; N]) -> i32 {
        let (mut acc, mut low) = (self.offset[i], 0i32);
        for ((&hi, &lo), &xj) in self.k_hi[i].iter().zip(&self.k_lo[i]).zip(x) {
            // Wrapping ops: construction proved no overflow; they keep any
            // panic path out of the hot loop.
            acc = acc.wrapping_add(xj.wrapping_mul(hi));
            low = low.wrapping_add(xj.wrapping_mul(lo));
        }
        acc.wrapping_add(low >> SPLIT) >> self.shift
    }
}

impl NarrowRows<3> {
    /// The three corrected axes of `x`.
    #[inline(always)]
    pub fn apply(&self, x: &[i32; 3]) -> [i32; 3] {
        // ARMv6-M (Cortex-M0) is the Arm target without 32-bit atomics
        // (no LDREX/STREX): Arm's target features are not visible to cfg.
        #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
        return [
            row_armv6m::<0>(self, x),
            row_armv6m::<1>(self, x),
            row_armv6m::<2>(self, x),
        ];
        #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
        [self.row(0, x), self.row(1, x), self.row(2, x)]
    }
}

/// Row `I` of `rows` applied to `x` on a Cortex-M0 (ARMv6-M: Thumb-1, no
/// shifted operands, MULS overwrites an operand): [`NarrowRows::row`]'s
/// arithmetic in 22 instructions, each coefficient loaded into the register
/// it is multiplied into. Written out because LLVM keeps the 21 coefficients
/// as loop invariants, spills them, and then copies an input before each of
/// the 18 multiplies (MULS would overwrite it): about 50 instructions more
/// per sample. The same operations in the same wrapping arithmetic as `row`
/// (the low sum first: integer addition is associative, so the bits are
/// equal), which tests/model_fixed.rs checks on the host and `cargo xtask
/// bench` on the emulated core (its digest against the host's).
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
#[inline(always)]
#[allow(unsafe_code)]
fn row_armv6m<const I: usize>(rows: &NarrowRows<3>, x: &[i32; 3]) -> i32 {
    use core::mem::{offset_of, size_of};
    let acc: i32;
    // SAFETY: reads only the words of `*rows` named by the offsets below
    // (fields of a repr(C) struct, 4-aligned, within its 96 bytes), writes
    // no memory and no stack; `t` and `acc` are scratch outputs.
    unsafe {
        core::arch::asm!(
            "ldr {acc}, [{p}, #{l0}]",
            "muls {acc}, {x0}, {acc}",
            "ldr {t}, [{p}, #{l1}]",
            "muls {t}, {x1}, {t}",
            "adds {acc}, {acc}, {t}",
            "ldr {t}, [{p}, #{l2}]",
            "muls {t}, {x2}, {t}",
            "adds {acc}, {acc}, {t}",
            "asrs {acc}, {acc}, #{split}",
            "ldr {t}, [{p}, #{o}]",
            "adds {acc}, {acc}, {t}",
            "ldr {t}, [{p}, #{h0}]",
            "muls {t}, {x0}, {t}",
            "adds {acc}, {acc}, {t}",
            "ldr {t}, [{p}, #{h1}]",
            "muls {t}, {x1}, {t}",
            "adds {acc}, {acc}, {t}",
            "ldr {t}, [{p}, #{h2}]",
            "muls {t}, {x2}, {t}",
            "adds {acc}, {acc}, {t}",
            "ldr {t}, [{p}, #{sh}]",
            "asrs {acc}, {acc}, {t}",
            p = in(reg) rows,
            x0 = in(reg) x[0],
            x1 = in(reg) x[1],
            x2 = in(reg) x[2],
            acc = out(reg) acc,
            t = out(reg) _,
            split = const SPLIT,
            l0 = const offset_of!(NarrowRows<3>, k_lo) + 12 * I,
            l1 = const offset_of!(NarrowRows<3>, k_lo) + 12 * I + size_of::<i32>(),
            l2 = const offset_of!(NarrowRows<3>, k_lo) + 12 * I + 2 * size_of::<i32>(),
            h0 = const offset_of!(NarrowRows<3>, k_hi) + 12 * I,
            h1 = const offset_of!(NarrowRows<3>, k_hi) + 12 * I + size_of::<i32>(),
            h2 = const offset_of!(NarrowRows<3>, k_hi) + 12 * I + 2 * size_of::<i32>(),
            o = const offset_of!(NarrowRows<3>, offset) + 4 * I,
            sh = const offset_of!(NarrowRows<3>, shift),
            options(pure, readonly, nostack),
        );
    }
    acc
}

impl NarrowRows<1> {
    /// The corrected single channel (temperature).
    #[inline(always)]
    pub fn apply_one(&self, x: i16) -> i32 {
        self.row(0, &[i32::from(x)])
    }
}
