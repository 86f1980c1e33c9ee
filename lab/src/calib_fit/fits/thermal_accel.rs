//! The accelerometer against temperature from static poses in unknown
//! orientations at several temperatures: one fit of
//!
//!   |(I+Σ)(ΔT)⁻¹·(f̂ − b(ΔT))| = g,  (I+Σ)(ΔT) = (I+Σ)₀ + ΔT·D,
//!   b(ΔT) = b₀ + c₁ΔT + c₂ΔT² + c₃ΔT³ (per axis),
//!
//! over every static segment at its own mean temperature (a soak or a
//! ramp alike). The gravity direction of each pose is unknown and never
//! estimated: the magnitude does not depend on it, which is what separates
//! b(T) and (I+Σ)(T) from the orientation (the method of
//! [`crate::calib_fit::fits::accel_fit`], extended in temperature).
//!
//! # Convention
//!
//! As in [`crate::calib_fit::fits::accel_fit`], magnitudes cannot see a rotation of the
//! output, so (I+Σ)₀ and D are upper triangular (6 entries each): at every
//! temperature the corrected z axis is the z sensing axis and the
//! corrected y axis lies in the plane of the y and z sensing axes. A lab's
//! full (I+Σ)(T) equals this one times a rotation that may itself change
//! with T (by ~|D|·|misalignment| per °C); the magnitudes, and so gravity
//! and every static reading, are corrected alike.
//!
//! # Parameters, numerics and σ's
//!
//! 24 parameters: the 6 of (I+Σ)₀, the 6 of D, b₀, and c₁..c₃ per axis;
//! those the temperatures do not support ([`crate::calib_fit::fits::thermal_coverage`]) are
//! held at zero (each by a unit row of its own, which leaves the fitted
//! block of (JᵀJ)⁻¹ as if it were absent). Levenberg–Marquardt from the
//! single-temperature fit of all the means ([`crate::calib_fit::fits::accel_fit::fit`]),
//! analytic Jacobian: with u = (I+Σ)⁻¹v, v = f̂ − b, w = (I+Σ)⁻ᵀu/|u|,
//! ∂r/∂(I+Σ)_jk = −w_j·u_k (times ΔT for D) and ∂r/∂b_i = −w_i (times ΔTᵏ
//! for cᵢₖ). Each residual is weighed by 1/its standard error (the
//! segment mean's errors along its gravity direction), so segments of
//! different lengths count as they should; the covariance is
//! s²·(JᵀJ)⁻¹ with s² = Σ(r/σ)²/(segments − parameters fitted), which
//! are its degrees of freedom.

use core::fmt;

use crate::calib_fit::fits::accel_fit::{self, AccelFitError, T_ENTRIES};
use crate::calib_fit::fits::bias_polynomial::StaticMean;
use crate::calib_fit::numerics::error::{check_condition, check_finite, NumericsError};
use crate::calib_fit::numerics::levenberg_marquardt::{self, Problem};
use crate::calib_fit::numerics::qr::{GivensLs, LsError};
use crate::calib_fit::numerics::small3::Mat3;
use triad::model::matrix;

/// Why the accelerometer's fit across temperature refused its segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThermalAccelError {
    /// The single-temperature fit of all the means, the start, refused
    /// them (their geometry, gravity, or its numerics).
    Start(AccelFitError),
    /// A value is not finite, the parameters are not determined (or no
    /// degree of freedom is left), or the iteration did not converge.
    Numerics(NumericsError),
}

impl From<NumericsError> for ThermalAccelError {
    fn from(e: NumericsError) -> Self {
        ThermalAccelError::Numerics(e)
    }
}

impl From<AccelFitError> for ThermalAccelError {
    fn from(e: AccelFitError) -> Self {
        ThermalAccelError::Start(e)
    }
}

impl fmt::Display for ThermalAccelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalAccelError::Start(e) => write!(f, "{e}"),
            ThermalAccelError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// Parameters: (I+Σ)₀ (6), D (6), b₀ (3), c per axis and order (9).
pub const PARAMETERS: usize = 24;

/// Index of the first entry of D.
const D_AT: usize = 6;
/// Index of b₀.
const B_AT: usize = 12;
/// Index of c₁ of axis 0; cᵢₖ is at C_AT + 3·i + k − 1.
const C_AT: usize = 15;

/// The largest accepted condition number of the column-scaled Jacobian.
/// Higher than the single-temperature fit's ([`accel_fit::MAX_CONDITION`])
/// because the powers of ΔT are correlated with each other even on a
/// centred range (ΔT and ΔT³ over ±h: correlation 0.92); beyond it the
/// σ's of some combination are 1e5 times the noise.
pub const MAX_CONDITION: f64 = 1.0e5;

/// What is fitted besides (I+Σ)₀ and b₀.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms {
    /// T_ref, °C.
    pub reference_c: f64,
    /// Order of the bias polynomial (0..=3).
    pub bias_order: usize,
    /// Whether D is fitted.
    pub scale: bool,
}

/// The result of [`fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalAccelFit {
    /// The terms fitted.
    pub terms: Terms,
    /// (I+Σ)₀ = (I+Σ)(T_ref), upper triangular.
    pub scale_misalignment: Mat3,
    /// σ's of (I+Σ)₀.
    pub sigma_scale_misalignment: Mat3,
    /// D = d(I+Σ)/dT, 1/°C, upper triangular (zero when not fitted).
    pub scale_misalignment_per_c: Mat3,
    /// σ's of D.
    pub sigma_scale_misalignment_per_c: Mat3,
    /// b₀, m/s².
    pub bias: [f64; 3],
    /// σ's of b₀.
    pub sigma_bias: [f64; 3],
    /// [c₁, c₂, c₃] per axis.
    pub bias_coefficients: Mat3,
    /// Their σ's.
    pub sigma_bias_coefficients: Mat3,
    /// Segments fitted.
    pub segments: usize,
    /// Degrees of freedom of every σ: segments − parameters fitted.
    pub dof: usize,
    /// Parameters fitted.
    pub fitted: usize,
    /// RMS of |(I+Σ)⁻¹(f̂ − b)| − g, m/s².
    pub residual_rms: f64,
    /// Largest such residual, m/s².
    pub residual_max: f64,
    /// s²: the weighted residuals' variance (≈ 1 when the segments scatter
    /// as their white-noise errors say).
    pub variance_factor: f64,
    /// Condition number of the column-scaled Jacobian.
    pub condition: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: u32,
    /// The 24 parameters ((I+Σ)₀, D, b₀, c), zero where not fitted.
    pub params: [f64; PARAMETERS],
    /// Their covariance s²·(JᵀJ)⁻¹ (zero rows and columns where not fitted).
    pub covariance: [[f64; PARAMETERS]; PARAMETERS],
}

/// The unit gravity direction of a static mean (m/s²) at `temperature_c`
/// in the accelerometer's corrected frame, for parameters `p` about
/// `reference_c`: (I+Σ)(ΔT)⁻¹(f̂ − b(ΔT)), normalised.
pub fn up(
    p: &[f64; PARAMETERS],
    reference_c: f64,
    mean: &[f64; 3],
    temperature_c: f64,
) -> [f64; 3] {
    let (m, b) = at(p, temperature_c - reference_c);
    let v = [0, 1, 2].map(|i| mean[i] - b[i]);
    let u = matrix::solve(&m, &v).unwrap_or([f64::NAN; 3]);
    crate::calib_fit::fits::rig_free::unit(u)
}

/// Which parameters `terms` fits.
fn active(terms: &Terms) -> [bool; PARAMETERS] {
    core::array::from_fn(|k| match k {
        0..D_AT => true,
        D_AT..B_AT => terms.scale,
        B_AT..C_AT => true,
        _ => (k - C_AT) % 3 < terms.bias_order,
    })
}

fn upper(p: &[f64]) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (x, &(j, k)) in p.iter().zip(T_ENTRIES.iter()) {
        m[j][k] = *x;
    }
    m
}

/// (I+Σ)(ΔT) and b(ΔT) at parameters `p`.
fn at(p: &[f64; PARAMETERS], delta: f64) -> (Mat3, [f64; 3]) {
    let m0 = upper(&p[..D_AT]);
    let d = upper(&p[D_AT..B_AT]);
    let m = core::array::from_fn(|i| core::array::from_fn(|j| m0[i][j] + delta * d[i][j]));
    let b = core::array::from_fn(|i| {
        let c = &p[C_AT + 3 * i..C_AT + 3 * i + 3];
        p[B_AT + i] + delta * (c[0] + delta * (c[1] + delta * c[2]))
    });
    (m, b)
}

struct Problem24<'a> {
    segments: &'a [StaticMean],
    weights: &'a [f64],
    g: f64,
    reference_c: f64,
    active: [bool; PARAMETERS],
}

impl Problem24<'_> {
    /// The unweighted residual of segment `s` and the gradient of the
    /// weighted one; NaN when (I+Σ)(ΔT) is singular.
    fn residual(&self, p: &[f64; PARAMETERS], s: usize) -> (f64, [f64; PARAMETERS]) {
        let seg = &self.segments[s];
        let delta = seg.temperature_c - self.reference_c;
        let (m, b) = at(p, delta);
        let v = [0, 1, 2].map(|i| seg.mean[i] - b[i]);
        let Some(m_inv) = matrix::inverse(&m) else {
            return (f64::NAN, [0.0; PARAMETERS]);
        };
        let u = matrix::mul_vec(&m_inv, &v);
        let n = libm::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        let w = matrix::mul_transpose_vec(&m_inv, &u.map(|x| x / n));
        let weight = self.weights[s];
        let mut grad = [0.0; PARAMETERS];
        for (e, &(j, k)) in T_ENTRIES.iter().enumerate() {
            grad[e] = -w[j] * u[k];
            grad[D_AT + e] = -delta * w[j] * u[k];
        }
        for i in 0..3 {
            grad[B_AT + i] = -w[i];
            let mut power = 1.0;
            for k in 0..3 {
                power *= delta;
                grad[C_AT + 3 * i + k] = -w[i] * power;
            }
        }
        for (g, on) in grad.iter_mut().zip(self.active) {
            *g = if on { *g * weight } else { 0.0 };
        }
        (n - self.g, grad)
    }
}

impl Problem<PARAMETERS> for Problem24<'_> {
    fn cost(&self, p: &[f64; PARAMETERS]) -> f64 {
        let mut c = 0.0;
        self.rows(p, &mut |_, r| c += r * r);
        if c.is_nan() {
            f64::INFINITY
        } else {
            c
        }
    }

    fn rows(&self, p: &[f64; PARAMETERS], row: &mut dyn FnMut([f64; PARAMETERS], f64)) {
        for s in 0..self.segments.len() {
            let (r, grad) = self.residual(p, s);
            row(grad, r * self.weights[s]);
        }
        for k in (0..PARAMETERS).filter(|&k| !self.active[k]) {
            let mut pin = [0.0; PARAMETERS];
            pin[k] = 1.0;
            row(pin, p[k]);
        }
    }
}

/// The standard error of a segment's magnitude: its axes' errors along its
/// gravity direction.
fn magnitude_error(s: &StaticMean) -> f64 {
    let n = libm::sqrt(s.mean.iter().map(|x| x * x).sum::<f64>());
    let var: f64 = (0..3)
        .map(|i| {
            let e = s.mean[i] / n * s.standard_error[i];
            e * e
        })
        .sum();
    libm::sqrt(var)
}

/// Fits the accelerometer's `terms` to `segments` for gravity `g`;
/// `weights` is scratch of one entry per segment.
pub fn fit(
    segments: &[StaticMean],
    g: f64,
    terms: Terms,
    means: &mut [[f64; 3]],
    weights: &mut [f64],
) -> Result<ThermalAccelFit, ThermalAccelError> {
    let n = segments.len().min(means.len()).min(weights.len());
    let segments = &segments[..n];
    for (segment, s) in segments.iter().enumerate() {
        check_finite(segment, s.standard_error.iter().chain([&s.temperature_c]))?;
        means[segment] = s.mean;
    }
    // The start, and the geometry's refusals: one fit of all the means.
    let start = accel_fit::fit(&means[..n], g)?;
    let errors_floor = segments.iter().map(magnitude_error).fold(0.0f64, f64::max) * 1e-6;
    for (w, s) in weights.iter_mut().zip(segments) {
        *w = 1.0 / magnitude_error(s).max(errors_floor).max(f64::MIN_POSITIVE);
    }
    let active = active(&terms);
    let fitted = active.iter().filter(|&&a| a).count();
    let problem = Problem24 {
        segments,
        weights: &weights[..n],
        g,
        reference_c: terms.reference_c,
        active,
    };
    let mut p0 = [0.0; PARAMETERS];
    for (e, &(j, k)) in T_ENTRIES.iter().enumerate() {
        p0[e] = start.scale_misalignment[j][k];
    }
    p0[B_AT..C_AT].copy_from_slice(&start.bias);
    let (p, iterations) = levenberg_marquardt::minimise(&problem, p0, accel_fit::MAX_ITERATIONS)?;

    let mut ls = GivensLs::<PARAMETERS>::new();
    problem.rows(&p, &mut |grad, r| ls.add_row(grad, -r));
    let condition = ls.scaled_condition();
    check_condition(condition, MAX_CONDITION)?;
    let dof = n.saturating_sub(fitted);
    if dof == 0 {
        return Err(NumericsError::LeastSquares(LsError::TooFewRows {
            rows: n,
            unknowns: fitted + 1,
        })
        .into());
    }
    let (mut sum_sq, mut weighted_sq, mut worst) = (0.0, 0.0, 0.0f64);
    for (s, w) in weights[..n].iter().enumerate() {
        let (r, _) = problem.residual(&p, s);
        sum_sq += r * r;
        weighted_sq += r * r * w * w;
        worst = worst.max(r.abs());
    }
    let s2 = weighted_sq / dof as f64;
    let inv = ls.inverse_normal_matrix().map_err(NumericsError::from)?;
    let sigma = |k: usize| {
        if active[k] {
            libm::sqrt(s2 * inv[k][k])
        } else {
            0.0
        }
    };
    let sigmas: [f64; PARAMETERS] = core::array::from_fn(sigma);
    let coefficients = |v: &[f64; PARAMETERS]| -> Mat3 {
        core::array::from_fn(|i| core::array::from_fn(|k| v[C_AT + 3 * i + k]))
    };
    Ok(ThermalAccelFit {
        terms,
        scale_misalignment: upper(&p[..D_AT]),
        sigma_scale_misalignment: upper(&sigmas[..D_AT]),
        scale_misalignment_per_c: upper(&p[D_AT..B_AT]).map(|r| r.map(|x| x + 0.0)),
        sigma_scale_misalignment_per_c: upper(&sigmas[D_AT..B_AT]),
        bias: [p[B_AT], p[B_AT + 1], p[B_AT + 2]],
        sigma_bias: [sigmas[B_AT], sigmas[B_AT + 1], sigmas[B_AT + 2]],
        bias_coefficients: coefficients(&p).map(|r| r.map(|x| x + 0.0)),
        sigma_bias_coefficients: coefficients(&sigmas),
        segments: n,
        dof,
        fitted,
        residual_rms: libm::sqrt(sum_sq / n as f64),
        residual_max: worst,
        variance_factor: s2,
        condition,
        iterations,
        params: p,
        covariance: core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                if active[i] && active[j] {
                    s2 * inv[i][j]
                } else {
                    0.0
                }
            })
        }),
    })
}
