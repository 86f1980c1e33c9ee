//! Folding: the chip's LSB→SI sensitivity s, the mounting rotation R and the
//! triad's (I+Σ)⁻¹ and b become one matrix and one offset,
//!
//! ```text
//! m = R·(I+Σ)⁻¹·(s·raw − b) = K·raw + k,   K = s·R·(I+Σ)⁻¹,   k = −R·(I+Σ)⁻¹·b,
//! ```
//!
//! computed once in f64 when a calibration is loaded or refolded.

use super::matrix::{self, Mat3};
use super::orientation::Orientation;

/// One triad's folded coefficients in f64: m = K·raw + k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoldedTriad {
    /// K = s·R·(I+Σ)⁻¹, SI units per LSB.
    pub k: Mat3,
    /// k = −R·(I+Σ)⁻¹·b, SI units.
    pub offset: [f64; 3],
}

impl FoldedTriad {
    /// Folds `scale_misalignment` (I+Σ), `bias` b, sensitivity `si_per_lsb`
    /// and the mounting `orientation`; `None` if (I+Σ) is singular (which
    /// validation has ruled out before any caller gets here).
    pub fn new(
        scale_misalignment: &Mat3,
        bias: &[f64; 3],
        si_per_lsb: f64,
        orientation: Orientation,
    ) -> Option<Self> {
        let inverse = matrix::inverse(scale_misalignment)?;
        // R has one ±1 per row: R·A⁻¹ only permutes rows and flips signs, exactly.
        let mut rotated = [[0.0; 3]; 3];
        for (out, r_row) in rotated.iter_mut().zip(orientation.matrix().iter()) {
            for (&r, inv_row) in r_row.iter().zip(inverse.iter()) {
                if r != 0 {
                    for (o, &x) in out.iter_mut().zip(inv_row.iter()) {
                        *o = f64::from(r) * x;
                    }
                }
            }
        }
        let mut k = rotated;
        for x in k.iter_mut().flatten() {
            *x *= si_per_lsb;
        }
        let rb = matrix::mul_vec(&rotated, bias);
        Some(FoldedTriad {
            k,
            offset: [-rb[0], -rb[1], -rb[2]],
        })
    }

    /// K·x + k in f64.
    pub fn apply(&self, x: &[f64; 3]) -> [f64; 3] {
        let kx = matrix::mul_vec(&self.k, x);
        [
            kx[0] + self.offset[0],
            kx[1] + self.offset[1],
            kx[2] + self.offset[2],
        ]
    }
}
