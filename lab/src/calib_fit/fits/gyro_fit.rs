//! Gyroscope (I+Σ) and b from rate-table segments with known true rates:
//! ω̂ = (I+Σ)·ω + b is linear in the 12 unknowns, and each output axis i is
//! its own problem ω̂_i = [ω_x ω_y ω_z 1]·[row i of (I+Σ), b_i]ᵀ with the
//! same design matrix, solved by QR ([`GivensLs`]) in f64. Four rate vectors
//! not in one (affine) plane make the design of full rank; e.g. ±30 °/s
//! about z with +30 °/s about x and about y. The covariance of each axis's
//! four parameters is s_i²·(XᵀX)⁻¹ with s_i² = RSS_i/(n − 4).
//!
//! Unlike the accelerometer's, the true rates are known vectors, so all nine
//! entries of (I+Σ) are determined: the rotation is the table's.

use core::fmt;

use crate::calib_fit::numerics::error::{check_condition, check_finite, NumericsError};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::small3::{spread, Mat3};

/// The largest accepted condition number of the column-scaled design
/// (see [`crate::calib_fit::fits::accel_fit::MAX_CONDITION`] for the reasoning).
pub const MAX_CONDITION: f64 = 1.0e4;

/// The fewest rate vectors the gyro fit accepts: 4 unknowns per output axis
/// (a row of I+Σ and b_i), one equation per axis per segment.
pub const MIN_GYRO_RATES: usize = 4;

/// Why the rate-table fit refused its segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GyroFitError {
    /// Fewer rate vectors than the gyro model's unknowns per axis.
    TooFewRates {
        /// Rate segments given.
        found: usize,
        /// The minimum.
        needed: usize,
    },
    /// The true rate vectors (with the bias column) do not span 4 dimensions.
    RatesDegenerate {
        /// Affine dimension of the rate vectors: 0 all equal, 1 on one line
        /// (e.g. all about one axis), 2 in one plane.
        dimension: u8,
    },
    /// A value is not finite, or the parameters are not determined.
    Numerics(NumericsError),
}

impl From<NumericsError> for GyroFitError {
    fn from(e: NumericsError) -> Self {
        GyroFitError::Numerics(e)
    }
}

impl fmt::Display for GyroFitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            GyroFitError::TooFewRates { found, needed } => write!(
                f,
                "found {found} rate segment(s); the gyro fit (per axis: 3 of I+Σ and 1 bias) needs at least {needed} \
                 rate vectors not in one plane"
            ),
            GyroFitError::RatesDegenerate { dimension } => {
                let what = match dimension {
                    0 => "all the same",
                    1 => "on one line (e.g. all about one axis)",
                    _ => "in one plane",
                };
                write!(
                    f,
                    "the true rate vectors are {what}: I+Σ and b need at least 4 rate vectors not in one plane \
                     (e.g. +30 and −30 °/s about z, and +30 °/s about x and about y)"
                )
            }
            GyroFitError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// One rate-table segment: the known true rate and the measured mean, rad/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateSegment {
    /// The table's rate vector in the sensor's axes, rad/s.
    pub true_rate: [f64; 3],
    /// The mean gyro output over the segment, rad/s.
    pub measured: [f64; 3],
}

/// The result of [`fit`] (and of [`crate::calib_fit::fits::accel_cube::fit`], the same
/// linear problem with gravity as the known vector).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearFit {
    /// I + Σ.
    pub scale_misalignment: Mat3,
    /// b (rad/s for the gyro, m/s² for the accelerometer).
    pub bias: [f64; 3],
    /// Standard deviations of (I+Σ); `None` with no degree of freedom (n = 4).
    pub sigma_scale_misalignment: Option<Mat3>,
    /// Standard deviations of b.
    pub sigma_bias: Option<[f64; 3]>,
    /// RMS of the residual components ω̂ − (I+Σ)ω − b (SI units).
    pub residual_rms: f64,
    /// Largest |residual component| (SI units).
    pub residual_max: f64,
    /// Segments used.
    pub segments: usize,
    /// Degrees of freedom of each axis's σ's: segments − 4 parameters per
    /// output axis (a row of (I+Σ) and its bias).
    pub dof: usize,
    /// Condition number of the column-scaled design.
    pub condition: f64,
}

impl LinearFit {
    /// The residual m̂ − (I+Σ)·m − b of a pair (known m, measured mean m̂).
    pub fn residual(&self, known: &[f64; 3], measured: &[f64; 3]) -> [f64; 3] {
        residual(&self.scale_misalignment, &self.bias, known, measured)
    }
}

fn residual(m: &Mat3, bias: &[f64; 3], known: &[f64; 3], measured: &[f64; 3]) -> [f64; 3] {
    let model = triad::model::matrix::mul_vec(m, known);
    core::array::from_fn(|i| measured[i] - model[i] - bias[i])
}

/// The gyro's fit: [`LinearFit`] of rate-table segments.
pub type GyroFit = LinearFit;

/// Fits (I+Σ) and b to `segments`.
pub fn fit(segments: &[RateSegment]) -> Result<GyroFit, GyroFitError> {
    linear_fit(segments.iter().map(|s| (s.true_rate, s.measured)))
}

/// Fits m̂ = (I+Σ)·m + b to pairs (known m, measured mean m̂). Errors:
/// [`GyroFitError::TooFewRates`], [`GyroFitError::RatesDegenerate`] (callers
/// with other known vectors rename them), [`NumericsError`].
pub fn linear_fit<I>(pairs: I) -> Result<LinearFit, GyroFitError>
where
    I: Iterator<Item = ([f64; 3], [f64; 3])> + Clone,
{
    let mut count = 0;
    for (segment, (known, measured)) in pairs.clone().enumerate() {
        count += 1;
        check_finite(segment, known.iter().chain(measured.iter()))?;
    }
    if count < MIN_GYRO_RATES {
        return Err(GyroFitError::TooFewRates {
            found: count,
            needed: MIN_GYRO_RATES,
        });
    }
    let (dimension, _) = spread(pairs.clone().map(|(known, _)| known), 1e-6);
    if dimension < 3 {
        return Err(GyroFitError::RatesDegenerate { dimension });
    }
    let mut axes = [GivensLs::<4>::new(); 3];
    for (known, measured) in pairs.clone() {
        let [wx, wy, wz] = known;
        for (ls, &y) in axes.iter_mut().zip(measured.iter()) {
            ls.add_row([wx, wy, wz, 1.0], y);
        }
    }
    let condition = axes[0].scaled_condition();
    check_condition(condition, MAX_CONDITION)?;
    let mut m = [[0.0; 3]; 3];
    let mut bias = [0.0; 3];
    for (i, ls) in axes.iter().enumerate() {
        let x = ls.solve().map_err(NumericsError::from)?;
        m[i] = [x[0], x[1], x[2]];
        bias[i] = x[3];
    }
    let dof = count - MIN_GYRO_RATES;
    let (sigma_m, sigma_b) = if dof > 0 {
        let inv = axes[0]
            .inverse_normal_matrix()
            .map_err(NumericsError::from)?;
        let mut sm = [[0.0; 3]; 3];
        let mut sb = [0.0; 3];
        for (i, ls) in axes.iter().enumerate() {
            let s2 = ls.residual_sum_of_squares() / dof as f64;
            for k in 0..3 {
                sm[i][k] = libm::sqrt(s2 * inv[k][k]);
            }
            sb[i] = libm::sqrt(s2 * inv[3][3]);
        }
        (Some(sm), Some(sb))
    } else {
        (None, None)
    };
    let mut sum_sq = 0.0;
    let mut worst = 0.0f64;
    for (known, measured) in pairs {
        for r in residual(&m, &bias, &known, &measured) {
            sum_sq += r * r;
            worst = worst.max(r.abs());
        }
    }
    Ok(LinearFit {
        scale_misalignment: m,
        bias,
        sigma_scale_misalignment: sigma_m,
        sigma_bias: sigma_b,
        residual_rms: libm::sqrt(sum_sq / (3 * count) as f64),
        residual_max: worst,
        segments: count,
        dof,
        condition,
    })
}
