//! Folding the gyroscope's g-sensitivity G into the gyro's correction.
//!
//! With f_s the specific force in sensor axes and R the mounting rotation,
//! the gyro's correction is ω = R·(I+Σ_g)⁻¹·(s_g·raw_g − b_g − G·f_s). The
//! corrected accelerometer sample is f = K_a·raw_a + k_a = R·f_s, so
//!
//! ```text
//! ω = K_g·raw_g + k_g + C·raw_a + c,   C = −H·K_a,   c = −H·k_a,   H = R·(I+Σ_g)⁻¹·G·Rᵀ:
//! ```
//!
//! one 3×6 map from the raw sample to the rate, computed once in f64 when a
//! calibration is loaded or refolded (H changes with the gyro's (I+Σ_g)(T),
//! C and c with the accelerometer's fold).

use super::fold::FoldedTriad;
use super::matrix::{self, Mat3};
use super::orientation::Orientation;

/// The accelerometer's contribution to the gyro's correction, C·raw_a + c, as
/// a [`FoldedTriad`] (K = C in SI rate per accelerometer LSB, k = c), or
/// `None` if (I+Σ_g) is singular (ruled out by validation before any caller
/// gets here).
#[inline(never)]
pub fn fold(
    g_sensitivity: &Mat3,
    gyro_scale_misalignment: &Mat3,
    accel: &FoldedTriad,
    orientation: Orientation,
) -> Option<FoldedTriad> {
    let inverse = matrix::inverse(gyro_scale_misalignment)?;
    let r = orientation.matrix().map(|row| row.map(f64::from));
    // H·K_a = R·((I+Σ_g)⁻¹·G)·(Rᵀ·K_a): R's entries are 0 and ±1, so the
    // products with R only permute and flip, exactly.
    let rm = matrix::mul(&r, &matrix::mul(&inverse, g_sensitivity));
    let hk = matrix::mul(&rm, &matrix::transpose_mul(&r, &accel.k));
    let hc = matrix::mul_vec(&rm, &matrix::mul_transpose_vec(&r, &accel.offset));
    Some(FoldedTriad {
        k: hk.map(|row| row.map(|x| -x)),
        offset: hc.map(|x| -x),
    })
}
