//! The integer-only hot path, for cores without an FPU.
//!
//! Outputs are i32 fixed point in SI units, with F fraction bits per quantity:
//! accelerometer Q16.16 m/s² (quantum 1.5e−5 m/s², range ±32768 m/s²),
//! gyroscope Q12.20 rad/s (quantum 9.5e−7 rad/s, range ±2048 rad/s),
//! temperature Q16.16 °C. The gyro gets more fraction bits because its finest
//! ranges are fine indeed: a 16-bit gyro at ±15.625 °/s (ICM-42688-P) has
//! 8.3e−6 rad/s per LSB, below the Q16.16 quantum; 20 (not more) so that the
//! 32-bit form below holds every valid calibration of a ±2000 °/s gyro.
//!
//! Two forms compute the same correction. Where the coefficients allow (every
//! valid calibration of the chips' usual ranges) the 32-bit form of
//! [`super::fixed_narrow`] is used: only i32 products, one MULS each on a
//! Cortex-M0. Elsewhere (very wide ranges with extreme corrections) the i64
//! form of this module, whose proof follows. [`FixedCorrector::error_bound`]
//! gives the bound of the form in use; both are ≤ 0.5 LSB.
//!
//! The i64 form.
//! Per triad, K and k from the f64 fold are scaled by 2^S and rounded:
//! K_q = round(K·2^S) in i32, k_q = round(k·2^S) + 2^(S−F−1) in i64 (the added
//! half output quantum turns the final arithmetic shift, a floor, into
//! round-half-up). Then, with i64 products and sums,
//!
//! ```text
//! out_i = (Σ_j K_q[i][j]·raw_j + k_q[i]) >> (S − F).
//! ```
//!
//! S is the largest value in F+1..=F+31 with max|K_q| ≤ 2³⁰, so the
//! coefficients keep 29..30 significant bits and the shift is 1..=31 (a
//! 32-bit funnel shift of the two halves). The input is a chip's count,
//! |raw_j| ≤ M, its [`CodeRange::magnitude`]: M = 2¹⁵ for a 16-bit chip,
//! 2¹⁹ for the ICM-42688-P's 20-bit FIFO values. No overflow for any input
//! up to M ≤ 2¹⁹ (construction refuses a larger M): each product is ≤
//! 2³⁰·2¹⁹ = 2⁴⁹, three of them ≤ 1.5·2⁵⁰, and |k_q| is checked ≤ 2⁶¹ at
//! construction, so the sum stays below 2⁶²; construction also checks that
//! the largest possible result (with M) fits i32 after the shift.
//!
//! Error against the exact K·raw + k, in SI units (proof):
//! - coefficient rounding: |K_q − K·2^S| ≤ ½ and |k_q − k·2^S − 2^(S−F−1)| ≤ ½,
//!   so the sum is off by ≤ ½·(Σ|raw_j| + 1) ≤ ½·(3·M + 1) quanta 2⁻ˢ;
//! - the final rounding: ≤ ½ output quantum = 2^−(F+1).
//!
//! So |error| ≤ 2^−(F+1) + (3·M + 1)·2^−(S+1)
//! ([`FixedCorrector::error_bound`]). As max|K|·2^S > 2²⁹ (unless S is at its
//! cap), the second term is below 1.5·M·2⁻²⁹·max|K| (9.2e−5·max|K| for
//! M = 2¹⁵, 1.5e−3·max|K| for M = 2¹⁹), and max|K| ≤ 3.4 LSB-worth for a
//! valid calibration (‖(I+Σ)⁻¹‖ ≤ 1/0.3), so it is below 3.2e−4 LSB (16-bit)
//! or 5.1e−3 LSB (20-bit).
//! The bound is therefore ≤ 0.5 LSB whenever the LSB is ≥ 2^−F·1.001: down to
//! 1.5e−5 m/s² for accelerometers (a 16-bit ±2 g one has 6e−4, the
//! ICM-42688-P's 20-bit FIFO value 3.0e−4) and 9.5e−7 rad/s for gyroscopes
//! (the 20-bit value: 6.7e−5). tests/model_fixed.rs asserts it for every
//! range and for the 20-bit FIFO's scale.
//!
//! The 32-bit form of [`super::fixed_narrow`] holds only 16-bit inputs
//! (M ≤ 2¹⁵: its products would overflow i32 beyond); the 20-bit FIFO's
//! values always take this i64 form. On a Cortex-M4F that is one SMLAL per
//! product; the firmware's hot path is the f32 corrector anyway, whose f32
//! conversion of a 20-bit count is exact.
//!
//! A g-sensitivity adds the accelerometer's contribution C·raw_a + c to the
//! gyro's rate ([`super::g_sensitivity`]). It is a second set of rows on the
//! raw accelerometer sample with the gyro's output format (Q12.20), in
//! whichever form fits, and the two i32 outputs are added: construction
//! checks that the largest possible sum fits i32, and the error bound is the
//! sum of the two rows' bounds (each rounds once at its own shift), ≤ one
//! Q12.20 quantum (9.5e−7 rad/s) plus the coefficient terms.

use super::corrector::{ClipFlags, Corrector, ReferenceSample};
use super::fixed_narrow::NarrowRows;
use super::fold::FoldedTriad;
use super::validate::CalibrationError;
use crate::sensor::{CodeRange, RawSample};

/// Fraction bits of the accelerometer output: Q16.16 m/s².
pub const ACCEL_FRACTION_BITS: u32 = 16;
/// Fraction bits of the gyroscope output: Q12.20 rad/s.
pub const GYRO_FRACTION_BITS: u32 = 20;
/// Fraction bits of the temperature output: Q16.16 °C.
pub const TEMPERATURE_FRACTION_BITS: u32 = 16;

/// One corrected sample in fixed-point SI units (value = field / 2^F).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedSample {
    /// Specific force, Q16.16 m/s² ([`ACCEL_FRACTION_BITS`]).
    pub accel: [i32; 3],
    /// Angular rate, Q12.20 rad/s ([`GYRO_FRACTION_BITS`]).
    pub gyro: [i32; 3],
    /// Die temperature, Q16.16 °C ([`TEMPERATURE_FRACTION_BITS`]).
    pub temperature: i32,
    /// Clipped triads.
    pub clip: ClipFlags,
}

impl FixedSample {
    /// The same values in f64 SI units (exact: an i32 / 2^F fits f64).
    pub fn to_f64(&self) -> ReferenceSample {
        let f = |v: &[i32; 3], bits| {
            [
                q_to_f64(v[0], bits),
                q_to_f64(v[1], bits),
                q_to_f64(v[2], bits),
            ]
        };
        ReferenceSample {
            accel: f(&self.accel, ACCEL_FRACTION_BITS),
            gyro: f(&self.gyro, GYRO_FRACTION_BITS),
            temperature: q_to_f64(self.temperature, TEMPERATURE_FRACTION_BITS),
            clip: self.clip,
        }
    }
}

fn q_to_f64(q: i32, fraction_bits: u32) -> f64 {
    f64::from(q) / f64::from(1u32 << fraction_bits)
}

/// `x <= limit`, false for NaN.
fn at_most(x: f64, limit: f64) -> bool {
    x <= limit
}

/// 2^e as f64 (exact).
pub(super) fn pow2(e: i32) -> f64 {
    libm::ldexp(1.0, e)
}

/// Largest input magnitude the i64 form proves its bounds for (module doc).
const MAX_INPUT_MAGNITUDE: u32 = 1 << 19;

/// One triad (or the temperature row) in fixed point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct FixedRows<const N: usize> {
    k: [[i32; N]; N],
    offset: [i64; N],
    /// S − F, in 1..=31.
    shift: u32,
    /// F, the output's fraction bits.
    fraction_bits: u32,
    /// M, the largest |input| (module doc).
    max_input: u32,
}

impl<const N: usize> FixedRows<N> {
    /// Scales and rounds `k` (N×N) and `offset` as the module doc says, for
    /// inputs up to `max_input` in magnitude.
    fn new(
        quantity: &'static str,
        fraction_bits: u32,
        k: &[[f64; N]; N],
        offset: &[f64; N],
        max_input: u32,
    ) -> Result<Self, CalibrationError> {
        let f = fraction_bits as i32;
        let max_k = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let max_raw = f64::from(max_input);
        let range_error = |max_output: f64| CalibrationError::FixedPointRange {
            quantity,
            max_output,
        };
        // Largest S in F+1..=F+31 with max|K|·2^S ≤ 2³⁰.
        let mut s = f + 31;
        while s > f + 1 && max_k * pow2(s) > pow2(30) {
            s -= 1;
        }
        let scale = pow2(s);
        if max_input > MAX_INPUT_MAGNITUDE || !at_most(max_k * scale, pow2(30)) {
            return Err(range_error(max_k * max_raw * N as f64));
        }
        let mut k_q = [[0i32; N]; N];
        for (q_row, row) in k_q.iter_mut().zip(k.iter()) {
            for (q, &x) in q_row.iter_mut().zip(row.iter()) {
                *q = libm::round(x * scale) as i32;
            }
        }
        let half = pow2(s - f - 1);
        let mut offset_q = [0i64; N];
        for ((q, &o), k_row) in offset_q.iter_mut().zip(offset.iter()).zip(k_q.iter()) {
            let scaled = libm::round(o * scale);
            // Largest |sum| before the shift, then in output quanta.
            let max_sum = k_row
                .iter()
                .map(|&x| f64::from(x).abs() * max_raw)
                .sum::<f64>()
                + scaled.abs()
                + half;
            let max_output = max_sum / pow2(s - f);
            if !at_most(scaled.abs(), pow2(61)) || !at_most(max_output, 2_147_483_646.0) {
                return Err(range_error(max_output / pow2(f)));
            }
            *q = scaled as i64 + half as i64;
        }
        Ok(FixedRows {
            k: k_q,
            offset: offset_q,
            shift: (s - f) as u32,
            fraction_bits,
            max_input,
        })
    }

    /// The proven bound on |fixed − exact| in SI units (module doc).
    fn error_bound(&self) -> f64 {
        let f = self.fraction_bits as i32;
        let s = self.shift as i32 + f;
        pow2(-f - 1) + (N as f64 * f64::from(self.max_input) + 1.0) * pow2(-s - 1)
    }
}

/// `(acc >> shift) as i32` for 1 ≤ shift ≤ 31 when the result fits i32 (which
/// construction proves): only the low word of the shifted value is needed, so
/// it is a funnel shift of the two halves, 3 instructions on a Cortex-M.
#[inline(always)]
fn shift_to_i32(acc: i64, shift: u32) -> i32 {
    let (lo, hi) = (acc as u32, (acc >> 32) as u32);
    ((lo >> shift) | (hi << (32 - shift))) as i32
}

impl FixedRows<3> {
    #[inline(always)]
    fn apply(&self, x: &[i32; 3]) -> [i32; 3] {
        let (x0, x1, x2) = (i64::from(x[0]), i64::from(x[1]), i64::from(x[2]));
        let row = |k: &[i32; 3], o: i64| {
            // The module doc proves |sum| < 2⁶² and that the shifted value
            // fits i32, for inputs within the triad's magnitude.
            let acc = o + i64::from(k[0]) * x0 + i64::from(k[1]) * x1 + i64::from(k[2]) * x2;
            shift_to_i32(acc, self.shift)
        };
        [
            row(&self.k[0], self.offset[0]),
            row(&self.k[1], self.offset[1]),
            row(&self.k[2], self.offset[2]),
        ]
    }
}

/// The integer-only corrector, built from a [`Corrector`]'s folded f64
/// coefficients (rebuild it after a [`Corrector::refold`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FixedCorrector {
    accel: Form<3>,
    gyro: Form<3>,
    /// C·raw_a + c in Q12.20, with a g-sensitivity.
    g_sensitivity: Option<Form<3>>,
    temperature: Form<1>,
    /// The accelerometer's and the gyroscope's codes, for the clip flags.
    codes: [CodeRange; 2],
}

/// One triad (or the temperature row) in the 32-bit form where it fits
/// ([`super::fixed_narrow`]), else in the i64 form of this module.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form<const N: usize> {
    Narrow(NarrowRows<N>),
    Wide(FixedRows<N>),
}

impl<const N: usize> Form<N> {
    fn new(
        quantity: &'static str,
        fraction_bits: u32,
        k: &[[f64; N]; N],
        offset: &[f64; N],
        max_input: u32,
    ) -> Result<Self, CalibrationError> {
        match NarrowRows::new(fraction_bits, k, offset, max_input) {
            Some(narrow) => Ok(Form::Narrow(narrow)),
            None => Ok(Form::Wide(FixedRows::new(
                quantity,
                fraction_bits,
                k,
                offset,
                max_input,
            )?)),
        }
    }

    fn error_bound(&self) -> f64 {
        match self {
            Form::Narrow(n) => n.error_bound(),
            Form::Wide(w) => w.error_bound(),
        }
    }

    fn is_narrow(&self) -> bool {
        matches!(self, Form::Narrow(_))
    }
}

impl Form<3> {
    #[inline(always)]
    fn apply(&self, x: &[i32; 3]) -> [i32; 3] {
        match self {
            Form::Narrow(n) => n.apply(x),
            Form::Wide(w) => w.apply(x),
        }
    }
}

impl Form<1> {
    #[inline(always)]
    fn apply_one(&self, x: i16) -> i32 {
        match self {
            Form::Narrow(n) => n.apply_one(x),
            Form::Wide(w) => {
                shift_to_i32(w.offset[0] + i64::from(w.k[0][0]) * i64::from(x), w.shift)
            }
        }
    }
}

impl FixedCorrector {
    /// Quantises the corrector's current K, k and temperature scale.
    pub fn new(corrector: &Corrector) -> Result<FixedCorrector, CalibrationError> {
        use super::calibration::Triad;
        let scale = corrector.scale();
        let (accel_max, gyro_max) = (scale.accel.codes.magnitude, scale.gyro.codes.magnitude);
        let rows = |quantity, bits, f: &FoldedTriad, max_input| {
            Form::new(quantity, bits, &f.k, &f.offset, max_input)
        };
        let gyro = corrector.folded(Triad::Gyro);
        let g_sensitivity = match corrector.folded_g_sensitivity() {
            None => None,
            Some(cross) => Some(g_sensitivity_rows(gyro, &cross, gyro_max, accel_max)?),
        };
        Ok(FixedCorrector {
            accel: rows(
                "accel",
                ACCEL_FRACTION_BITS,
                corrector.folded(Triad::Accel),
                accel_max,
            )?,
            gyro: rows("gyro", GYRO_FRACTION_BITS, gyro, gyro_max)?,
            g_sensitivity,
            // The temperature is an i16 register reading on every chip.
            temperature: Form::new(
                "temperature",
                TEMPERATURE_FRACTION_BITS,
                &[[scale.temperature_per_lsb]],
                &[scale.temperature_offset],
                CodeRange::I16.magnitude,
            )?,
            codes: [scale.accel.codes, scale.gyro.codes],
        })
    }

    /// The gyro's rate: its rows on the raw gyro sample, plus with a
    /// g-sensitivity the accelerometer's contribution (whose sum
    /// construction proved to fit i32).
    #[inline(always)]
    fn gyro_rate(&self, raw: &RawSample) -> [i32; 3] {
        let rate = self.gyro.apply(&raw.gyro);
        match &self.g_sensitivity {
            None => rate,
            Some(cross) => {
                let c = cross.apply(&raw.accel);
                [
                    rate[0].wrapping_add(c[0]),
                    rate[1].wrapping_add(c[1]),
                    rate[2].wrapping_add(c[2]),
                ]
            }
        }
    }

    /// The integer hot path: fixed-point SI outputs and clip flags.
    #[inline]
    pub fn correct(&self, raw: &RawSample) -> FixedSample {
        FixedSample {
            accel: self.accel.apply(&raw.accel),
            gyro: self.gyro_rate(raw),
            temperature: self.temperature.apply_one(raw.temperature),
            clip: self.clip_flags(raw),
        }
    }

    /// The clip flags of `raw` ([`ClipFlags::of`] with the triads' codes).
    #[inline(always)]
    fn clip_flags(&self, raw: &RawSample) -> ClipFlags {
        ClipFlags {
            accel: self.codes[0].at_limit(&raw.accel),
            gyro: self.codes[1].at_limit(&raw.gyro),
        }
    }

    /// [`Self::correct`] of each sample of `raw` into the front of `out` (as
    /// many as both hold), with the choice of form made once for the batch
    /// rather than per sample and triad.
    pub fn correct_batch(&self, raw: &[RawSample], out: &mut [FixedSample]) {
        match (
            &self.accel,
            &self.gyro,
            &self.temperature,
            &self.g_sensitivity,
        ) {
            (Form::Narrow(accel), Form::Narrow(gyro), Form::Narrow(temperature), None) => {
                for (r, o) in raw.iter().zip(out.iter_mut()) {
                    *o = FixedSample {
                        accel: accel.apply(&r.accel),
                        gyro: gyro.apply(&r.gyro),
                        temperature: temperature.apply_one(r.temperature),
                        clip: self.clip_flags(r),
                    };
                }
            }
            _ => {
                for (r, o) in raw.iter().zip(out.iter_mut()) {
                    *o = self.correct(r);
                }
            }
        }
    }

    /// Per output `[accel, gyro, temperature]`: true where the 32-bit form
    /// ([`super::fixed_narrow`]) is in use (for the gyro with a g-sensitivity:
    /// for both its sets of rows), false for the i64 form.
    pub fn uses_32_bit_products(&self) -> [bool; 3] {
        [
            self.accel.is_narrow(),
            self.gyro.is_narrow() && self.g_sensitivity.as_ref().is_none_or(Form::is_narrow),
            self.temperature.is_narrow(),
        ]
    }

    /// The proven bound on |fixed − exact| in SI units for every input, per
    /// output `[accel, gyro, temperature]`: for the i64 form
    /// 2^−(F+1) + (N·M + 1)·2^−(S+1), for the 32-bit form the sum in
    /// [`super::fixed_narrow`]; with a g-sensitivity the gyro's adds the
    /// bound of its accelerometer rows.
    pub fn error_bound(&self) -> [f64; 3] {
        [
            self.accel.error_bound(),
            self.gyro.error_bound() + self.g_sensitivity.as_ref().map_or(0.0, Form::error_bound),
            self.temperature.error_bound(),
        ]
    }
}

/// The rows of a g-sensitivity's contribution `cross` (C·raw_a + c) in the
/// gyro's output format, after checking that their outputs and the gyro's
/// (`gyro`) add up within i32 for any input. Out of line, so that a
/// calibration without G does not carry its frame.
#[inline(never)]
fn g_sensitivity_rows(
    gyro: &FoldedTriad,
    cross: &FoldedTriad,
    gyro_max: u32,
    accel_max: u32,
) -> Result<Form<3>, CalibrationError> {
    let largest = |f: &FoldedTriad, i: usize, max_input: u32| {
        f.k[i]
            .iter()
            .map(|x| x.abs() * f64::from(max_input))
            .sum::<f64>()
            + f.offset[i].abs()
    };
    let max_output = (0..3)
        .map(|i| largest(gyro, i, gyro_max) + largest(cross, i, accel_max))
        .fold(0.0f64, f64::max);
    // Each row's output is within one quantum of its exact value.
    if !at_most(
        max_output * pow2(GYRO_FRACTION_BITS as i32) + 2.0,
        2_147_483_647.0,
    ) {
        return Err(CalibrationError::FixedPointRange {
            quantity: "gyro",
            max_output,
        });
    }
    Form::new(
        "gyro g-sensitivity",
        GYRO_FRACTION_BITS,
        &cross.k,
        &cross.offset,
        accel_max,
    )
}

impl Corrector {
    /// The fixed-point form of the current fold.
    pub fn to_fixed(&self) -> Result<FixedCorrector, CalibrationError> {
        FixedCorrector::new(self)
    }
}
