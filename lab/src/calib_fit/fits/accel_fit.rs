//! Multi-position accelerometer calibration with unknown orientations
//! (the method of Tedaldi, Pretto & Menegatti, "A robust and easy to
//! implement method for IMU calibration without external equipments",
//! ICRA 2014, and Skog & Händel, "Calibration of a MEMS inertial measurement
//! unit", IMEKO XVII, 2006): at rest the true specific force has magnitude
//! g, so every static mean f̂ obeys |(I+Σ)⁻¹(f̂ − b)| = g.
//!
//! # The convention that fixes the unobservable rotation
//!
//! Magnitudes cannot see a rotation: if A satisfies |A(f̂ − b)| = g for
//! every orientation, so does R·A for any rotation R. Every invertible A is
//! uniquely R·T with T upper triangular with positive diagonal (a QR
//! factorisation of A), so the fit takes (I+Σ)⁻¹ = T: six parameters
//! `T00 T01 T02 T11 T12 T22` and the bias `b0 b1 b2`, nine in all. The file
//! then holds (I+Σ) = T⁻¹, also upper triangular. Its rows are the sensing
//! axes expressed in the corrected frame, so:
//!
//! - the corrected z axis is the accelerometer's z sensing axis
//!   ((I+Σ) row 2 = (0, 0, s_z));
//! - the corrected y axis is perpendicular to it, in the plane of the y and
//!   z sensing axes (row 1 = (0, s_y, m_yz));
//! - the corrected x axis completes the right-handed orthonormal frame; the
//!   x sensing axis may be misaligned in both directions (row 0 is full).
//!
//! A full (I+Σ) from a lab with known orientations equals this file's
//! (I+Σ) times a rotation (an RQ factorisation); both correct |f| exactly
//! alike and differ by a rotation of the output of order the misalignments.
//!
//! # Numerics
//!
//! f64 throughout. Levenberg–Marquardt with Marquardt's diagonal scaling,
//! each step solved by QR ([`GivensLs`]) with the damping as extra rows, so
//! JᵀJ is never formed. The start is the algebraic ellipsoid
//! ([`crate::calib_fit::numerics::ellipsoid`]). At the solution the covariance of the nine
//! parameters is s²·(JᵀJ)⁻¹, s² = Σr²/(n − 9), from the same QR.
//!
//! Every static mean weighs the same (unweighted least squares): give
//! segments of similar length, so their means have similar noise and s² is
//! the variance they share.

use core::fmt;

use crate::calib_fit::numerics::ellipsoid::{self, EllipsoidError};
use crate::calib_fit::numerics::error::{check_condition, check_finite, NumericsError};
use crate::calib_fit::numerics::levenberg_marquardt::{self, Problem};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::small3::{spread, Mat3};
use triad::model::matrix;

/// Static means whose directions are closer than this count as one
/// orientation. Two orientations 5° apart differ in gravity by 0.087·g per
/// axis, ≫ any MEMS calibration error (a few % scale, ≤ 0.1 misalignment
/// would be rejected anyway), so closer ones add little geometry.
pub const DISTINCT_ANGLE_DEG: f64 = 5.0;

/// The smallest RMS distance of the unit gravity directions from their
/// best-fitting plane: 0.05 ≈ every direction within ~3° of one circle on
/// the sphere. Below it the ellipsoid's extent across the plane is not
/// determined (a conic section of an ellipsoid fits infinitely many).
pub const MIN_OUT_OF_PLANE_RMS: f64 = 0.05;

/// The largest accepted condition number of the column-scaled Jacobian
/// ([`GivensLs::scaled_condition`]). κ relates the relative error of the
/// static means to that of the worst-determined parameter combination; a
/// means' relative noise of ~1e-5 (0.1 mg/g) at κ = 1e4 already gives 10 %
/// errors. Well-spread orientation sets measure κ ≈ 10..100.
pub const MAX_CONDITION: f64 = 1.0e4;

/// Iteration limit of Levenberg–Marquardt (from the algebraic start it
/// converges in a handful: the problem is nearly linear near the solution).
pub const MAX_ITERATIONS: u32 = 100;

/// The nine parameters: T00 T01 T02 T11 T12 T22 b0 b1 b2.
pub type Params = [f64; 9];

/// (row, column) of T for parameters 0..6.
pub const T_ENTRIES: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The result of [`fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelFit {
    /// (I+Σ)⁻¹ = T, upper triangular.
    pub inverse: Mat3,
    /// (I+Σ) = T⁻¹, upper triangular: what the calibration file holds.
    pub scale_misalignment: Mat3,
    /// b, m/s².
    pub bias: [f64; 3],
    /// The nine parameters (T entries, then b).
    pub params: Params,
    /// s²·(JᵀJ)⁻¹ of the parameters; `None` with no degree of freedom (n = 9).
    pub covariance: Option<[[f64; 9]; 9]>,
    /// Standard deviations of the entries of (I+Σ) = T⁻¹, by linear
    /// propagation (d(T⁻¹) = −T⁻¹·dT·T⁻¹); zero below the diagonal by convention.
    pub sigma_scale_misalignment: Option<Mat3>,
    /// Standard deviations of b, m/s².
    pub sigma_bias: Option<[f64; 3]>,
    /// RMS of |T(f̂ − b)| − g over the segments, m/s².
    pub residual_rms: f64,
    /// Largest | |T(f̂ − b)| − g |, m/s².
    pub residual_max: f64,
    /// Static segments used.
    pub segments: usize,
    /// Degrees of freedom of the σ's: segments − 9 parameters (one equation
    /// per segment: its magnitude).
    pub dof: usize,
    /// Distinct orientations among them.
    pub orientations: usize,
    /// Condition number of the column-scaled Jacobian at the solution.
    pub condition: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: u32,
}

/// T from the parameters.
pub fn t_of(p: &Params) -> Mat3 {
    [[p[0], p[1], p[2]], [0.0, p[3], p[4]], [0.0, 0.0, p[5]]]
}

/// |T(f̂ − b)| − g: the segment's residual, m/s².
pub fn residual(t: &Mat3, bias: &[f64; 3], mean: &[f64; 3], g: f64) -> f64 {
    let v = [mean[0] - bias[0], mean[1] - bias[1], mean[2] - bias[2]];
    norm(&matrix::mul_vec(t, &v)) - g
}

fn norm(v: &[f64; 3]) -> f64 {
    libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
}

/// The residual and its gradient with respect to the parameters.
fn residual_and_gradient(p: &Params, mean: &[f64; 3], g: f64) -> (f64, [f64; 9]) {
    let t = t_of(p);
    let v = [mean[0] - p[6], mean[1] - p[7], mean[2] - p[8]];
    let u = matrix::mul_vec(&t, &v);
    let n = norm(&u);
    let mut grad = [0.0; 9];
    for (gk, &(j, k)) in grad.iter_mut().zip(T_ENTRIES.iter()) {
        *gk = u[j] * v[k] / n;
    }
    for k in 0..3 {
        grad[6 + k] = -(u[0] * t[0][k] + u[1] * t[1][k] + u[2] * t[2][k]) / n;
    }
    (n - g, grad)
}

fn cost(p: &Params, means: &[[f64; 3]], g: f64) -> f64 {
    let t = t_of(p);
    let b = [p[6], p[7], p[8]];
    means
        .iter()
        .map(|m| {
            let r = residual(&t, &b, m, g);
            r * r
        })
        .sum()
}

/// The fewest distinct gravity directions the accelerometer fit accepts: 9
/// unknowns (6 of the triangular T, 3 of b), one equation |T(f̂−b)| = g per
/// orientation.
pub const MIN_ACCEL_ORIENTATIONS: usize = 9;

/// Why the accelerometer fit refused its static means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AccelFitError {
    /// The gravity given is not a positive finite number.
    InvalidGravity {
        /// The value in m/s².
        value: f64,
    },
    /// A static mean's magnitude is nowhere near g.
    NotNearGravity(NotNearGravity),
    /// Fewer distinct static orientations than the model's unknowns.
    TooFewOrientations {
        /// Static segments given.
        segments: usize,
        /// Distinct gravity directions among them (more than
        /// [`DISTINCT_ANGLE_DEG`] apart).
        found: usize,
        /// The minimum.
        needed: usize,
    },
    /// The gravity directions lie near one plane (a circle on the sphere):
    /// the ellipsoid is not determined across it.
    OrientationsInOnePlane {
        /// Distinct orientations found.
        orientations: usize,
        /// RMS distance of the unit directions from their best plane.
        out_of_plane_rms: f64,
        /// The smallest accepted RMS distance.
        needed: f64,
    },
    /// The algebraic ellipsoid fit that starts the iteration is not an
    /// ellipsoid (the data are not a sensor at rest in several orientations).
    NotAnEllipsoid,
    /// A value is not finite, the parameters are not determined, or the
    /// iteration did not converge.
    Numerics(NumericsError),
}

/// A static mean's magnitude is nowhere near g: not the sensor at rest in
/// gravity, or not in m/s² (a record in g gives |f̂| ≈ 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NotNearGravity {
    /// The segment (0-based).
    pub segment: usize,
    /// |f̂|, m/s².
    pub magnitude: f64,
    /// g, m/s².
    pub gravity: f64,
}

impl From<NumericsError> for AccelFitError {
    fn from(e: NumericsError) -> Self {
        AccelFitError::Numerics(e)
    }
}

impl From<NotNearGravity> for AccelFitError {
    fn from(e: NotNearGravity) -> Self {
        AccelFitError::NotNearGravity(e)
    }
}

impl From<EllipsoidError> for AccelFitError {
    fn from(e: EllipsoidError) -> Self {
        match e {
            EllipsoidError::Numerics(e) => AccelFitError::Numerics(e),
            EllipsoidError::NotAnEllipsoid => AccelFitError::NotAnEllipsoid,
        }
    }
}

impl fmt::Display for NotNearGravity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "static segment {}: |f̂| = {:.4} m/s² is outside 0.5..1.5 × g = {} m/s² \
             (not at rest, or the record is not in m/s²?)",
            self.segment + 1,
            self.magnitude,
            self.gravity
        )
    }
}

/// The refusal of a gravity that is not a positive finite number (m/s²).
pub(crate) fn write_invalid_gravity(f: &mut fmt::Formatter<'_>, value: f64) -> fmt::Result {
    write!(f, "gravity {value} m/s²: must be a positive finite number")
}

impl fmt::Display for AccelFitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AccelFitError::InvalidGravity { value } => write_invalid_gravity(f, *value),
            AccelFitError::NotNearGravity(e) => write!(f, "{e}"),
            AccelFitError::TooFewOrientations {
                segments,
                found,
                needed,
            } => write!(
                f,
                "found {found} distinct static orientation(s) in {segments} static segment(s); \
                 the accelerometer fit (9 unknowns: 6 scale/misalignment, 3 bias) needs at least {needed} \
                 distinct orientations, well spread over the sphere (a 6- or 24-position cube tumble \
                 gives only 6 gravity directions)"
            ),
            AccelFitError::OrientationsInOnePlane {
                orientations,
                out_of_plane_rms,
                needed,
            } => write!(
                f,
                "the {orientations} static orientations have gravity directions in one plane \
                 (RMS distance {out_of_plane_rms:.4} of the unit vectors from it, need ≥ {needed}): \
                 tilt the sensor out of that plane too"
            ),
            AccelFitError::NotAnEllipsoid => write!(
                f,
                "the static means do not lie on an ellipsoid around the origin \
                 (not a sensor at rest in several orientations?)"
            ),
            AccelFitError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// Checks one static mean: finite, and |f̂| within 0.5..1.5 g. The loader
/// accepts scale factors 0.5..1.5 (`model::validate`) and a bias is a few %
/// of g: outside that range it is no sensor at rest that could pass
/// validation (a record in g instead of m/s² gives |f̂| ≈ 1).
/// Each fit that takes static means wraps both refusals in its own error.
pub fn check_magnitude<E>(segment: usize, mean: &[f64; 3], g: f64) -> Result<(), E>
where
    E: From<NumericsError> + From<NotNearGravity>,
{
    check_finite(segment, mean)?;
    let magnitude = norm(mean);
    if !(0.5 * g..=1.5 * g).contains(&magnitude) {
        return Err(NotNearGravity {
            segment,
            magnitude,
            gravity: g,
        }
        .into());
    }
    Ok(())
}

/// The number of distinct directions among `means` (a mean counts when no
/// earlier one lies within [`DISTINCT_ANGLE_DEG`] of it).
pub fn distinct_orientations(means: &[[f64; 3]]) -> usize {
    let cos_limit = libm::cos(DISTINCT_ANGLE_DEG.to_radians());
    (0..means.len())
        .filter(|&i| {
            let a = &means[i];
            !means[..i].iter().any(|b| {
                let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                dot > cos_limit * norm(a) * norm(b)
            })
        })
        .count()
}

/// Checks the geometry before fitting: enough distinct orientations, not in one plane.
pub fn check_orientations(means: &[[f64; 3]]) -> Result<usize, AccelFitError> {
    let found = distinct_orientations(means);
    if found < MIN_ACCEL_ORIENTATIONS {
        return Err(AccelFitError::TooFewOrientations {
            segments: means.len(),
            found,
            needed: MIN_ACCEL_ORIENTATIONS,
        });
    }
    let units = means.iter().map(|m| {
        let n = norm(m);
        [m[0] / n, m[1] / n, m[2] / n]
    });
    let (_, out_of_plane) = spread(units, 1e-6);
    if out_of_plane.is_nan() || out_of_plane < MIN_OUT_OF_PLANE_RMS {
        return Err(AccelFitError::OrientationsInOnePlane {
            orientations: found,
            out_of_plane_rms: out_of_plane,
            needed: MIN_OUT_OF_PLANE_RMS,
        });
    }
    Ok(found)
}

/// Fits T and b to the static means (m/s²) for gravity `g` (m/s²).
pub fn fit(means: &[[f64; 3]], g: f64) -> Result<AccelFit, AccelFitError> {
    if !(g > 0.0 && g.is_finite()) {
        return Err(AccelFitError::InvalidGravity { value: g });
    }
    for (segment, m) in means.iter().enumerate() {
        check_magnitude::<AccelFitError>(segment, m, g)?;
    }
    let orientations = check_orientations(means)?;
    let (t0, b0, _) = ellipsoid::algebraic_fit(means, g)?;
    let start: Params = [
        t0[0][0], t0[0][1], t0[0][2], t0[1][1], t0[1][2], t0[2][2], b0[0], b0[1], b0[2],
    ];
    let (p, iterations) =
        levenberg_marquardt::minimise(&Magnitudes { means, g }, start, MAX_ITERATIONS)?;

    // The undamped QR at the solution: conditioning and covariance.
    let mut ls = GivensLs::<9>::new();
    let mut sum_sq = 0.0;
    let mut worst = 0.0f64;
    for m in means {
        let (r, grad) = residual_and_gradient(&p, m, g);
        ls.add_row(grad, -r);
        sum_sq += r * r;
        worst = worst.max(r.abs());
    }
    let condition = ls.scaled_condition();
    check_condition(condition, MAX_CONDITION)?;
    let dof = means.len().saturating_sub(9);
    let covariance = if dof > 0 {
        let s2 = sum_sq / dof as f64;
        let inv = ls.inverse_normal_matrix().map_err(NumericsError::from)?;
        Some(inv.map(|row| row.map(|x| x * s2)))
    } else {
        None
    };
    let t = t_of(&p);
    let mut m = matrix::inverse(&t).ok_or(AccelFitError::NotAnEllipsoid)?;
    // T⁻¹ of an upper triangular T is upper triangular: make the zeros exact (no −0).
    m[1][0] = 0.0;
    m[2][0] = 0.0;
    m[2][1] = 0.0;
    for row in m.iter_mut() {
        for x in row.iter_mut() {
            *x += 0.0;
        }
    }
    let sigma_scale_misalignment = covariance.as_ref().map(|c| sigma_of_inverse(&m, c));
    let sigma_bias = covariance
        .as_ref()
        .map(|c| [0, 1, 2].map(|k| libm::sqrt(c[6 + k][6 + k])));
    Ok(AccelFit {
        inverse: t,
        scale_misalignment: m,
        bias: [p[6], p[7], p[8]],
        params: p,
        covariance,
        sigma_scale_misalignment,
        sigma_bias,
        residual_rms: libm::sqrt(sum_sq / means.len() as f64),
        residual_max: worst,
        segments: means.len(),
        dof,
        orientations,
        condition,
        iterations,
    })
}

/// Standard deviations of the entries of M = T⁻¹: ∂M/∂T_jk = −M·E_jk·M,
/// so ∂M_ac/∂T_jk = −M_aj·M_kc.
fn sigma_of_inverse(m: &Mat3, c: &[[f64; 9]; 9]) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (a, row) in out.iter_mut().enumerate() {
        for (col, s) in row.iter_mut().enumerate() {
            let mut g = [0.0; 6];
            for (gk, &(j, k)) in g.iter_mut().zip(T_ENTRIES.iter()) {
                *gk = -m[a][j] * m[k][col];
            }
            let mut var = 0.0;
            for (i, gi) in g.iter().enumerate() {
                for (l, gl) in g.iter().enumerate() {
                    var += gi * c[i][l] * gl;
                }
            }
            *s = libm::sqrt(var.max(0.0));
        }
    }
    out
}

/// The magnitudes' least-squares problem for [`levenberg_marquardt::minimise`].
struct Magnitudes<'a> {
    means: &'a [[f64; 3]],
    g: f64,
}

impl Problem<9> for Magnitudes<'_> {
    fn cost(&self, p: &Params) -> f64 {
        cost(p, self.means, self.g)
    }
    fn rows(&self, p: &Params, row: &mut dyn FnMut([f64; 9], f64)) {
        for m in self.means {
            let (r, grad) = residual_and_gradient(p, m, self.g);
            row(grad, r);
        }
    }
}
