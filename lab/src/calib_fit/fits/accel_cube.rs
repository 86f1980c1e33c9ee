//! The classic axis-aligned (cube) accelerometer calibration: in every
//! static position one sensor axis is vertical, up or down (a six-position
//! tumble, or the 24 positions of a cube at four headings; IEEE Std 1293
//! calls it the multi-position test). The true specific force is then known
//! from the measurement itself, +g or −g along the axis nearest to the
//! static mean, so m̂ = (I+Σ)·m + b is linear in all 12 unknowns and is
//! solved as the gyro's rate-table fit is ([`crate::calib_fit::fits::gyro_fit::linear_fit`]).
//!
//! Unlike [`crate::calib_fit::fits::accel_fit`] no rotation convention is needed: the cube's
//! faces (the fixture) define the axes, and (I+Σ) is full. It needs at least
//! 4 faces up that are not all in one plane (6 is the usual minimum in
//! practice); 9 distinct orientations are not needed.

use core::fmt;

use crate::calib_fit::fits::accel_fit::{self, NotNearGravity};
use crate::calib_fit::fits::gyro_fit::{linear_fit, GyroFitError, LinearFit};
use crate::calib_fit::numerics::error::NumericsError;

/// The largest angle between a static mean and the nearest sensor axis, in
/// degrees. A face on a level table is within a fraction of a degree; the
/// MEMS misalignments the loader accepts (≤ 0.1 rad ≈ 5.7°) and the
/// cross-axis biases stay inside 10°.
pub const MAX_AXIS_ANGLE_DEG: f64 = 10.0;

/// Why the axis-aligned fit refused its static means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AccelCubeError {
    /// The gravity given is not a positive finite number.
    InvalidGravity {
        /// The value in m/s².
        value: f64,
    },
    /// A static mean's magnitude is nowhere near g.
    NotNearGravity(NotNearGravity),
    /// A static mean is not along a sensor axis (the axis-aligned fit needs
    /// one axis vertical in every position).
    NotAxisAligned {
        /// The segment (0-based).
        segment: usize,
        /// Angle between the mean and the nearest sensor axis, degrees.
        angle_deg: f64,
        /// The largest accepted angle, degrees.
        limit_deg: f64,
    },
    /// Fewer than 4 faces, or all in one plane.
    TooFewFaces {
        /// Distinct faces (±x, ±y, ±z) found up.
        found: usize,
        /// Static segments.
        segments: usize,
    },
    /// A value is not finite, or the parameters are not determined.
    Numerics(NumericsError),
}

impl From<NumericsError> for AccelCubeError {
    fn from(e: NumericsError) -> Self {
        AccelCubeError::Numerics(e)
    }
}

impl From<NotNearGravity> for AccelCubeError {
    fn from(e: NotNearGravity) -> Self {
        AccelCubeError::NotNearGravity(e)
    }
}

impl fmt::Display for AccelCubeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AccelCubeError::InvalidGravity { value } => accel_fit::write_invalid_gravity(f, *value),
            AccelCubeError::NotNearGravity(e) => write!(f, "{e}"),
            AccelCubeError::NotAxisAligned {
                segment,
                angle_deg,
                limit_deg,
            } => write!(
                f,
                "static segment {}: gravity is {angle_deg:.1}° from the nearest sensor axis (limit {limit_deg}°): \
                 --axis-aligned needs one sensor axis vertical in every position",
                segment + 1
            ),
            AccelCubeError::TooFewFaces { found, segments } => write!(
                f,
                "found {found} distinct face(s) up in {segments} static segment(s); the axis-aligned fit \
                 (per axis: 3 of I+Σ and 1 bias) needs at least 4 faces not all in one plane, \
                 e.g. +z, −z, +x, +y (better all six)"
            ),
            AccelCubeError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// The true specific force ±g·e_k of an axis-aligned static mean, or the
/// angle (degrees) to the nearest axis when it is more than
/// [`MAX_AXIS_ANGLE_DEG`] away.
pub fn reference(mean: &[f64; 3], g: f64) -> Result<[f64; 3], f64> {
    let norm = libm::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
    let mut k = 0;
    for i in 1..3 {
        if mean[i].abs() > mean[k].abs() {
            k = i;
        }
    }
    let angle = libm::acos((mean[k].abs() / norm).min(1.0)).to_degrees();
    if angle.is_nan() || angle > MAX_AXIS_ANGLE_DEG {
        return Err(angle);
    }
    let mut f = [0.0; 3];
    f[k] = if mean[k] > 0.0 { g } else { -g };
    Ok(f)
}

/// Fits the full (I+Σ) and b to axis-aligned static means (m/s²).
pub fn fit(means: &[[f64; 3]], g: f64) -> Result<LinearFit, AccelCubeError> {
    if !(g > 0.0 && g.is_finite()) {
        return Err(AccelCubeError::InvalidGravity { value: g });
    }
    let mut faces = [false; 6];
    for (segment, m) in means.iter().enumerate() {
        accel_fit::check_magnitude::<AccelCubeError>(segment, m, g)?;
        let f = reference(m, g).map_err(|angle_deg| AccelCubeError::NotAxisAligned {
            segment,
            angle_deg,
            limit_deg: MAX_AXIS_ANGLE_DEG,
        })?;
        for (k, &x) in f.iter().enumerate() {
            if x != 0.0 {
                faces[2 * k + usize::from(x < 0.0)] = true;
            }
        }
    }
    let pairs = means.iter().map(|m| {
        // Checked above: every mean has its reference.
        (reference(m, g).unwrap_or([0.0; 3]), *m)
    });
    linear_fit(pairs).map_err(|e| match e {
        GyroFitError::TooFewRates { .. } | GyroFitError::RatesDegenerate { .. } => {
            AccelCubeError::TooFewFaces {
                found: faces.iter().filter(|&&f| f).count(),
                segments: means.len(),
            }
        }
        GyroFitError::Numerics(e) => AccelCubeError::Numerics(e),
    })
}
