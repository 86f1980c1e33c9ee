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

use crate::calib_fit::error::FitError;
use crate::calib_fit::fits::gyro_fit::{linear_fit, LinearFit};

/// The largest angle between a static mean and the nearest sensor axis, in
/// degrees. A face on a level table is within a fraction of a degree; the
/// MEMS misalignments the loader accepts (≤ 0.1 rad ≈ 5.7°) and the
/// cross-axis biases stay inside 10°.
pub const MAX_AXIS_ANGLE_DEG: f64 = 10.0;

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
pub fn fit(means: &[[f64; 3]], g: f64) -> Result<LinearFit, FitError> {
    if !(g > 0.0 && g.is_finite()) {
        return Err(FitError::InvalidGravity { value: g });
    }
    let mut faces = [false; 6];
    for (segment, m) in means.iter().enumerate() {
        crate::calib_fit::fits::accel_fit::check_magnitude(segment, m, g)?;
        let f = reference(m, g).map_err(|angle_deg| FitError::NotAxisAligned {
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
        FitError::TooFewRates { .. } | FitError::RatesDegenerate { .. } => FitError::TooFewFaces {
            found: faces.iter().filter(|&&f| f).count(),
            segments: means.len(),
        },
        other => other,
    })
}
