//! What a thermal calibration's temperatures can support: the range the
//! records cover, the reference temperature, and which temperature terms
//! the spread of temperatures determines (a design rule on the
//! temperatures alone, never on the fitted values, so the σ's of the terms
//! that are fitted keep their Student-t coverage).
//!
//! # The thresholds
//!
//! - **Swing ≥ [`MIN_SWING_C`] per order.** The temperature a fit uses is
//!   the chip's own sensor reading; the die differs from it by lag and
//!   gradients of about 0.5 °C during a slow ramp or just after a soak step.
//!   An error δT in every ΔT biases a coefficient of order k by about
//!   k·δT/(swing/2) of itself (the k-th power of ΔT ± δT); for ≤ 10 % at
//!   δT = 0.5 °C the linear term needs a swing of 10 °C, and each further
//!   order another 10 °C (the quadratic 20 °C, the cubic 30 °C).
//! - **Distinct temperatures ≥ order + 1.** A polynomial of order k through
//!   k distinct temperatures is undetermined. Temperatures are told apart
//!   in bins of [`LEVEL_C`] (a soak is one level; a ramp covers many).
//! - **(I+Σ) against temperature (D) needs the full orientation set on both
//!   sides of the reference:** ≥ 9 distinct gravity directions
//!   ([`MIN_ACCEL_ORIENTATIONS`]) among the segments colder than the
//!   reference by ≥ [`LEVEL_C`]/2, and as many among the warmer ones, so
//!   that (I+Σ) is determined at two temperatures; a static record at many
//!   temperatures sees one direction only, where D·f and the bias cannot
//!   be told apart.

use core::fmt;

use crate::calib_fit::fits::accel_fit::distinct_orientations;
use crate::calib_fit::fits::accel_fit::MIN_ACCEL_ORIENTATIONS;

/// The smallest swing (°C) per polynomial order of the bias; also the
/// smallest for (I+Σ) linear in ΔT. See the module's notes for why.
pub const MIN_SWING_C: f64 = 10.0;

/// Temperatures closer than this (°C) count as one level (one bin).
pub const LEVEL_C: f64 = 2.0;

/// The highest order of the bias polynomial (the model's cubic).
pub const MAX_BIAS_ORDER: usize = 3;

/// The temperatures a thermal fit covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coverage {
    /// Coldest segment, °C.
    pub min_c: f64,
    /// Warmest segment, °C.
    pub max_c: f64,
    /// T_ref: the middle of the range rounded to 0.1 °C, so ΔT stays
    /// within ± half the swing and the polynomial's terms are least
    /// correlated with the constant.
    pub reference_c: f64,
    /// Distinct temperature levels ([`LEVEL_C`] bins that hold a segment).
    pub levels: usize,
}

impl Coverage {
    /// max − min, °C.
    pub fn swing_c(&self) -> f64 {
        self.max_c - self.min_c
    }

    /// The highest bias order the temperatures support (0: none).
    pub fn bias_order(&self) -> usize {
        (1..=MAX_BIAS_ORDER)
            .take_while(|&k| self.levels > k && self.swing_c() >= MIN_SWING_C * k as f64)
            .last()
            .unwrap_or(0)
    }
}

/// Why the temperatures do not support a term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoverageError {
    /// A segment's temperature is NaN or infinite.
    NonFinite {
        /// The segment (0-based).
        segment: usize,
        /// The value, °C.
        value: f64,
    },
    /// The records' temperatures span too little for any temperature term
    /// ([`MIN_SWING_C`]).
    TemperatureSwingTooSmall {
        /// Coldest segment, °C.
        min_c: f64,
        /// Warmest segment, °C.
        max_c: f64,
        /// The smallest accepted swing, °C.
        needed_c: f64,
    },
    /// (I+Σ) against temperature needs the full orientation set both colder
    /// and warmer than the reference temperature.
    TooFewTemperaturesForScale {
        /// Distinct gravity directions among the colder segments.
        colder: usize,
        /// Among the warmer ones.
        warmer: usize,
        /// The reference temperature, °C.
        reference_c: f64,
        /// The minimum on each side.
        needed: usize,
    },
}

impl fmt::Display for CoverageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CoverageError::NonFinite { segment, value } => {
                write!(f, "segment {}: value {value} is not a finite number", segment + 1)
            }
            CoverageError::TemperatureSwingTooSmall { min_c, max_c, needed_c } => write!(
                f,
                "the static segments' temperatures span {min_c:.1} to {max_c:.1} °C, a swing of {:.1} °C: \
                 a temperature term needs at least {needed_c} °C (the die lags the chip's own reading by \
                 ~0.5 °C, which would bias a coefficient by ≥ 10 %); record over a wider range, or fit at \
                 one temperature with `calib fit accel`/`imu`",
                max_c - min_c
            ),
            CoverageError::TooFewTemperaturesForScale { colder, warmer, reference_c, needed } => write!(
                f,
                "(I+Σ) against temperature needs (I+Σ) at two temperatures: ≥ {needed} distinct static \
                 orientations colder than the reference {reference_c:.1} °C and ≥ {needed} warmer; found \
                 {colder} colder and {warmer} warmer (a static record sees one direction, where the bias \
                 and (I+Σ)·g cannot be told apart): add a multi-position record at each end of the range \
                 (e.g. the hand-soak script), or fit only the gyroscope's bias (--gyro-only)"
            ),
        }
    }
}

/// The coverage of `temperatures` (°C): refused when one is not finite or
/// the swing is below [`MIN_SWING_C`] (no term is supported).
pub fn coverage(temperatures: &[f64]) -> Result<Coverage, CoverageError> {
    if let Some((segment, &value)) = temperatures
        .iter()
        .enumerate()
        .find(|(_, t)| !t.is_finite())
    {
        return Err(CoverageError::NonFinite { segment, value });
    }
    let min_c = temperatures.iter().copied().fold(f64::INFINITY, f64::min);
    let max_c = temperatures
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let swing = max_c - min_c;
    if temperatures.is_empty() || swing < MIN_SWING_C {
        return Err(CoverageError::TemperatureSwingTooSmall {
            min_c,
            max_c,
            needed_c: MIN_SWING_C,
        });
    }
    let mut bins: [u64; 64] = [0; 64];
    for t in temperatures {
        // At most 64 × 64 bins of 2 °C: far beyond any sensor's range.
        let bin = (((t - min_c) / LEVEL_C) as usize).min(64 * 64 - 1);
        bins[bin / 64] |= 1 << (bin % 64);
    }
    let levels = bins.iter().map(|b| b.count_ones() as usize).sum();
    let reference_c = libm::round((min_c + max_c) * 5.0) / 10.0;
    Ok(Coverage {
        min_c,
        max_c,
        reference_c,
        levels,
    })
}

/// Distinct gravity directions among the static means (m/s²) colder and
/// warmer than `reference_c` by at least [`LEVEL_C`]/2: both must reach
/// [`MIN_ACCEL_ORIENTATIONS`] for (I+Σ) linear in ΔT (see the module).
pub fn orientations_either_side(
    means: &[[f64; 3]],
    temperatures: &[f64],
    reference_c: f64,
    scratch: &mut [[f64; 3]],
) -> [usize; 2] {
    let mut side = |colder: bool| {
        let mut n = 0;
        for (m, &t) in means.iter().zip(temperatures) {
            let d = t - reference_c;
            let on_side = if colder {
                d <= -LEVEL_C / 2.0
            } else {
                d >= LEVEL_C / 2.0
            };
            if on_side && n < scratch.len() {
                scratch[n] = *m;
                n += 1;
            }
        }
        distinct_orientations(&scratch[..n])
    };
    [side(true), side(false)]
}

/// Checks the orientations either side ([`orientations_either_side`]).
pub fn check_scale_support(found: [usize; 2], coverage: &Coverage) -> Result<(), CoverageError> {
    if found[0] < MIN_ACCEL_ORIENTATIONS || found[1] < MIN_ACCEL_ORIENTATIONS {
        return Err(CoverageError::TooFewTemperaturesForScale {
            colder: found[0],
            warmer: found[1],
            reference_c: coverage.reference_c,
            needed: MIN_ACCEL_ORIENTATIONS,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_soaks_support_a_quadratic_and_a_ramp_a_cubic() {
        let soaks = coverage(&[-10.0, -10.0, 25.0, 25.3, 60.0]).unwrap();
        assert_eq!((soaks.levels, soaks.reference_c), (3, 25.0));
        assert_eq!(soaks.bias_order(), 2);
        let ramp: [f64; 141] = core::array::from_fn(|i| -10.0 + 0.5 * i as f64);
        assert_eq!(coverage(&ramp).unwrap().bias_order(), 3);
        let narrow = coverage(&[20.0, 35.0]).unwrap();
        assert_eq!(narrow.bias_order(), 1, "15 °C: linear only");
        assert_eq!(
            coverage(&[20.0, 29.0]),
            Err(CoverageError::TemperatureSwingTooSmall {
                min_c: 20.0,
                max_c: 29.0,
                needed_c: 10.0
            })
        );
        assert!(matches!(
            coverage(&[20.0, f64::NAN]),
            Err(CoverageError::NonFinite { segment: 1, .. })
        ));
    }
}
