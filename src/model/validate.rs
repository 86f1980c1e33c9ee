//! Validation of a calibration where it is loaded (as PX4's
//! sensor_calibration does): every rejection names the triad, the entry, the
//! value and the reason, in one line.
//!
//! Bounds and why:
//! - [`SCALE_RANGE`]: a MEMS sensitivity error is a few % (datasheet
//!   sensitivity tolerances are ±0.5..3 %, e.g. the sensor specification
//!   tables of the ICM-42688-P and BMI088 datasheets). 0.5..1.5 accepts
//!   anything physical and catches unit mistakes (a factor 9.81, 57.3 or 1000
//!   between g, °/s, mg and SI).
//! - [`MAX_MISALIGNMENT`]: cross-axis sensitivity is ±1..2 % in the same
//!   tables and package/board misalignment about 1° (0.017); 0.1 (≈ 5.7°)
//!   leaves margin and still rejects a swapped or rotated axis, which belongs
//!   in the [`Orientation`](super::Orientation), not in (I+Σ).
//! - [`MAX_CONDITION_NUMBER`]: see its doc.
//! - Bias: |b_i| must stay within the sensor's configured full scale; a
//!   larger offset would leave no measurement range, so it is a broken fit
//!   or a unit error.
//! - Temperature terms hold over [`TEMPERATURE_RANGE_C`]: (I+Σ)(T) is linear
//!   in T, so its entry bounds are checked exactly at the two ends; the bias
//!   cubic is checked at its extremes (ends and stationary points).
//! - [`MAX_G_SENSITIVITY`]: the gyroscope's g-sensitivity G, entry by entry.

use core::fmt;

use super::calibration::{Calibration, TemperatureTerms, Triad, TriadCalibration};
use super::matrix::{self, Mat3};

/// Sane range of the diagonal of (I+Σ) (scale factors).
pub const SCALE_RANGE: (f64, f64) = (0.5, 1.5);

/// Largest |off-diagonal| of (I+Σ) (misalignment / cross-axis sensitivity).
pub const MAX_MISALIGNMENT: f64 = 0.1;

/// Largest accepted 1-norm condition number κ₁ = ‖A‖₁·‖A⁻¹‖₁ of (I+Σ).
///
/// A MEMS (I+Σ) is within a few % of the identity, so κ₁ ≈ 1.0x; a value
/// above 100 means a broken fit (nearly dependent axes), not a sensor. The
/// limit also bounds the numerical cost: the correction amplifies relative
/// errors by up to κ, so folding into f32 (24-bit significand, 7.2 digits)
/// loses up to log10(κ) = 2 digits at the limit and keeps 5. Any matrix that
/// passes [`SCALE_RANGE`] and [`MAX_MISALIGNMENT`] has κ₂ ≤ (1.5 + √6·0.1) /
/// (0.5 − √6·0.1) ≈ 6.8 and κ₁ ≤ 3·κ₂ ≈ 21, so this check fires first only
/// for matrices that are singular or nearly so.
pub const MAX_CONDITION_NUMBER: f64 = 100.0;

/// Temperatures over which temperature terms are validated and applied, in
/// °C: the industrial range most MEMS IMUs are specified for (−40..+85 °C,
/// e.g. the ICM-42688-P's ordering information). A refold clamps to it rather than
/// extrapolate a fit beyond where it was validated.
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-40.0, 85.0);

/// Largest |d(I+Σ)/dT| entry, per °C: MEMS scale-factor temperature
/// coefficients are 0.005..0.03 %/°C (50..300 ppm/°C); 1 %/°C is absurd.
pub const MAX_SCALE_MISALIGNMENT_PER_C: f64 = 0.01;

/// Largest |G| entry of the gyroscope's g-sensitivity, in (rad/s)/(m/s²):
/// 1 °/s per g. MEMS data sheets give about 0.1 °/s per g (the "linear
/// acceleration sensitivity" of the MPU-6000/6050 and the BMI088's
/// "g-sensitivity"), and issue 22's real unit showed 0.12; ten times that
/// accepts every physical gyro and rejects a unit mistake (G in °/s per g
/// written as SI is 561 times the value).
pub const MAX_G_SENSITIVITY: f64 = core::f64::consts::PI / 180.0 / 9.80665;

/// One number of a triad's calibration, named as in the calibration file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Entry {
    /// `scale_misalignment[row][col]`.
    ScaleMisalignment {
        /// Row 0..3.
        row: u8,
        /// Column 0..3.
        col: u8,
    },
    /// `bias[axis]`.
    Bias {
        /// Axis 0..3 (x, y, z).
        axis: u8,
    },
    /// `temperature.reference_c`.
    ReferenceC,
    /// `temperature.bias_coefficients[axis][power − 1]`.
    BiasCoefficient {
        /// Axis 0..3.
        axis: u8,
        /// The power of ΔT, 1..=3.
        power: u8,
    },
    /// `temperature.scale_misalignment_per_c[row][col]`.
    ScaleMisalignmentPerC {
        /// Row 0..3.
        row: u8,
        /// Column 0..3.
        col: u8,
    },
    /// `g_sensitivity[row][col]` (the gyroscope's only).
    GSensitivity {
        /// Row 0..3: the gyro axis.
        row: u8,
        /// Column 0..3: the specific-force axis.
        col: u8,
    },
}

impl fmt::Display for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Entry::ScaleMisalignment { row, col } => write!(f, "scale_misalignment[{row}][{col}]"),
            Entry::Bias { axis } => write!(f, "bias[{axis}]"),
            Entry::ReferenceC => write!(f, "temperature.reference_c"),
            Entry::BiasCoefficient { axis, power } => {
                write!(
                    f,
                    "temperature.bias_coefficients[{axis}][{}]",
                    power.saturating_sub(1)
                )
            }
            Entry::ScaleMisalignmentPerC { row, col } => {
                write!(f, "temperature.scale_misalignment_per_c[{row}][{col}]")
            }
            Entry::GSensitivity { row, col } => write!(f, "g_sensitivity[{row}][{col}]"),
        }
    }
}

/// Why a calibration (or a sensor scale it is folded with) was rejected.
/// `temperature_c` is `Some(T)` when the value is the one the temperature
/// terms give at T.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CalibrationError {
    /// An entry is NaN or ±∞.
    NonFinite {
        /// Which triad.
        triad: Triad,
        /// Which entry.
        entry: Entry,
        /// The value.
        value: f64,
    },
    /// (I+Σ) is exactly singular (determinant 0): it cannot be inverted.
    Singular {
        /// Which triad.
        triad: Triad,
        /// The determinant (0 or not finite).
        determinant: f64,
        /// Set when evaluated from temperature terms.
        temperature_c: Option<f64>,
    },
    /// κ₁(I+Σ) exceeds [`MAX_CONDITION_NUMBER`].
    BadlyConditioned {
        /// Which triad.
        triad: Triad,
        /// κ₁ = ‖A‖₁·‖A⁻¹‖₁.
        condition: f64,
        /// Set when evaluated from temperature terms.
        temperature_c: Option<f64>,
    },
    /// A diagonal entry (scale factor) outside [`SCALE_RANGE`].
    ScaleOutOfRange {
        /// Which triad.
        triad: Triad,
        /// The axis (row = column).
        axis: u8,
        /// The value.
        value: f64,
        /// Set when evaluated from temperature terms.
        temperature_c: Option<f64>,
    },
    /// An off-diagonal entry with |value| above [`MAX_MISALIGNMENT`].
    MisalignmentTooLarge {
        /// Which triad.
        triad: Triad,
        /// Row.
        row: u8,
        /// Column.
        col: u8,
        /// The value.
        value: f64,
        /// Set when evaluated from temperature terms.
        temperature_c: Option<f64>,
    },
    /// |bias| beyond the sensor's configured full scale.
    BiasBeyondFullScale {
        /// Which triad.
        triad: Triad,
        /// The axis.
        axis: u8,
        /// The bias.
        value: f64,
        /// The full scale, ± SI units.
        full_scale: f64,
        /// Set when evaluated from temperature terms.
        temperature_c: Option<f64>,
    },
    /// `temperature.reference_c` outside [`TEMPERATURE_RANGE_C`].
    ReferenceTemperatureOutOfRange {
        /// Which triad.
        triad: Triad,
        /// The value in °C.
        value: f64,
    },
    /// A temperature coefficient beyond its physical bound.
    TemperatureTermAbsurd {
        /// Which triad.
        triad: Triad,
        /// Which entry.
        entry: Entry,
        /// The value.
        value: f64,
        /// The bound on |value|.
        limit: f64,
    },
    /// A g-sensitivity entry with |value| above [`MAX_G_SENSITIVITY`].
    GSensitivityAbsurd {
        /// Row: the gyro axis.
        row: u8,
        /// Column: the specific-force axis.
        col: u8,
        /// The value in (rad/s)/(m/s²).
        value: f64,
    },
    /// A sensor scale that cannot be folded: `quantity` names it.
    InvalidScale {
        /// `accel.si_per_lsb`, `gyro.full_scale`, `temperature_per_lsb`, ...
        quantity: &'static str,
        /// The value.
        value: f64,
    },
    /// A temperature given to a refold is NaN or ±∞.
    NonFiniteTemperature {
        /// The value.
        value: f64,
    },
    /// The fixed-point form cannot represent this triad's outputs.
    FixedPointRange {
        /// `accel`, `gyro` or `temperature`.
        quantity: &'static str,
        /// The largest output magnitude the coefficients allow, in SI units.
        max_output: f64,
    },
}

/// A value in a message: the shortest decimal that reads back to it when
/// that is short (magnitudes 1e-5 up to 1e16, and zero), in exponent form
/// otherwise (`1e308`, not 309 digits).
pub struct Readable(pub f64);

impl fmt::Display for Readable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if !self.0.is_finite() || self.0 == 0.0 || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// ` at 85 °C` or nothing.
struct At(Option<f64>);

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(t) => write!(f, " at {t} °C"),
            None => Ok(()),
        }
    }
}

impl fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CalibrationError::NonFinite { triad, entry, value } => {
                let value = Readable(value);
                write!(f, "{} {entry} = {value}: not a finite number", triad.name())
            }
            CalibrationError::Singular { triad, determinant, temperature_c } => write!(
                f,
                "{} scale_misalignment{}: singular (determinant {determinant}), cannot be inverted",
                triad.name(),
                At(temperature_c),
                determinant = Readable(determinant)
            ),
            CalibrationError::BadlyConditioned { triad, condition, temperature_c } => write!(
                f,
                "{} scale_misalignment{}: condition number {condition:.4e} exceeds {MAX_CONDITION_NUMBER} \
                 (a MEMS I+Σ is within a few % of identity: this is a broken fit)",
                triad.name(),
                At(temperature_c)
            ),
            CalibrationError::ScaleOutOfRange { triad, axis, value, temperature_c } => write!(
                f,
                "{} scale_misalignment[{axis}][{axis}]{} = {value}: diagonal (scale factor) outside the sane range {}..{}",
                triad.name(),
                At(temperature_c),
                SCALE_RANGE.0,
                SCALE_RANGE.1,
                value = Readable(value)
            ),
            CalibrationError::MisalignmentTooLarge { triad, row, col, value, temperature_c } => write!(
                f,
                "{} scale_misalignment[{row}][{col}]{} = {value}: off-diagonal (misalignment) beyond ±{MAX_MISALIGNMENT}",
                triad.name(),
                At(temperature_c),
                value = Readable(value)
            ),
            CalibrationError::BiasBeyondFullScale { triad, axis, value, full_scale, temperature_c } => write!(
                f,
                "{} bias[{axis}]{} = {value}: beyond the sensor's full scale ±{full_scale}",
                triad.name(),
                At(temperature_c),
                value = Readable(value),
                full_scale = Readable(full_scale)
            ),
            CalibrationError::ReferenceTemperatureOutOfRange { triad, value } => write!(
                f,
                "{} temperature.reference_c = {value}: outside the validated range {}..{} °C",
                triad.name(),
                TEMPERATURE_RANGE_C.0,
                TEMPERATURE_RANGE_C.1,
                value = Readable(value)
            ),
            CalibrationError::TemperatureTermAbsurd { triad, entry, value, limit } => write!(
                f,
                "{} {entry} = {value}: beyond the physical bound ±{limit} per °C",
                triad.name(),
                value = Readable(value)
            ),
            CalibrationError::GSensitivityAbsurd { row, col, value } => write!(
                f,
                "gyro g_sensitivity[{row}][{col}] = {value} (rad/s)/(m/s²) ({per_g:.4} °/s per g): \
                 beyond the physical bound ±{MAX_G_SENSITIVITY:.4e} (1 °/s per g; MEMS gyros show about 0.1)",
                value = Readable(value),
                per_g = crate::units::si_to_dps_per_g(value)
            ),
            CalibrationError::InvalidScale { quantity, value } => {
                let value = Readable(value);
                write!(f, "sensor scale {quantity} = {value}: must be finite and positive")
            }
            CalibrationError::NonFiniteTemperature { value } => {
                let value = Readable(value);
                write!(f, "temperature {value} °C: not a finite number")
            }
            CalibrationError::FixedPointRange { quantity, max_output } => write!(
                f,
                "{quantity}: outputs up to {max_output} do not fit the fixed-point output range",
                max_output = Readable(max_output)
            ),
        }
    }
}

/// Lets hosts use `?` into their error types; the message is the Display above.
impl core::error::Error for CalibrationError {}

impl Calibration {
    /// Checks both triads; `*_full_scale` are the configured ranges (± SI
    /// units) that bound the bias.
    pub fn validate(
        &self,
        accel_full_scale: f64,
        gyro_full_scale: f64,
    ) -> Result<(), CalibrationError> {
        positive_finite("accel.full_scale", accel_full_scale)?;
        positive_finite("gyro.full_scale", gyro_full_scale)?;
        validate_triad(Triad::Accel, &self.accel, accel_full_scale)?;
        validate_triad(Triad::Gyro, &self.gyro, gyro_full_scale)?;
        validate_g_sensitivity(self.g_sensitivity.as_ref())
    }
}

/// Checks the gyroscope's g-sensitivity G (if any): finite, and each entry
/// within ±[`MAX_G_SENSITIVITY`].
pub fn validate_g_sensitivity(g: Option<&Mat3>) -> Result<(), CalibrationError> {
    let Some(g) = g else { return Ok(()) };
    for (row, r) in (0u8..).zip(g.iter()) {
        for (col, &value) in (0u8..).zip(r.iter()) {
            if !value.is_finite() {
                return Err(CalibrationError::NonFinite {
                    triad: Triad::Gyro,
                    entry: Entry::GSensitivity { row, col },
                    value,
                });
            }
            if !at_most(value.abs(), MAX_G_SENSITIVITY) {
                return Err(CalibrationError::GSensitivityAbsurd { row, col, value });
            }
        }
    }
    Ok(())
}

/// `Ok` if `value` is finite and > 0, else [`CalibrationError::InvalidScale`].
pub(crate) fn positive_finite(quantity: &'static str, value: f64) -> Result<(), CalibrationError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(CalibrationError::InvalidScale { quantity, value })
    }
}

/// Checks one triad against the bounds in the module doc.
pub fn validate_triad(
    triad: Triad,
    cal: &TriadCalibration,
    full_scale: f64,
) -> Result<(), CalibrationError> {
    check_finite(triad, cal)?;
    if let Some(terms) = &cal.temperature {
        check_temperature_terms(triad, terms)?;
    }
    check_matrix(triad, &cal.scale_misalignment, None)?;
    for (axis, &b) in cal.bias.iter().enumerate() {
        check_bias(triad, axis, b, full_scale, None)?;
    }
    if let Some(terms) = &cal.temperature {
        for end in [TEMPERATURE_RANGE_C.0, TEMPERATURE_RANGE_C.1] {
            let (m, _) = cal.at_temperature(end);
            check_matrix(triad, &m, Some(end))?;
        }
        for (axis, (&b, c)) in cal
            .bias
            .iter()
            .zip(terms.bias_coefficients.iter())
            .enumerate()
        {
            let (value, t) = worst_bias(b, c, terms.reference_c);
            check_bias(triad, axis, value, full_scale, Some(t))?;
        }
    }
    Ok(())
}

fn check_finite(triad: Triad, cal: &TriadCalibration) -> Result<(), CalibrationError> {
    let bad = |entry: Entry, value: f64| CalibrationError::NonFinite {
        triad,
        entry,
        value,
    };
    for (row, r) in (0u8..).zip(cal.scale_misalignment.iter()) {
        for (col, &v) in (0u8..).zip(r.iter()) {
            if !v.is_finite() {
                return Err(bad(Entry::ScaleMisalignment { row, col }, v));
            }
        }
    }
    for (axis, &v) in (0u8..).zip(cal.bias.iter()) {
        if !v.is_finite() {
            return Err(bad(Entry::Bias { axis }, v));
        }
    }
    if let Some(terms) = &cal.temperature {
        if !terms.reference_c.is_finite() {
            return Err(bad(Entry::ReferenceC, terms.reference_c));
        }
        for (axis, c) in (0u8..).zip(terms.bias_coefficients.iter()) {
            for (power, &v) in (1u8..).zip(c.iter()) {
                if !v.is_finite() {
                    return Err(bad(Entry::BiasCoefficient { axis, power }, v));
                }
            }
        }
        for (row, r) in (0u8..).zip(terms.scale_misalignment_per_c.iter()) {
            for (col, &v) in (0u8..).zip(r.iter()) {
                if !v.is_finite() {
                    return Err(bad(Entry::ScaleMisalignmentPerC { row, col }, v));
                }
            }
        }
    }
    Ok(())
}

fn check_temperature_terms(triad: Triad, terms: &TemperatureTerms) -> Result<(), CalibrationError> {
    let (lo, hi) = TEMPERATURE_RANGE_C;
    if !(lo..=hi).contains(&terms.reference_c) {
        return Err(CalibrationError::ReferenceTemperatureOutOfRange {
            triad,
            value: terms.reference_c,
        });
    }
    for (row, r) in (0u8..).zip(terms.scale_misalignment_per_c.iter()) {
        for (col, &value) in (0u8..).zip(r.iter()) {
            if value.abs() > MAX_SCALE_MISALIGNMENT_PER_C {
                return Err(CalibrationError::TemperatureTermAbsurd {
                    triad,
                    entry: Entry::ScaleMisalignmentPerC { row, col },
                    value,
                    limit: MAX_SCALE_MISALIGNMENT_PER_C,
                });
            }
        }
    }
    Ok(())
}

/// Singular, conditioning, diagonal, off-diagonal: in that order, so a
/// singular matrix is reported as singular rather than by its largest entry.
fn check_matrix(
    triad: Triad,
    m: &Mat3,
    temperature_c: Option<f64>,
) -> Result<(), CalibrationError> {
    let condition = match matrix::condition_number(m) {
        Some(c) => c,
        _ => {
            return Err(CalibrationError::Singular {
                triad,
                determinant: matrix::determinant(m),
                temperature_c,
            })
        }
    };
    // `at_most` is false for NaN, so a NaN condition number is rejected too.
    if !at_most(condition, MAX_CONDITION_NUMBER) {
        return Err(CalibrationError::BadlyConditioned {
            triad,
            condition,
            temperature_c,
        });
    }
    for (row, r) in (0u8..).zip(m.iter()) {
        for (col, &value) in (0u8..).zip(r.iter()) {
            if row == col {
                if !(SCALE_RANGE.0..=SCALE_RANGE.1).contains(&value) {
                    return Err(CalibrationError::ScaleOutOfRange {
                        triad,
                        axis: row,
                        value,
                        temperature_c,
                    });
                }
            } else if !at_most(value.abs(), MAX_MISALIGNMENT) {
                return Err(CalibrationError::MisalignmentTooLarge {
                    triad,
                    row,
                    col,
                    value,
                    temperature_c,
                });
            }
        }
    }
    Ok(())
}

/// `x <= limit`, false for NaN.
fn at_most(x: f64, limit: f64) -> bool {
    x <= limit
}

fn check_bias(
    triad: Triad,
    axis: usize,
    value: f64,
    full_scale: f64,
    temperature_c: Option<f64>,
) -> Result<(), CalibrationError> {
    if at_most(value.abs(), full_scale) {
        Ok(())
    } else {
        Err(CalibrationError::BiasBeyondFullScale {
            triad,
            axis: axis as u8,
            value,
            full_scale,
            temperature_c,
        })
    }
}

/// The bias of largest magnitude b + c1·ΔT + c2·ΔT² + c3·ΔT³ takes over
/// [`TEMPERATURE_RANGE_C`], and the temperature where it does: the extremes
/// of a cubic on an interval lie at its ends or where 3c3·x² + 2c2·x + c1 = 0.
fn worst_bias(b: f64, c: &[f64; 3], reference_c: f64) -> (f64, f64) {
    let at = |x: f64| b + x * (c[0] + x * (c[1] + x * c[2]));
    let lo = TEMPERATURE_RANGE_C.0 - reference_c;
    let hi = TEMPERATURE_RANGE_C.1 - reference_c;
    let mut candidates = [lo, hi, lo, lo];
    let (qa, qb, qc) = (3.0 * c[2], 2.0 * c[1], c[0]);
    if qa != 0.0 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let root = libm::sqrt(disc);
            candidates[2] = (-qb + root) / (2.0 * qa);
            candidates[3] = (-qb - root) / (2.0 * qa);
        }
    } else if qb != 0.0 {
        candidates[2] = -qc / qb;
    }
    let mut worst = (at(lo), lo);
    for &x in &candidates {
        if (lo..=hi).contains(&x) && !at_most(at(x).abs(), worst.0.abs()) {
            worst = (at(x), x);
        }
    }
    (worst.0, worst.1 + reference_c)
}
