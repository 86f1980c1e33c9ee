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
//! With a g-sensitivity the gyro's rows also read the raw accelerometer
//! sample, in the f32 kernel's order (the gyro's three products, then the
//! accelerometer's three), so the same holds.

use super::corrector::{counts_f32, ClipFlags, Corrector};
#[cfg(triad_fpu)]
use super::fused_pass::FusedPass;
use super::limit_codes::LimitCodes;
use super::Triad;
use crate::sensor::{CodeRange, RawSample, TriadScale};

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

/// The batch frame's LSB for a triad of `scale`: [`fixed_point_lsb`] of a
/// 16-bit code's worth of its range, so that the frame's ±32767 counts span
/// 1.5 × the range whatever the chip's code width. For a 16-bit chip that is
/// `fixed_point_lsb(si_per_lsb)`; for the ICM-42688-P's 20-bit FIFO values
/// the frame's counts are coarser than the chip's (the batch frame keeps
/// its 16-bit layout: data frames, f32, carry the finer resolution).
pub fn triad_lsb(scale: &TriadScale) -> f32 {
    let per_16_bit_code = f64::from(scale.codes.magnitude) / f64::from(CodeRange::I16.magnitude);
    fixed_point_lsb(scale.si_per_lsb * per_16_bit_code.max(1.0))
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

/// The bits of `MAX_COUNTS as f32`: for a non-NaN f32, |v| > MAX_COUNTS
/// exactly when its bits without the sign exceed these (IEEE order).
const LIMIT_BITS: u32 = 0x46FF_FE00;

/// Added to an f32's bits `b`, sets bit 31 of `(b + OVER) ^ b` exactly when
/// |v| > MAX_COUNTS: for b ≥ 0 the sum reaches 2³¹ exactly when b >
/// LIMIT_BITS; for a negative v the sign bit of b is set and the sum's bit 31
/// flips (carry out) exactly then, so the XOR with b leaves it set.
const OVER: u32 = 0x7FFF_FFFF - LIMIT_BITS;

/// The fast path holds when every corrected value is below this in counts,
/// for any i16 input: then the magic rounding is exact (|v| < 2²²).
const FAST_RANGE: f64 = 4_194_303.0;

/// The f32 evaluation of a row is within a relative 2⁻²⁰ of its exact value
/// (four roundings of at most 2⁻²⁴ each, seven with a g-sensitivity's
/// accelerometer terms, of terms bounded by the bound), so
/// a bound times this that is still within ±MAX_COUNTS proves no clip.
const EVALUATION_MARGIN: f64 = 1.0 + 1.0 / (1u32 << 20) as f64;

/// One triad's K and k scaled to counts; for the gyro with a g-sensitivity
/// also C, on the raw accelerometer sample (and k then is k_g + c).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ScaledTriad {
    k: [[f32; 3]; 3],
    offset: [f32; 3],
    cross: Option<[[f32; 3]; 3]>,
}

impl ScaledTriad {
    fn new(corrector: &Corrector, triad: Triad, lsb: f32) -> Self {
        let (k, offset) = corrector.folded_f32(triad);
        let per_lsb = 1.0 / lsb;
        let scaled = |m: [[f32; 3]; 3]| m.map(|row| row.map(|c| c * per_lsb));
        let (offset, cross) = match (triad, corrector.g_sensitivity_f32()) {
            (Triad::Gyro, Some((c, whole_offset))) => (whole_offset, Some(scaled(c))),
            _ => (offset, None),
        };
        ScaledTriad {
            k: scaled(k),
            offset: offset.map(|c| c * per_lsb),
            cross,
        }
    }

    /// The largest |value| any input within `max_input` can give, times
    /// [`EVALUATION_MARGIN`]: |k_i| + M·Σ_j |K_ij| bounds row i exactly
    /// (in f64, exact for these f32 terms up to one rounding), and the margin
    /// covers the f32 evaluation. NaN or infinite for non-finite coefficients.
    fn max_counts(&self, max_input: f64) -> f64 {
        let cross = self.cross.unwrap_or([[0.0; 3]; 3]);
        let rows = self
            .k
            .iter()
            .zip(cross)
            .zip(self.offset)
            .map(|((row, c), o)| {
                let k = row.map(|c| f64::from(c).abs());
                let c = c.map(|c| f64::from(c).abs());
                f64::from(o).abs() + max_input * (k[0] + k[1] + k[2] + c[0] + c[1] + c[2])
            });
        rows.fold(0.0, |m: f64, b| if b > m || b.is_nan() { b } else { m }) * EVALUATION_MARGIN
    }

    /// Whether every corrected value of any i16 input is below
    /// [`FAST_RANGE`] in magnitude (false for non-finite coefficients).
    fn fits_fast_path(&self) -> bool {
        self.max_counts(32768.0) < FAST_RANGE
    }

    /// Whether no i16 input can give a value beyond ±[`MAX_COUNTS`]: the
    /// usual case, as the frame's LSB leaves room beyond the chip's range.
    fn never_clips(&self) -> bool {
        self.max_counts(32768.0) <= f64::from(MAX_COUNTS)
    }

    /// One raw triad to counts, in the f32 kernel's order (offset first,
    /// then the three products, left to right, then with a g-sensitivity
    /// the three of the raw accelerometer sample `accel`); true when a value
    /// clipped. Exact for every finite input (the reference form of [`Self::pass`]).
    #[inline(always)]
    fn apply(&self, raw: &[i32; 3], accel: &[i32; 3], out: &mut [i16]) -> bool {
        let x = counts_f32(raw);
        let a = counts_f32(accel);
        let cross = self.cross.unwrap_or([[0.0; 3]; 3]);
        let mut clipped = false;
        for (((row, c), offset), slot) in self
            .k
            .iter()
            .zip(cross)
            .zip(self.offset)
            .zip(out.iter_mut())
        {
            let v = offset + row[0] * x[0] + row[1] * x[1] + row[2] * x[2];
            let v = match self.cross {
                None => v,
                Some(_) => v + c[0] * a[0] + c[1] * a[1] + c[2] * a[2],
            };
            let (counts, clip) = counts_of_scaled(v);
            *slot = counts;
            clipped |= clip;
        }
        clipped
    }

    /// This triad of every sample of `raw` to counts at `out[i][AT..AT + 3]`
    /// (AT = 0: the accelerometer, 3: the gyroscope), with the triad's clip
    /// flag: one pass per triad, so that the 12 coefficients stay in
    /// registers. Every value is computed as [`Self::apply`] computes it;
    /// the rounding and the flags are integer operations on the f32's bits,
    /// without branches, which give apply's results when
    /// [`Self::fits_fast_path`]:
    /// - no value is NaN: the coefficients are finite (fits_fast_path), the
    ///   inputs are i16, and no sum of such products overflows f32;
    /// - |v| < 2²², so the bits of v + ROUND_MAGIC are MAGIC_BITS plus v
    ///   rounded to the nearest integer, ties to even (counts_of_scaled's
    ///   rounding); MAGIC_BITS' low half is zero, so the low 16 bits of
    ///   those bits are the count's whenever it is within ±MAX_COUNTS;
    /// - the flag of a value beyond ±MAX_COUNTS is exact, from its bits
    ///   (see [`OVER`]), and only then can a count be out of range: a pass
    ///   with such a value is redone by `apply`, which clips (a batch that
    ///   clips costs two passes; one that does not, one).
    ///
    /// Without `CHECK` the range test is left out: only for a triad that
    /// [`Self::never_clips`]. With `CROSS` (the gyro with a g-sensitivity)
    /// each row adds C's three products on the raw accelerometer sample.
    #[inline(always)]
    fn pass<const AT: usize, const CHECK: bool, const CROSS: bool>(
        &self,
        raw: &[RawSample],
        out: &mut [[i16; 6]],
    ) -> bool {
        let [[k00, k01, k02], [k10, k11, k12], [k20, k21, k22]] = self.k;
        let [[c00, c01, c02], [c10, c11, c12], [c20, c21, c22]] =
            self.cross.unwrap_or([[0.0; 3]; 3]);
        let [o0, o1, o2] = self.offset;
        // A raw axis at a limit code (see at_limit in corrector.rs); bit 31
        // of `over`: a value beyond ±MAX_COUNTS.
        let (mut limit, mut over) = (LimitCodes::start(), 0u32);
        for (r, o) in raw.iter().zip(out.iter_mut()) {
            let a = if AT == 0 { &r.accel } else { &r.gyro };
            let [a0, a1, a2] = *a;
            limit.add(*a);
            let (x0, x1, x2) = (a0 as f32, a1 as f32, a2 as f32);
            let mut v = [
                o0 + k00 * x0 + k01 * x1 + k02 * x2,
                o1 + k10 * x0 + k11 * x1 + k12 * x2,
                o2 + k20 * x0 + k21 * x1 + k22 * x2,
            ];
            if CROSS {
                let y = counts_f32(&r.accel);
                v = [
                    v[0] + c00 * y[0] + c01 * y[1] + c02 * y[2],
                    v[1] + c10 * y[0] + c11 * y[1] + c12 * y[2],
                    v[2] + c20 * y[0] + c21 * y[1] + c22 * y[2],
                ];
            }
            for (slot, v) in o[AT..AT + 3].iter_mut().zip(v) {
                if CHECK {
                    let b = v.to_bits();
                    over |= b.wrapping_add(OVER) ^ b;
                }
                *slot = (v + ROUND_MAGIC).to_bits() as i16;
            }
        }
        if over >> 31 != 0 {
            for (r, o) in raw.iter().zip(out.iter_mut()) {
                let x = if AT == 0 { &r.accel } else { &r.gyro };
                self.apply(x, &r.accel, &mut o[AT..AT + 3]);
            }
            return true;
        }
        limit.any()
    }
}

/// The loop of a kernel, chosen once at construction from its coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Path {
    /// No input can clip a value ([`ScaledTriad::never_clips`]): one pass
    /// per triad, the flags from the raw limit codes only (on the
    /// Cortex-M4F one loop for both triads: src/model/fused_pass.rs).
    NeverClips,
    /// One pass per triad with the exact range test.
    Fast,
    /// Sample by sample (values may reach 2²²: the magic rounding fails).
    Exact,
}

/// A corrector's f32 kernel scaled to a batch frame's counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BatchKernel {
    accel: ScaledTriad,
    gyro: ScaledTriad,
    accel_lsb: f32,
    gyro_lsb: f32,
    /// Which loop [`BatchKernel::correct`] runs.
    path: Path,
    /// The accelerometer's and the gyroscope's codes, for the clip flags.
    codes: [CodeRange; 2],
    /// Both triads' coefficients for the Cortex-M4F's loop ([`Path::NeverClips`]).
    #[cfg(triad_fpu)]
    fused: FusedPass,
}

impl BatchKernel {
    /// The kernel of `corrector` as currently folded, to counts of the
    /// batch frame's LSBs for the corrector's chip scale.
    pub fn new(corrector: &Corrector) -> Self {
        let scale = corrector.scale();
        let accel_lsb = triad_lsb(&scale.accel);
        let gyro_lsb = triad_lsb(&scale.gyro);
        let accel = ScaledTriad::new(corrector, Triad::Accel, accel_lsb);
        let gyro = ScaledTriad::new(corrector, Triad::Gyro, gyro_lsb);
        let codes = [scale.accel.codes, scale.gyro.codes];
        BatchKernel {
            accel,
            gyro,
            accel_lsb,
            gyro_lsb,
            codes,
            #[cfg(triad_fpu)]
            fused: FusedPass::new((accel.k, accel.offset), (gyro.k, gyro.offset), gyro.cross),
            // The passes' range proofs and limit-code test are a 16-bit
            // chip's: wider codes (the 20-bit FIFO) go sample by sample.
            path: if codes != [CodeRange::I16; 2] {
                Path::Exact
            } else if accel.never_clips() && gyro.never_clips() {
                Path::NeverClips
            } else if accel.fits_fast_path() && gyro.fits_fast_path() {
                Path::Fast
            } else {
                Path::Exact
            },
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
    ///
    /// Not inlined on the Cortex-M4F: it runs once per FIFO batch, and
    /// inlined into a caller's loop the passes' coefficients would stay live
    /// around its loop (which uses s0-s29) and be reloaded at each call.
    #[cfg_attr(triad_fpu, inline(never))]
    pub fn correct(&self, raw: &[RawSample], out: &mut [[i16; 6]]) -> ClipFlags {
        let cross = self.gyro.cross.is_some();
        match self.path {
            #[cfg(triad_fpu)]
            Path::NeverClips => self.fused.correct(raw, out),
            #[cfg(not(triad_fpu))]
            Path::NeverClips => ClipFlags {
                accel: self.accel.pass::<0, false, false>(raw, out),
                gyro: if cross {
                    self.gyro.pass::<3, false, true>(raw, out)
                } else {
                    self.gyro.pass::<3, false, false>(raw, out)
                },
            },
            Path::Fast => ClipFlags {
                accel: self.accel.pass::<0, true, false>(raw, out),
                gyro: if cross {
                    self.gyro.pass::<3, true, true>(raw, out)
                } else {
                    self.gyro.pass::<3, true, false>(raw, out)
                },
            },
            Path::Exact => self.correct_each(raw, out),
        }
    }

    /// [`Self::correct`] sample by sample, exact for any finite
    /// coefficients: for kernels beyond the fast path's range.
    fn correct_each(&self, raw: &[RawSample], out: &mut [[i16; 6]]) -> ClipFlags {
        let mut clip = ClipFlags::default();
        for (r, o) in raw.iter().zip(out.iter_mut()) {
            let (accel_out, gyro_out) = o.split_at_mut(3);
            let at_limit = ClipFlags {
                accel: self.codes[0].at_limit(&r.accel),
                gyro: self.codes[1].at_limit(&r.gyro),
            };
            clip.accel |= self.accel.apply(&r.accel, &r.accel, accel_out) | at_limit.accel;
            clip.gyro |= self.gyro.apply(&r.gyro, &r.accel, gyro_out) | at_limit.gyro;
        }
        clip
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triad(k: f32, offset: f32) -> ScaledTriad {
        ScaledTriad {
            k: [[k, 0.1, -0.2], [0.05, k, 0.3], [-0.1, 0.2, k]],
            offset: [offset, -offset, 0.5 * offset],
            cross: None,
        }
    }

    fn kernel(accel: ScaledTriad) -> BatchKernel {
        BatchKernel {
            accel,
            gyro: triad(0.6, 3.0),
            accel_lsb: 1.0,
            gyro_lsb: 1.0,
            path: Path::Exact,
            codes: [CodeRange::I16; 2],
        }
    }

    /// Each path on its own kernel gives, sample by sample, what `apply`
    /// gives (the naive loop), flags included: the paths are chosen by the
    /// coefficients' range, not by what they compute.
    #[test]
    fn every_path_computes_what_apply_computes() {
        let raw: [RawSample; 40] = core::array::from_fn(|n| {
            let n = n as i32;
            let x = |m: i32| (n * 7919 + m * 104_729) % 65_536 - 32_768;
            RawSample {
                accel: [x(1), x(2), if n == 9 { -32768 } else { x(3) }],
                gyro: [x(4), x(5), x(6)],
                temperature: 0,
            }
        });
        let cases = [
            (triad(0.6, 3.0), Path::NeverClips),
            (triad(1.5, 40.0), Path::Fast),
            (triad(200.0, 1e6), Path::Exact),
        ];
        for (n, (accel, path)) in cases.into_iter().chain(cases).enumerate() {
            let mut k = kernel(accel);
            // The second time round with a g-sensitivity's accelerometer terms.
            if n >= cases.len() {
                k.gyro.cross = Some([[1e-3, -2e-4, 5e-4], [3e-4, 2e-3, 0.0], [-1e-4, 0.0, 1e-3]]);
            }
            let chosen = [
                (accel.never_clips(), Path::NeverClips),
                (accel.fits_fast_path(), Path::Fast),
            ]
            .into_iter()
            .find_map(|(holds, p)| holds.then_some(p))
            .unwrap_or(Path::Exact);
            assert_eq!(chosen, path);
            k.path = path;
            let mut fast = [[0i16; 6]; 40];
            let mut naive = fast;
            for w in [1, 8, 32] {
                for (r, (f, n)) in raw
                    .chunks(w)
                    .zip(fast.chunks_mut(w).zip(naive.chunks_mut(w)))
                {
                    let got = k.correct(r, f);
                    assert_eq!(got, k.correct_each(r, n), "{path:?} W={w}");
                }
                assert_eq!(fast, naive, "{path:?} W={w}");
            }
        }
    }
}
