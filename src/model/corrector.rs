//! The corrector: a validated calibration, inverted in f64 once, folded with
//! the chip's sensitivity and the mounting orientation into the f32 hot path
//! m = K·raw + k, with the f64 reference beside it. With a g-sensitivity G
//! the gyro's row also reads the raw accelerometer sample
//! ([`super::g_sensitivity`]): one 3×6 map.

use super::calibration::{Calibration, Triad, TriadCalibration};
use super::fold::FoldedTriad;
use super::g_sensitivity;
use super::matrix::{self, Mat3};
use super::orientation::Orientation;
use super::validate::{
    positive_finite, validate_g_sensitivity, validate_triad, CalibrationError, TEMPERATURE_RANGE_C,
};
use crate::sensor::{CodeRange, ImuScale, RawSample, TriadScale};

/// Which triads had a raw axis at the chip's limit code (for a 16-bit
/// chip i16::MIN or i16::MAX; each triad's [`CodeRange`]). The off-diagonal
/// terms spread a clipped axis into the others, so the whole corrected
/// triad is suspect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClipFlags {
    /// An accelerometer axis is at its limit.
    pub accel: bool,
    /// A gyroscope axis is at its limit.
    pub gyro: bool,
}

impl ClipFlags {
    /// Flags of a raw sample from a chip of `scale`.
    #[inline(always)]
    pub fn of(raw: &RawSample, scale: &ImuScale) -> ClipFlags {
        ClipFlags {
            accel: scale.accel.codes.at_limit(&raw.accel),
            gyro: scale.gyro.codes.at_limit(&raw.gyro),
        }
    }
}

/// Raw counts as f32: exact, as every chip's counts are below 2²⁴ in
/// magnitude (20 bits at most, [`crate::sensor::CodeRange`]).
#[inline(always)]
pub fn counts_f32(v: &[i32; 3]) -> [f32; 3] {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}

/// One corrected sample, f32, in the board's axes.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Specific force in m/s².
    pub accel: [f32; 3],
    /// Angular rate in rad/s.
    pub gyro: [f32; 3],
    /// Die temperature in °C.
    pub temperature: f32,
    /// Clipped triads.
    pub clip: ClipFlags,
}

/// One corrected sample from the f64 reference path.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ReferenceSample {
    /// Specific force in m/s².
    pub accel: [f64; 3],
    /// Angular rate in rad/s.
    pub gyro: [f64; 3],
    /// Die temperature in °C.
    pub temperature: f64,
    /// Clipped triads.
    pub clip: ClipFlags,
}

/// The f32 form of one triad's K and k.
#[derive(Clone, Copy, Debug, PartialEq)]
struct KernelF32 {
    k: [[f32; 3]; 3],
    offset: [f32; 3],
}

impl KernelF32 {
    /// Rounds the f64 coefficients to nearest f32 (relative error ≤ 2⁻²⁴ each).
    fn new(folded: &FoldedTriad) -> Self {
        let r = |row: &[f64; 3]| [row[0] as f32, row[1] as f32, row[2] as f32];
        KernelF32 {
            k: [r(&folded.k[0]), r(&folded.k[1]), r(&folded.k[2])],
            offset: r(&folded.offset),
        }
    }

    /// K·x + k, each row evaluated left to right: ((k + K0·x0) + K1·x1) + K2·x2,
    /// offset first so each row is three multiply-accumulates (VMLA.F32, which
    /// rounds the product and the sum separately, like the host's separate
    /// mul and add: the same bits on both). The error bound in
    /// tests/model_f32.rs depends on this order.
    #[inline(always)]
    fn apply(&self, x: [f32; 3]) -> [f32; 3] {
        let row = |k: &[f32; 3], o: f32| o + k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
        [
            row(&self.k[0], self.offset[0]),
            row(&self.k[1], self.offset[1]),
            row(&self.k[2], self.offset[2]),
        ]
    }
}

/// The gyro's f32 row with g-sensitivity: ω = o + K_g·raw_g + C·raw_a, with
/// o = k_g + c rounded once from f64 (see [`super::g_sensitivity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct GSensitivityState {
    /// C in f32 (rate per accelerometer LSB).
    k_accel: [[f32; 3]; 3],
    /// k_g + c in f32.
    offset: [f32; 3],
}

impl GSensitivityState {
    // Out of line: its f64 work would otherwise enlarge the stack frame of
    // every corrector's construction, with or without G (the Cortex-M0
    // benchmark's 16 KiB).
    #[inline(never)]
    fn new(
        g: &Mat3,
        gyro: &TriadState,
        accel: &TriadState,
        orientation: Orientation,
    ) -> Result<Self, CalibrationError> {
        let folded = g_sensitivity::fold(g, &gyro.matrix, &accel.folded, orientation).ok_or(
            CalibrationError::Singular {
                triad: Triad::Gyro,
                determinant: matrix::determinant(&gyro.matrix),
                temperature_c: None,
            },
        )?;
        let r = |row: &[f64; 3]| [row[0] as f32, row[1] as f32, row[2] as f32];
        let o = &gyro.folded.offset;
        Ok(GSensitivityState {
            k_accel: [r(&folded.k[0]), r(&folded.k[1]), r(&folded.k[2])],
            offset: r(&[
                o[0] + folded.offset[0],
                o[1] + folded.offset[1],
                o[2] + folded.offset[2],
            ]),
        })
    }

    /// o + K_g·g + C·a, each row left to right as [`KernelF32::apply`] does,
    /// the accelerometer's three products after the gyro's.
    #[inline(always)]
    fn apply(&self, k_gyro: &[[f32; 3]; 3], g: [f32; 3], a: [f32; 3]) -> [f32; 3] {
        let row = |k: &[f32; 3], c: &[f32; 3], o: f32| {
            o + k[0] * g[0] + k[1] * g[1] + k[2] * g[2] + c[0] * a[0] + c[1] * a[1] + c[2] * a[2]
        };
        [
            row(&k_gyro[0], &self.k_accel[0], self.offset[0]),
            row(&k_gyro[1], &self.k_accel[1], self.offset[1]),
            row(&k_gyro[2], &self.k_accel[2], self.offset[2]),
        ]
    }
}

/// One triad as currently folded: (I+Σ)(T), b(T) for the reference, K and k
/// in f64 and f32.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TriadState {
    matrix: Mat3,
    bias: [f64; 3],
    folded: FoldedTriad,
    kernel: KernelF32,
}

impl TriadState {
    fn new(
        triad: Triad,
        (matrix, bias): (Mat3, [f64; 3]),
        si_per_lsb: f64,
        orientation: Orientation,
    ) -> Result<Self, CalibrationError> {
        let folded = FoldedTriad::new(&matrix, &bias, si_per_lsb, orientation).ok_or(
            CalibrationError::Singular {
                triad,
                determinant: matrix::determinant(&matrix),
                temperature_c: None,
            },
        )?;
        Ok(TriadState {
            matrix,
            bias,
            folded,
            kernel: KernelF32::new(&folded),
        })
    }

    /// (I+Σ)⁻¹·(x − b) in the sensor's axes, by Gaussian elimination:
    /// independent of the fold.
    fn solve(&self, x: [f64; 3]) -> [f64; 3] {
        let d = [
            x[0] - self.bias[0],
            x[1] - self.bias[1],
            x[2] - self.bias[2],
        ];
        matrix::solve(&self.matrix, &d).unwrap_or([f64::NAN; 3])
    }
}

/// A validated calibration folded for one chip configuration and mounting.
#[derive(Clone, Debug, PartialEq)]
pub struct Corrector {
    calibration: Calibration,
    orientation: Orientation,
    scale: ImuScale,
    fold_temperature_c: Option<f64>,
    accel: TriadState,
    gyro: TriadState,
    g_sensitivity: Option<GSensitivityState>,
    temperature_scale: f32,
    temperature_offset: f32,
}

impl Corrector {
    /// Validates `cal` against the ranges in `scale`, inverts each (I+Σ) in
    /// f64 and folds sensitivity, orientation, (I+Σ)⁻¹ and b. Temperature
    /// terms start folded at their reference temperature (ΔT = 0).
    pub fn new(
        cal: &Calibration,
        scale: &ImuScale,
        orientation: Orientation,
    ) -> Result<Corrector, CalibrationError> {
        positive_finite("accel.si_per_lsb", scale.accel.si_per_lsb)?;
        positive_finite("gyro.si_per_lsb", scale.gyro.si_per_lsb)?;
        positive_finite("accel.full_scale", scale.accel.full_scale)?;
        positive_finite("gyro.full_scale", scale.gyro.full_scale)?;
        positive_finite("temperature_per_lsb", scale.temperature_per_lsb)?;
        if !scale.temperature_offset.is_finite() {
            return Err(CalibrationError::InvalidScale {
                quantity: "temperature_offset",
                value: scale.temperature_offset,
            });
        }
        validate_triad(Triad::Accel, &cal.accel, scale.accel.full_scale)?;
        validate_triad(Triad::Gyro, &cal.gyro, scale.gyro.full_scale)?;
        validate_g_sensitivity(cal.g_sensitivity.as_ref())?;
        let at_reference =
            |t: &TriadCalibration| t.at_temperature(t.temperature.map_or(0.0, |x| x.reference_c));
        let accel = TriadState::new(
            Triad::Accel,
            at_reference(&cal.accel),
            scale.accel.si_per_lsb,
            orientation,
        )?;
        let gyro = TriadState::new(
            Triad::Gyro,
            at_reference(&cal.gyro),
            scale.gyro.si_per_lsb,
            orientation,
        )?;
        let g_sensitivity = cal
            .g_sensitivity
            .map(|g| GSensitivityState::new(&g, &gyro, &accel, orientation))
            .transpose()?;
        Ok(Corrector {
            calibration: *cal,
            orientation,
            scale: *scale,
            fold_temperature_c: None,
            accel,
            gyro,
            g_sensitivity,
            temperature_scale: scale.temperature_per_lsb as f32,
            temperature_offset: scale.temperature_offset as f32,
        })
    }

    /// A corrector for inputs already in SI units (the host's `triad
    /// correct`): sensitivity 1, temperature passed through. The
    /// `*_full_scale` ranges (± SI units) bound the bias check. Use it with
    /// [`Corrector::correct_si`] and [`Corrector::reference_si`].
    pub fn new_si(
        cal: &Calibration,
        accel_full_scale: f64,
        gyro_full_scale: f64,
        orientation: Orientation,
    ) -> Result<Corrector, CalibrationError> {
        let scale = ImuScale {
            accel: TriadScale {
                si_per_lsb: 1.0,
                full_scale: accel_full_scale,
                codes: CodeRange::I16,
            },
            gyro: TriadScale {
                si_per_lsb: 1.0,
                full_scale: gyro_full_scale,
                codes: CodeRange::I16,
            },
            temperature_per_lsb: 1.0,
            temperature_offset: 0.0,
        };
        Corrector::new(cal, &scale, orientation)
    }

    /// The f32 hot path: m = K·raw + k per triad (the gyro's with C·raw_a
    /// too when the calibration has a g-sensitivity), temperature to °C, clip flags.
    ///
    /// Over many samples prefer [`Self::correct_batch`]: it chooses between
    /// the forms with and without G once, where a loop of this function's
    /// calls tests it per sample, which on a Cortex-M4F keeps the
    /// coefficients out of registers (about 40 instructions per sample more,
    /// docs/BENCHMARKS.md: full_f32 against full_f32_per_call).
    #[inline]
    pub fn correct(&self, raw: &RawSample) -> Sample {
        match &self.g_sensitivity {
            None => self.correct_without_g::<false>(raw),
            Some(s) => self.correct_with_g::<false>(s, raw),
        }
    }

    /// [`Self::correct`] of each sample of `raw` into the front of `out` (as
    /// many as both hold), with the choice of form made once for the batch:
    /// with or without G, and the clip flags' test (a 16-bit chip's limit
    /// codes have one of their own, three instructions per axis where a
    /// code range's takes four on the Cortex-M4F).
    pub fn correct_batch(&self, raw: &[RawSample], out: &mut [Sample]) {
        let narrow = [self.scale.accel.codes, self.scale.gyro.codes] == [CodeRange::I16; 2];
        match (&self.g_sensitivity, narrow) {
            (None, true) => self.batch_without_g::<true>(raw, out),
            (None, false) => self.batch_without_g::<false>(raw, out),
            (Some(s), true) => self.batch_with_g::<true>(s, raw, out),
            (Some(s), false) => self.batch_with_g::<false>(s, raw, out),
        }
    }

    /// The loop of [`Self::correct_batch`] without G, a function of its own
    /// so that its coefficients have the registers to themselves. The
    /// outputs lead the zip: led by the inputs, LLVM addresses each of the
    /// seven stores from a negative count (+8 instructions per sample on
    /// the Cortex-M4F).
    #[inline(never)]
    fn batch_without_g<const NARROW: bool>(&self, raw: &[RawSample], out: &mut [Sample]) {
        for (o, r) in out.iter_mut().zip(raw) {
            *o = self.correct_without_g::<NARROW>(r);
        }
    }

    /// The loop of [`Self::correct_batch`] with G.
    #[inline(never)]
    fn batch_with_g<const NARROW: bool>(
        &self,
        s: &GSensitivityState,
        raw: &[RawSample],
        out: &mut [Sample],
    ) {
        for (o, r) in out.iter_mut().zip(raw) {
            *o = self.correct_with_g::<NARROW>(s, r);
        }
    }

    /// The clip flags of `raw`; with `NARROW` (both triads' codes are
    /// [`CodeRange::I16`]) by the 16-bit test.
    #[inline(always)]
    fn clip_flags<const NARROW: bool>(&self, raw: &RawSample) -> ClipFlags {
        if NARROW {
            ClipFlags {
                accel: CodeRange::at_i16_limit(&raw.accel),
                gyro: CodeRange::at_i16_limit(&raw.gyro),
            }
        } else {
            ClipFlags::of(raw, &self.scale)
        }
    }

    #[inline(always)]
    fn correct_without_g<const NARROW: bool>(&self, raw: &RawSample) -> Sample {
        let f = counts_f32;
        Sample {
            accel: self.accel.kernel.apply(f(&raw.accel)),
            gyro: self.gyro.kernel.apply(f(&raw.gyro)),
            temperature: self.temperature_c(f32::from(raw.temperature)),
            clip: self.clip_flags::<NARROW>(raw),
        }
    }

    #[inline(always)]
    fn correct_with_g<const NARROW: bool>(&self, s: &GSensitivityState, raw: &RawSample) -> Sample {
        let f = counts_f32;
        let accel = f(&raw.accel);
        Sample {
            accel: self.accel.kernel.apply(accel),
            gyro: s.apply(&self.gyro.kernel.k, f(&raw.gyro), accel),
            temperature: self.temperature_c(f32::from(raw.temperature)),
            clip: self.clip_flags::<NARROW>(raw),
        }
    }

    /// The gyro's f32 row on the gyro input `g` and the accelerometer input
    /// `a` (raw counts, or SI for a [`Corrector::new_si`] corrector).
    #[inline(always)]
    fn gyro_rate(&self, g: [f32; 3], a: [f32; 3]) -> [f32; 3] {
        match &self.g_sensitivity {
            None => self.gyro.kernel.apply(g),
            Some(s) => s.apply(&self.gyro.kernel.k, g, a),
        }
    }

    /// A temperature reading (counts, or a mean of counts) in °C, in f32 as
    /// the hot path converts it.
    #[inline(always)]
    pub fn temperature_c(&self, counts: f32) -> f32 {
        counts * self.temperature_scale + self.temperature_offset
    }

    /// The same f32 kernel on inputs in SI units (for a corrector from
    /// [`Corrector::new_si`]); the temperature passes through; no clip flags.
    #[inline]
    pub fn correct_si(&self, accel: [f32; 3], gyro: [f32; 3], temperature: f32) -> Sample {
        Sample {
            accel: self.accel.kernel.apply(accel),
            gyro: self.gyro_rate(gyro, accel),
            temperature,
            clip: ClipFlags::default(),
        }
    }

    /// The f64 reference (ground truth): R·(I+Σ)⁻¹·(s·raw − b) solved by
    /// Gaussian elimination with the calibration as currently folded (for
    /// the gyro R·(I+Σ_g)⁻¹·(s·raw − b_g − G·f), f the accelerometer's
    /// solution in the sensor's axes).
    pub fn reference(&self, raw: &RawSample) -> ReferenceSample {
        let si = |v: &[i32; 3], s: f64| {
            [
                f64::from(v[0]) * s,
                f64::from(v[1]) * s,
                f64::from(v[2]) * s,
            ]
        };
        let (accel, gyro) = self.reference_pair(
            si(&raw.accel, self.scale.accel.si_per_lsb),
            si(&raw.gyro, self.scale.gyro.si_per_lsb),
        );
        ReferenceSample {
            accel,
            gyro,
            temperature: self.scale.temperature_c(raw.temperature),
            clip: ClipFlags::of(raw, &self.scale),
        }
    }

    /// Both triads' f64 reference on SI inputs, in the board's axes.
    fn reference_pair(&self, accel: [f64; 3], gyro: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let f = self.accel.solve(accel);
        let gyro = match &self.calibration.g_sensitivity {
            None => gyro,
            Some(g) => {
                let gf = matrix::mul_vec(g, &f);
                [gyro[0] - gf[0], gyro[1] - gf[1], gyro[2] - gf[2]]
            }
        };
        (
            self.orientation.rotate(f),
            self.orientation.rotate(self.gyro.solve(gyro)),
        )
    }

    /// The f64 reference on inputs in SI units (for a corrector from [`Corrector::new_si`]).
    pub fn reference_si(
        &self,
        accel: [f64; 3],
        gyro: [f64; 3],
        temperature: f64,
    ) -> ReferenceSample {
        let (accel, gyro) = self.reference_pair(accel, gyro);
        ReferenceSample {
            accel,
            gyro,
            temperature,
            clip: ClipFlags::default(),
        }
    }

    /// Re-folds K and k for the temperature terms at `temperature_c`, clamped
    /// to [`TEMPERATURE_RANGE_C`] (where they were validated). Call at a low
    /// rate, not per sample. Triads without temperature terms are unchanged.
    /// A non-finite temperature is rejected and the current coefficients stay.
    pub fn refold(&mut self, temperature_c: f64) -> Result<(), CalibrationError> {
        if !temperature_c.is_finite() {
            return Err(CalibrationError::NonFiniteTemperature {
                value: temperature_c,
            });
        }
        let t = temperature_c.clamp(TEMPERATURE_RANGE_C.0, TEMPERATURE_RANGE_C.1);
        let cal = &self.calibration;
        let refolded =
            |triad: Triad, state: &TriadState, s: f64| match &cal.triad(triad).temperature {
                // Validation proved (I+Σ)(T) invertible and in bounds over the whole range.
                Some(_) => TriadState::new(
                    triad,
                    cal.triad(triad).at_temperature(t),
                    s,
                    self.orientation,
                ),
                None => Ok(*state),
            };
        // Both triads first, then assign: a failed refold changes nothing.
        let accel = refolded(Triad::Accel, &self.accel, self.scale.accel.si_per_lsb)?;
        let gyro = refolded(Triad::Gyro, &self.gyro, self.scale.gyro.si_per_lsb)?;
        let g_sensitivity = cal
            .g_sensitivity
            .map(|g| GSensitivityState::new(&g, &gyro, &accel, self.orientation))
            .transpose()?;
        self.accel = accel;
        self.gyro = gyro;
        self.g_sensitivity = g_sensitivity;
        self.fold_temperature_c = Some(t);
        Ok(())
    }

    /// The calibration identity the stream carries.
    pub fn calibration_id(&self) -> u32 {
        self.calibration.id
    }

    /// The calibration as loaded.
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The mounting orientation folded in.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// The chip scale folded in (sensitivity 1 for [`Corrector::new_si`]).
    pub fn scale(&self) -> &ImuScale {
        &self.scale
    }

    /// Whether a refold can change the coefficients: a triad has
    /// temperature terms. Without, a refold computes what is folded already.
    pub fn has_temperature_terms(&self) -> bool {
        self.calibration.accel.temperature.is_some() || self.calibration.gyro.temperature.is_some()
    }

    /// The temperature of the last refold (after clamping), `None` before the
    /// first: then each triad is folded at its reference temperature.
    pub fn fold_temperature_c(&self) -> Option<f64> {
        self.fold_temperature_c
    }

    /// A triad's folded f64 coefficients (K, k), as currently folded.
    pub fn folded(&self, triad: Triad) -> &FoldedTriad {
        match triad {
            Triad::Accel => &self.accel.folded,
            Triad::Gyro => &self.gyro.folded,
        }
    }

    /// The g-sensitivity's contribution to the gyro's correction, C·raw_a + c
    /// in f64 ([`super::g_sensitivity`]), as currently folded; `None` without
    /// G. Folded again at each call (it is not kept: the corrector stays small
    /// for the Cortex-M0's 16 KiB, and only construction-time checks need it).
    pub fn folded_g_sensitivity(&self) -> Option<FoldedTriad> {
        let g = self.calibration.g_sensitivity.as_ref()?;
        g_sensitivity::fold(g, &self.gyro.matrix, &self.accel.folded, self.orientation)
    }

    /// With G, the gyro row's f32 C and its whole offset k_g + c, exactly as
    /// the hot path applies them after [`Self::folded_f32`]'s K_g (whose
    /// offset it then does not use); `None` without G.
    pub fn g_sensitivity_f32(&self) -> Option<([[f32; 3]; 3], [f32; 3])> {
        self.g_sensitivity.as_ref().map(|s| (s.k_accel, s.offset))
    }

    /// A triad's f32 K and k, exactly as the hot path applies them.
    pub fn folded_f32(&self, triad: Triad) -> ([[f32; 3]; 3], [f32; 3]) {
        let state = match triad {
            Triad::Accel => &self.accel,
            Triad::Gyro => &self.gyro,
        };
        (state.kernel.k, state.kernel.offset)
    }

    /// κ₁ of a triad's (I+Σ) as currently folded.
    pub fn condition_number(&self, triad: Triad) -> f64 {
        let state = match triad {
            Triad::Accel => &self.accel,
            Triad::Gyro => &self.gyro,
        };
        matrix::condition_number(&state.matrix).unwrap_or(f64::INFINITY)
    }
}
