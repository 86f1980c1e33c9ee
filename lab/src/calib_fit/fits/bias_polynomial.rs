//! A triad's bias against temperature from static means at known
//! temperatures: per axis b(ΔT) = b₀ + c₁ΔT + c₂ΔT² + c₃ΔT³ up to the
//! order the temperatures support ([`crate::calib_fit::fits::thermal_coverage`]), by
//! weighted linear least squares (each mean weighed by 1/its standard
//! error, so long and short segments count as they should).
//!
//! σ's: s²·(AᵀWA)⁻¹ per axis, s² the weighted residual variance with
//! segments − (order + 1) degrees of freedom, so anything that scatters
//! the means beyond their white-noise errors (drift, for the gyroscope the
//! Earth's rate in changing orientations) widens the σ's instead of being
//! ignored. Used for the gyroscope, whose static mean is its bias (the
//! Earth's rate, ≤ 7.3e-5 rad/s, is not removed: in one orientation it
//! goes into b₀, in many into the scatter).

use core::fmt;

use crate::calib_fit::fits::thermal_coverage::MAX_BIAS_ORDER;
use crate::calib_fit::numerics::qr::{GivensLs, LsError};

/// Why the bias polynomial was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BiasPolynomialError {
    /// A mean or its standard error is NaN or infinite.
    NonFinite {
        /// The segment (0-based).
        segment: usize,
        /// The value.
        value: f64,
    },
    /// The least-squares problem is rank deficient or short of rows.
    LeastSquares(LsError),
}

impl From<LsError> for BiasPolynomialError {
    fn from(e: LsError) -> Self {
        BiasPolynomialError::LeastSquares(e)
    }
}

impl fmt::Display for BiasPolynomialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BiasPolynomialError::NonFinite { segment, value } => {
                write!(
                    f,
                    "segment {}: value {value} is not a finite number",
                    segment + 1
                )
            }
            BiasPolynomialError::LeastSquares(e) => write!(f, "{e}"),
        }
    }
}

/// One static mean: its temperature, the mean and its standard errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticMean {
    /// Mean temperature over the segment, °C.
    pub temperature_c: f64,
    /// The triad's mean (SI).
    pub mean: [f64; 3],
    /// Standard error of the mean per axis (SI).
    pub standard_error: [f64; 3],
}

/// The fitted bias polynomial.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiasPolynomial {
    /// T_ref, °C.
    pub reference_c: f64,
    /// The order fitted (1..=3); higher coefficients are zero.
    pub order: usize,
    /// b₀ = b(T_ref) per axis.
    pub bias: [f64; 3],
    /// σ of b₀.
    pub sigma_bias: [f64; 3],
    /// [c₁, c₂, c₃] per axis (SI/°C^k).
    pub coefficients: [[f64; 3]; 3],
    /// Their σ's (zero for the orders not fitted).
    pub sigma_coefficients: [[f64; 3]; 3],
    /// Degrees of freedom of every σ: means − (order + 1).
    pub dof: usize,
    /// RMS of the residuals per axis (SI, unweighted).
    pub residual_rms: [f64; 3],
}

impl BiasPolynomial {
    /// b at `temperature_c`.
    pub fn at(&self, temperature_c: f64) -> [f64; 3] {
        let p = powers(temperature_c - self.reference_c, self.order);
        core::array::from_fn(|i| {
            let c = &self.coefficients[i];
            self.bias[i] + p[1] * c[0] + p[2] * c[1] + p[3] * c[2]
        })
    }
}

/// Fits the polynomial of `order` (1..=[`MAX_BIAS_ORDER`]) about `reference_c`.
pub fn fit(
    means: &[StaticMean],
    reference_c: f64,
    order: usize,
) -> Result<BiasPolynomial, BiasPolynomialError> {
    let order = order.clamp(1, MAX_BIAS_ORDER);
    let unknowns = order + 1;
    for (segment, m) in means.iter().enumerate() {
        let values = m
            .mean
            .iter()
            .chain(&m.standard_error)
            .chain([&m.temperature_c]);
        if let Some(&value) = values.into_iter().find(|x| !x.is_finite()) {
            return Err(BiasPolynomialError::NonFinite { segment, value });
        }
    }
    // One degree of freedom at least: no σ without one.
    if means.len() <= unknowns {
        return Err(BiasPolynomialError::LeastSquares(LsError::TooFewRows {
            rows: means.len(),
            unknowns: unknowns + 1,
        }));
    }
    let dof = means.len() - unknowns;
    let mut out = BiasPolynomial {
        reference_c,
        order,
        bias: [0.0; 3],
        sigma_bias: [0.0; 3],
        coefficients: [[0.0; 3]; 3],
        sigma_coefficients: [[0.0; 3]; 3],
        dof,
        residual_rms: [0.0; 3],
    };
    for axis in 0..3 {
        // Equal weights when a segment's error is zero (noise-free data).
        let floor = means
            .iter()
            .map(|m| m.standard_error[axis])
            .fold(0.0f64, f64::max)
            * 1e-6;
        let mut ls = GivensLs::<4>::new();
        for m in means {
            let w = 1.0 / m.standard_error[axis].max(floor).max(f64::MIN_POSITIVE);
            ls.add_row(
                powers(m.temperature_c - reference_c, order).map(|x| x * w),
                m.mean[axis] * w,
            );
        }
        // The orders not fitted are pinned at zero (a unit row of their own):
        // the fitted block of (AᵀA)⁻¹ is unchanged.
        for k in unknowns..4 {
            let mut row = [0.0; 4];
            row[k] = 1.0;
            ls.add_row(row, 0.0);
        }
        let p = ls.solve()?;
        let inv = ls.inverse_normal_matrix()?;
        let s2 = ls.residual_sum_of_squares() / dof as f64;
        out.bias[axis] = p[0];
        out.sigma_bias[axis] = libm::sqrt(s2 * inv[0][0]);
        for k in 1..unknowns {
            out.coefficients[axis][k - 1] = p[k];
            out.sigma_coefficients[axis][k - 1] = libm::sqrt(s2 * inv[k][k]);
        }
        let sum_sq: f64 = means
            .iter()
            .map(|m| {
                let fitted: f64 = powers(m.temperature_c - reference_c, order)
                    .iter()
                    .zip(p)
                    .map(|(a, c)| a * c)
                    .sum();
                (m.mean[axis] - fitted) * (m.mean[axis] - fitted)
            })
            .sum();
        out.residual_rms[axis] = libm::sqrt(sum_sq / means.len().max(1) as f64);
    }
    Ok(out)
}

/// [1, ΔT, ΔT², ΔT³] with the powers above `order` zero.
pub fn powers(delta_c: f64, order: usize) -> [f64; 4] {
    let mut p = [1.0, delta_c, delta_c * delta_c, delta_c * delta_c * delta_c];
    for x in p.iter_mut().skip(order + 1) {
        *x = 0.0;
    }
    p
}
