//! Rig-free gyroscope calibration from one hand-rotated record (the method
//! of Tedaldi, Pretto & Menegatti, "A robust and easy to implement method
//! for IMU calibration without external equipments", ICRA 2014): the unit
//! rests in a pose, is turned by hand, rests again, and so on.
//!
//! 1. The accelerometer is fitted first ([`crate::calib_fit::fits::accel_fit`]) from the
//!    poses' static means; its corrected frame is the frame of the result.
//! 2. The poses' gyro means give the g-sensitivity G where the poses
//!    support one ([`g_sensitivity`]); each pose is checked against what the
//!    others predict for it (their bias and G), and one that strays is
//!    refused (the unit turned about the vertical during it). The gyro bias
//!    is then the fit's intercept when the poses show a G, else the mean of
//!    the poses' gyro means, its σ the scatter of those means over
//!    √(poses), with poses − 1 degrees of freedom: drift of the bias from
//!    pose to pose (correlated noise) is in it, not only white noise.
//! 3. The gyro's (I+Σ), all nine entries: for each move from pose j to pose
//!    j+1 the corrected rate ω = (I+Σ)⁻¹(ω̂ − b) is integrated from the last
//!    sample of pose j to the first of pose j+1 (RK4 on the quaternion at
//!    the record's own rate, [`quaternion::rk4_step`]), which predicts where
//!    pose j's gravity direction u_j lies at pose j+1; the residual is the
//!    predicted minus the measured direction u_{j+1}, its two components
//!    across u_{j+1} (along u_{j+1} it is second order). Levenberg–Marquardt
//!    ([`levenberg_marquardt`]) from (I+Σ) = I over all moves, with the
//!    Jacobian from one pass over each move ([`turn_sensitivity`]);
//!    covariance s²·(JᵀJ)⁻¹ with
//!    2·moves − 9 degrees of freedom. With a G the bias during a move is
//!    c + G·f, f interpolated from one pose's specific force to the next's
//!    (normalised linear interpolation of the direction, linear in magnitude).
//!
//! The gravity directions come from the fitted accelerometer, whose error
//! (common to all poses) is not in the gyro's σ's; nor is the bias's (its
//! effect, σ_b × the duration of a turn, is small beside the noise
//! integrated over the turn). The caller owns the record.

use alloc::vec::Vec;
use core::fmt;

use crate::calib_fit::fits::accel_fit::{self, AccelFit};
use crate::calib_fit::fits::g_sensitivity::{
    self, AtRest, Consistency, PoseMean, PoseNotStatic, Support,
};
use crate::calib_fit::fits::turn_refusals::{RangeError, TooFastForRate, TooFewRotations};
use crate::calib_fit::fits::turn_sensitivity;
use crate::calib_fit::numerics::error::{check_condition, NumericsError};
use crate::calib_fit::numerics::levenberg_marquardt::{self, Problem};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::quaternion::{self, Quat};
use crate::calib_fit::numerics::small3::{symmetric_eigenvalues, Mat3};
use crate::calib_fit::static_segments::Segment;
use triad::model::matrix;

/// The fewest turns the gyro fit accepts: 9 unknowns, 2 equations per turn,
/// so 5 turns leave one degree of freedom.
pub const MIN_ROTATIONS: usize = 5;

/// A move between poses counts as a turn when it turns by at least this
/// (degrees): smaller ones carry little about (I+Σ) and their axis is noise.
pub const MIN_TURN_DEG: f64 = 10.0;

/// The smallest accepted eigenvalue of the scatter of the turns' unit axes
/// (mean of a·aᵀ, trace 1): 0.05 ≈ RMS 13° of the axes out of their best
/// plane. Axes spread evenly give 1/3 each.
pub const MIN_AXIS_SPREAD: f64 = 0.05;

/// The gyro may read at most this fraction of its full scale: nearer, a
/// turn's peak may have clipped (the sample and its neighbours lose rate
/// the integration cannot recover).
pub const MAX_RANGE_FRACTION: f64 = 0.9;

/// The largest rotation between two samples, degrees. The integrator takes
/// the rate as linear between samples; on smooth synthetic turns at this
/// limit its error is 2e-10 rad (the test `integration_error_at_the_rate_limit`),
/// so the limit guards real turns, whose rate need not be smooth within a
/// sample (hand jerks, the sensor's output filter): at 3° per sample a rate
/// change of 10 % within one sample already moves the turn by 0.3°·0.1/2 ≈
/// 3e-4 rad, above the noise a MEMS gyro integrates over a turn (~1e-4 rad).
pub const MAX_ROTATION_PER_SAMPLE_DEG: f64 = 3.0;

/// The largest accepted condition number of the column-scaled Jacobian
/// (see [`crate::calib_fit::fits::accel_fit::MAX_CONDITION`]).
pub const MAX_CONDITION: f64 = 1.0e4;

/// Iteration limit of Levenberg–Marquardt.
pub const MAX_ITERATIONS: u32 = 100;

/// Step of the central differences on the accelerometer's parameters (≈ 1
/// and ≈ 0.1): the truncation error ∝ h² and the rounding error ∝ ε/h
/// balance near 1e-5..1e-6.
const DERIVATIVE_STEP: f64 = 1.0e-6;

/// The record: sample times (s) and gyro samples (rad/s).
#[derive(Clone, Copy, Debug)]
pub struct Record<'a> {
    /// Times, s, increasing.
    pub t: &'a [f64],
    /// Gyro samples, rad/s.
    pub gyro: &'a [[f64; 3]],
}

/// The result of [`fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigFreeGyroFit {
    /// The gyro's (I+Σ) in the accelerometer's corrected frame.
    pub scale_misalignment: Mat3,
    /// b, rad/s.
    pub bias: [f64; 3],
    /// σ of (I+Σ); `None` with no degree of freedom.
    pub sigma_scale_misalignment: Option<Mat3>,
    /// σ of b, rad/s (scatter of the pose means).
    pub sigma_bias: Option<[f64; 3]>,
    /// Poses (static segments).
    pub segments: usize,
    /// Moves between consecutive poses (poses − 1), all fitted.
    pub rotations: usize,
    /// Those that turn by ≥ [`MIN_TURN_DEG`].
    pub turns: usize,
    /// Degrees of freedom of the (I+Σ) σ's: the smallest of
    /// [`Self::dof_entries`], rounded down.
    pub dof: usize,
    /// Effective degrees of freedom of each entry's σ (Welch–Satterthwaite
    /// of the gyro's own 2·rotations − 9 and the accelerometer fit's).
    pub dof_entries: Option<Mat3>,
    /// Degrees of freedom of the gyro's own residuals: 2·rotations − 9.
    pub gyro_dof: usize,
    /// Degrees of freedom of the bias σ's: poses − 1, or poses − 4 when the
    /// bias is the intercept of a fit with G.
    pub bias_dof: usize,
    /// RMS of the direction residuals, rad.
    pub residual_rms: f64,
    /// Largest |direction residual component|, rad.
    pub residual_max: f64,
    /// Condition number of the column-scaled Jacobian at the solution.
    pub condition: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: u32,
    /// The smallest and middle eigenvalues of the turns' axis scatter.
    pub axis_spread: [f64; 2],
    /// The largest rotation between two samples, degrees.
    pub max_rotation_per_sample_deg: f64,
    /// The largest |gyro axis| in the record, rad/s.
    pub peak_rate: f64,
    /// The g-sensitivity G from the poses, or why they do not give one; the
    /// fit (bias, turns) used it when [`Support::applied`].
    pub g_sensitivity: Support,
    /// How the poses were checked against each other.
    pub pose_check: Consistency,
}

/// The gyro's bias during a move from one pose to the next: constant, or
/// c + G·f with f going from the first pose's specific force to the second's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveBias {
    /// c (the bias at f = 0), rad/s.
    pub bias: [f64; 3],
    /// G and the two poses' specific forces, m/s²; `None` for a constant bias.
    pub g_sensitivity: Option<(Mat3, [[f64; 3]; 2])>,
}

impl MoveBias {
    /// A bias that does not change during the move.
    pub fn constant(bias: [f64; 3]) -> MoveBias {
        MoveBias {
            bias,
            g_sensitivity: None,
        }
    }

    /// The bias at fraction `s` (0..=1) of the move.
    fn at(&self, s: f64) -> [f64; 3] {
        let Some((g, forces)) = &self.g_sensitivity else {
            return self.bias;
        };
        let gf = matrix::mul_vec(g, &force_along(forces, s));
        [0, 1, 2].map(|i| self.bias[i] + gf[i])
    }
}

/// The specific force at fraction `s` of a move from `from` to `to`: the
/// direction interpolated linearly and normalised, the magnitude linear.
pub(crate) fn force_along([from, to]: &[[f64; 3]; 2], s: f64) -> [f64; 3] {
    let norm = |v: &[f64; 3]| libm::sqrt(dot(v, v));
    let mixed = [0, 1, 2].map(|i| from[i] + s * (to[i] - from[i]));
    let magnitude = norm(from) + s * (norm(to) - norm(from));
    let n = norm(&mixed);
    if n > 0.0 {
        mixed.map(|x| x * magnitude / n)
    } else {
        mixed
    }
}

/// The unit gravity direction of a pose in the accelerometer's corrected
/// frame, for accelerometer parameters `a` ([`accel_fit::Params`]).
fn up(a: &accel_fit::Params, mean: &[f64; 3]) -> [f64; 3] {
    unit(force(a, mean))
}

/// The specific force of a pose in the accelerometer's corrected frame, m/s².
fn force(a: &accel_fit::Params, mean: &[f64; 3]) -> [f64; 3] {
    let v = [0, 1, 2].map(|i| mean[i] - a[6 + i]);
    matrix::mul_vec(&accel_fit::t_of(a), &v)
}

pub(crate) fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = libm::sqrt(dot(&v, &v));
    v.map(|x| x / n)
}

pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Two unit vectors across `u` (fixed by `u` alone, not by the parameters).
pub(crate) fn across(u: &[f64; 3]) -> [[f64; 3]; 2] {
    let k = (0..3)
        .min_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let e1 = unit(cross(u, &e));
    [e1, cross(u, &e1)]
}

/// The turn from the last sample of `from` to the first of `to`, integrating
/// (I+Σ)⁻¹(ω̂ − b) = `k`·(ω̂ − b), b as `bias` gives it along the move.
pub(crate) fn integrate(
    record: &Record,
    from: &Segment,
    to: &Segment,
    k: &Mat3,
    bias: &MoveBias,
) -> Quat {
    integrate_observed(record, from, to, k, bias, |_| {})
}

/// One sample of a move as [`integrate_observed`] passes it on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MoveSample {
    /// The attitude at the sample (identity at the move's first sample).
    pub q: Quat,
    /// The corrected rate (I+Σ)⁻¹(ω̂ − b), rad/s.
    pub rate: [f64; 3],
    /// The fraction of the move's time, 0..=1.
    pub s: f64,
    /// The sample's trapezoid weight in an integral over the move, s.
    pub weight: f64,
}

/// [`integrate`], passing every sample of the move to `observe` (for the
/// turn's derivatives, [`crate::calib_fit::fits::turn_sensitivity`]).
pub(crate) fn integrate_observed(
    record: &Record,
    from: &Segment,
    to: &Segment,
    k: &Mat3,
    bias: &MoveBias,
    mut observe: impl FnMut(&MoveSample),
) -> Quat {
    let (first, last) = (from.end - 1, to.start);
    let (t0, t1) = (record.t[first], record.t[last]);
    let rate = |i: usize| {
        let w = record.gyro[i];
        let s = ((record.t[i] - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let b = bias.at(s);
        (
            matrix::mul_vec(k, &[w[0] - b[0], w[1] - b[1], w[2] - b[2]]),
            s,
        )
    };
    let mut q = quaternion::IDENTITY;
    let (mut w0, mut s0) = rate(first);
    let mut dt_before = 0.0;
    for i in first..last {
        let (w1, s1) = rate(i + 1);
        let dt = record.t[i + 1] - record.t[i];
        observe(&MoveSample {
            q,
            rate: w0,
            s: s0,
            weight: 0.5 * (dt_before + dt),
        });
        q = quaternion::rk4_step(&q, &w0, &w1, dt);
        (w0, s0, dt_before) = (w1, s1, dt);
    }
    observe(&MoveSample {
        q,
        rate: w0,
        s: s0,
        weight: 0.5 * dt_before,
    });
    q
}

fn matrix_of(p: &[f64; 9]) -> Mat3 {
    [[p[0], p[1], p[2]], [p[3], p[4], p[5]], [p[6], p[7], p[8]]]
}

/// The moves' direction residuals as a least-squares problem in the nine
/// entries of (I+Σ), row by row.
struct Moves<'a> {
    record: Record<'a>,
    poses: &'a [Segment],
    /// The moves used.
    used: Used<'a>,
    accel_means: &'a [[f64; 3]],
    accel: &'a AccelFit,
    bias: [f64; 3],
    /// G when the poses show one.
    g_sensitivity: Option<Mat3>,
}

impl Moves<'_> {
    /// The two residuals of the `m`th used move (pose j to j+1) at (I+Σ) =
    /// `p`; NaN when (I+Σ) is singular.
    fn residuals(&self, m: usize, p: &[f64; 9]) -> [f64; 2] {
        let j = self.used.get(m);
        let Some(k) = matrix::inverse(&matrix_of(p)) else {
            return [f64::NAN; 2];
        };
        let a = &self.accel.params;
        let q = integrate(
            &self.record,
            &self.poses[j],
            &self.poses[j + 1],
            &k,
            &self.move_bias(a, j),
        );
        self.residuals_after(j, &q, a)
    }

    fn move_bias(&self, a: &accel_fit::Params, j: usize) -> MoveBias {
        move_bias(self.bias, self.g_sensitivity, a, self.accel_means, j)
    }

    /// Move j's residuals once turned by `q`, with the accelerometer's
    /// parameters `a`: the predicted minus the measured gravity direction,
    /// across the measured.
    fn residuals_after(&self, j: usize, q: &Quat, a: &accel_fit::Params) -> [f64; 2] {
        let before = up(a, &self.accel_means[j]);
        let after = up(a, &self.accel_means[j + 1]);
        let predicted = quaternion::rotate_inverse(q, &before);
        let d = [0, 1, 2].map(|i| predicted[i] - after[i]);
        across(&after).map(|e| dot(&d, &e))
    }

    /// The `m`th used move integrated once with its sensitivities
    /// ([`turn_sensitivity`]), G's force terms only when `forces`.
    fn turn(&self, m: usize, p: &[f64; 9], forces: bool) -> Option<Turn> {
        let j = self.used.get(m);
        let k = matrix::inverse(&matrix_of(p))?;
        let a = &self.accel.params;
        let bias = self.move_bias(a, j);
        let kg = match (forces, bias.g_sensitivity) {
            (true, Some((g, f))) => Some((matrix::mul(&k, &g), f)),
            _ => None,
        };
        let mut gather = turn_sensitivity::Accumulator::new(kg);
        let q = integrate_observed(
            &self.record,
            &self.poses[j],
            &self.poses[j + 1],
            &k,
            &bias,
            |s| gather.add(s),
        );
        Some(Turn {
            j,
            k,
            q,
            sensitivity: gather.finish(),
        })
    }

    /// The residuals of a turn and their gradient in (I+Σ) (analytic,
    /// [`turn_sensitivity::scale_gradient`]).
    fn gyro_rows(&self, turn: &Turn) -> ([f64; 2], [[f64; 9]; 2]) {
        let a = &self.accel.params;
        let before = up(a, &self.accel_means[turn.j]);
        let after = up(a, &self.accel_means[turn.j + 1]);
        let predicted = quaternion::rotate_inverse(&turn.q, &before);
        let grad = turn_sensitivity::scale_gradient(
            &turn.sensitivity,
            &turn.q,
            &turn.k,
            &predicted,
            &across(&after),
        );
        (self.residuals_after(turn.j, &turn.q, a), grad)
    }

    /// The gradient of a turn's residuals in the accelerometer's parameters
    /// (gathered with `forces`): through the gravity directions by central
    /// differences at the integrated turn (no re-integration), and, with G,
    /// through the bias's forces ([`turn_sensitivity::force_turn`]).
    fn accel_rows(&self, turn: &Turn) -> [[f64; 9]; 2] {
        let a = self.accel.params;
        let after = up(&a, &self.accel_means[turn.j + 1]);
        let predicted = quaternion::rotate_inverse(&turn.q, &up(&a, &self.accel_means[turn.j]));
        let e = across(&after);
        let mut out = [[0.0; 9]; 2];
        for k in 0..9 {
            let shifted = |h: f64| {
                let mut pa = a;
                pa[k] += h;
                pa
            };
            let (plus, minus) = (shifted(DERIVATIVE_STEP), shifted(-DERIVATIVE_STEP));
            let (rp, rm) = (
                self.residuals_after(turn.j, &turn.q, &plus),
                self.residuals_after(turn.j, &turn.q, &minus),
            );
            let d_force = |q: usize| {
                let (fp, fm) = (
                    force(&plus, &self.accel_means[q]),
                    force(&minus, &self.accel_means[q]),
                );
                [0, 1, 2].map(|i| (fp[i] - fm[i]) / (2.0 * DERIVATIVE_STEP))
            };
            let theta = turn_sensitivity::force_turn(
                &turn.sensitivity,
                &turn.q,
                &d_force(turn.j),
                &d_force(turn.j + 1),
            );
            for c in 0..2 {
                // δ(predicted) = predicted × δθ.
                let bias_part = dot(&theta, &cross(&e[c], &predicted));
                out[c][k] = (rp[c] - rm[c]) / (2.0 * DERIVATIVE_STEP) + bias_part;
            }
        }
        out
    }

    fn moves(&self) -> usize {
        self.used.len()
    }
}

/// One move integrated with its sensitivities.
struct Turn {
    /// From pose j to pose j+1.
    j: usize,
    /// (I+Σ)⁻¹.
    k: Mat3,
    /// The end attitude.
    q: Quat,
    sensitivity: turn_sensitivity::TurnSensitivity,
}

impl Problem<9> for Moves<'_> {
    fn cost(&self, p: &[f64; 9]) -> f64 {
        let c: f64 = (0..self.moves())
            .flat_map(|j| self.residuals(j, p))
            .map(|r| r * r)
            .sum();
        if c.is_nan() {
            f64::INFINITY
        } else {
            c
        }
    }

    fn rows(&self, p: &[f64; 9], row: &mut dyn FnMut([f64; 9], f64)) {
        for m in 0..self.moves() {
            let Some(turn) = self.turn(m, p, false) else {
                row([0.0; 9], f64::NAN);
                row([0.0; 9], f64::NAN);
                continue;
            };
            let (r, grads) = self.gyro_rows(&turn);
            row(grads[0], r[0]);
            row(grads[1], r[1]);
        }
    }
}

/// Why the rig-free gyro fit refused a record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RigFreeError {
    /// The record's times and samples differ in number, or a pose's samples
    /// are not within the record, after the previous pose's.
    PosesOutOfRecord {
        /// The pose (0-based).
        pose: usize,
        /// Samples in the record.
        samples: usize,
    },
    /// The full scale given is not a rate, or a sample the fit uses is near it.
    Range(RangeError),
    /// A pose's gyro mean strays from what the others predict.
    PoseNotStatic(PoseNotStatic),
    /// Too few moves, or too few of them turn.
    TooFewRotations(TooFewRotations),
    /// The record turns too far between two samples for the integration.
    TooFastForRate(TooFastForRate),
    /// The turns' axes lie near one plane or one axis: some column of the
    /// gyro's (I+Σ) is not determined.
    RotationAxesDegenerate {
        /// Turns whose axes were measured.
        turns: usize,
        /// The smallest and the middle eigenvalue of the axes' scatter
        /// (mean of a·aᵀ, trace 1; 1/3 each for axes spread evenly).
        spread: [f64; 2],
        /// The smallest accepted eigenvalue.
        needed: f64,
    },
    /// A value is not finite, the parameters are not determined, or the
    /// iteration did not converge.
    Numerics(NumericsError),
}

impl From<NumericsError> for RigFreeError {
    fn from(e: NumericsError) -> Self {
        RigFreeError::Numerics(e)
    }
}

impl From<RangeError> for RigFreeError {
    fn from(e: RangeError) -> Self {
        RigFreeError::Range(e)
    }
}

impl fmt::Display for RigFreeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RigFreeError::PosesOutOfRecord { pose, samples } => write!(
                f,
                "pose {}: its samples are not within the record's {samples} (or not after the previous pose's)",
                pose + 1
            ),
            RigFreeError::Range(e) => write!(f, "{e}"),
            RigFreeError::PoseNotStatic(e) => write!(f, "{e}"),
            RigFreeError::TooFewRotations(e) => write!(f, "{e}"),
            RigFreeError::TooFastForRate(e) => write!(f, "{e}"),
            RigFreeError::RotationAxesDegenerate {
                turns,
                spread,
                needed,
            } => {
                let what = if spread[1] < *needed {
                    "all about one axis"
                } else {
                    "all about axes in one plane"
                };
                write!(
                    f,
                    "the {turns} turns are {what} (eigenvalues {:.4}, {:.4} of the axes' scatter, need ≥ {needed}): \
                 the gyro's response to rates about the missing axis is not determined; turn the unit about \
                 other axes too (tip it over its edges and spin it flat, not always the same way)",
                    spread[0], spread[1]
                )
            }
            RigFreeError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// Checks the poses lie in the record, in order, each with ≥ 2 samples.
fn check_poses(
    record: &Record,
    poses: &[Segment],
    accel_means: &[[f64; 3]],
) -> Result<(), RigFreeError> {
    let samples = record.gyro.len();
    if record.t.len() != samples {
        return Err(RigFreeError::PosesOutOfRecord { pose: 0, samples });
    }
    if accel_means.len() != poses.len() {
        let pose = accel_means.len().min(poses.len());
        return Err(RigFreeError::PosesOutOfRecord { pose, samples });
    }
    let mut previous_end = 0;
    for (pose, s) in poses.iter().enumerate() {
        if s.start < previous_end || s.end < s.start + 2 || s.end > samples {
            return Err(RigFreeError::PosesOutOfRecord { pose, samples });
        }
        previous_end = s.end;
    }
    if let Some((sample, value)) = record
        .gyro
        .iter()
        .flatten()
        .chain(record.t.iter())
        .enumerate()
        .find(|(_, x)| !x.is_finite())
    {
        return Err(NumericsError::NonFinite {
            segment: sample / 3,
            value: *value,
        }
        .into());
    }
    Ok(())
}

/// The largest |axis| of the record, and the sample; refused near the range.
pub(crate) fn check_range(record: &Record, full_scale: f64) -> Result<f64, RangeError> {
    check_range_of(record, 0..record.gyro.len(), full_scale)
}

/// The largest |axis| of the samples `range` of the record and where;
/// the sample itself when it is near the range.
pub fn peak_of(record: &Record, range: core::ops::Range<usize>) -> (usize, f64) {
    record.gyro[range.clone()]
        .iter()
        .map(|w| w.iter().fold(0.0f64, |a, x| a.max(x.abs())))
        .zip(range)
        .fold(
            (0, 0.0f64),
            |best, (x, i)| if x > best.1 { (i, x) } else { best },
        )
}

/// The samples a fit uses from pose j to pose j+1 (both poses and the move).
pub fn move_samples(poses: &[Segment], j: usize) -> core::ops::Range<usize> {
    poses[j].start..poses[j + 1].end
}

/// [`check_range`] over the samples `range` only.
fn check_range_of(
    record: &Record,
    range: core::ops::Range<usize>,
    full_scale: f64,
) -> Result<f64, RangeError> {
    if !(full_scale > 0.0 && full_scale.is_finite()) {
        return Err(RangeError::InvalidFullScale { value: full_scale });
    }
    let (sample, peak) = peak_of(record, range);
    if peak > MAX_RANGE_FRACTION * full_scale {
        return Err(RangeError::GyroNearRange {
            sample,
            rate: peak,
            full_scale,
            fraction: MAX_RANGE_FRACTION,
        });
    }
    Ok(peak)
}

/// Mean and standard error (s/√n) of each axis of `samples` (n ≥ 2).
fn mean_and_error(samples: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mean = crate::calib_fit::static_segments::mean(samples);
    let sd = crate::calib_fit::static_segments::standard_deviation(samples);
    (mean, sd.map(|s| s / libm::sqrt(samples.len() as f64)))
}

/// The bias during move `j` (pose j to j+1): with G, c + G·f along the move.
fn move_bias(
    bias: [f64; 3],
    g: Option<Mat3>,
    a: &accel_fit::Params,
    accel_means: &[[f64; 3]],
    j: usize,
) -> MoveBias {
    MoveBias {
        bias,
        g_sensitivity: g.map(|g| {
            (
                g,
                [force(a, &accel_means[j]), force(a, &accel_means[j + 1])],
            )
        }),
    }
}

/// What the poses say about the gyro at rest ([`g_sensitivity::at_rest`]),
/// a stray pose refused with its times.
fn poses_at_rest(
    record: &Record,
    poses: &[Segment],
    accel_means: &[[f64; 3]],
    accel: &AccelFit,
) -> Result<AtRest, RigFreeError> {
    let n = poses.len();
    // Each pose's means once: the consistency test visits every pose n times.
    let means: Vec<PoseMean> = poses
        .iter()
        .zip(accel_means)
        .map(|(s, accel_mean)| {
            let (gyro, standard_error) = mean_and_error(&record.gyro[s.start..s.end]);
            PoseMean {
                gyro,
                standard_error,
                force: force(&accel.params, accel_mean),
            }
        })
        .collect();
    g_sensitivity::at_rest(n, |q| means[q])
        .map_err(|stray| RigFreeError::PoseNotStatic(PoseNotStatic::new(&stray, poses, record.t)))
}

/// The largest rotation between two samples of the moves (rad), and where.
pub(crate) fn fastest_step(record: &Record, poses: &[Segment], bias: &[f64; 3]) -> (usize, f64) {
    fastest_step_of(
        record,
        poses,
        bias,
        Used::All(poses.len().saturating_sub(1)),
    )
}

/// [`fastest_step`] over the moves `used`.
fn fastest_step_of(
    record: &Record,
    poses: &[Segment],
    bias: &[f64; 3],
    used: Used,
) -> (usize, f64) {
    let mut worst = (0, 0.0f64);
    for pair in (0..used.len()).map(|m| &poses[used.get(m)..used.get(m) + 2]) {
        for i in pair[0].end - 1..pair[1].start {
            let w = record.gyro[i];
            let d = [w[0] - bias[0], w[1] - bias[1], w[2] - bias[2]];
            let angle = libm::sqrt(dot(&d, &d)) * (record.t[i + 1] - record.t[i]);
            if angle > worst.1 {
                worst = (i, angle);
            }
        }
    }
    worst
}

/// The turns (moves of ≥ [`MIN_TURN_DEG`] with (I+Σ) = I) and the smallest
/// and middle eigenvalues of their axes' scatter.
fn axis_spread(
    record: &Record,
    poses: &[Segment],
    used: Used,
    bias: &[f64; 3],
) -> (usize, [f64; 2]) {
    let mut scatter = [[0.0; 3]; 3];
    let mut turns = 0;
    for pair in (0..used.len()).map(|m| &poses[used.get(m)..used.get(m) + 2]) {
        let q = integrate(
            record,
            &pair[0],
            &pair[1],
            &matrix::IDENTITY,
            &MoveBias::constant(*bias),
        );
        let phi = quaternion::to_rotation_vector(&q);
        let angle = libm::sqrt(dot(&phi, &phi));
        if angle < MIN_TURN_DEG.to_radians() {
            continue;
        }
        turns += 1;
        let a = phi.map(|x| x / angle);
        for (i, row) in scatter.iter_mut().enumerate() {
            for (j, s) in row.iter_mut().enumerate() {
                *s += a[i] * a[j];
            }
        }
    }
    if turns == 0 {
        return (0, [0.0; 2]);
    }
    let e = symmetric_eigenvalues(&scatter.map(|row| row.map(|x| x / turns as f64)));
    (turns, [e[0], e[1]])
}

/// The variance each entry of (I+Σ) inherits from the accelerometer fit
/// (`accel_cov`, its parameters' covariance): the solution moves by
/// dp = G·da with G = −(J_gᵀJ_g)⁻¹·J_gᵀ·J_a (implicit function theorem at
/// the minimum; `inv` = (J_gᵀJ_g)⁻¹), so its covariance is G·C_a·Gᵀ.
fn carried_variance(
    problem: &Moves,
    p: &[f64; 9],
    inv: &[[f64; 9]; 9],
    accel_cov: &[[f64; 9]; 9],
) -> [f64; 9] {
    let mut jtj_a = [[0.0; 9]; 9];
    for m in 0..problem.moves() {
        let Some(turn) = problem.turn(m, p, true) else {
            return [f64::NAN; 9];
        };
        let (_, jg) = problem.gyro_rows(&turn);
        let ja = problem.accel_rows(&turn);
        for c in 0..2 {
            for (row, g) in jtj_a.iter_mut().zip(jg[c]) {
                for (x, a) in row.iter_mut().zip(ja[c]) {
                    *x += g * a;
                }
            }
        }
    }
    let g: [[f64; 9]; 9] = core::array::from_fn(|i| {
        core::array::from_fn(|k| -(0..9).map(|m| inv[i][m] * jtj_a[m][k]).sum::<f64>())
    });
    core::array::from_fn(|i| {
        (0..9)
            .flat_map(|k| (0..9).map(move |l| (k, l)))
            .map(|(k, l)| g[i][k] * accel_cov[k][l] * g[i][l])
            .sum::<f64>()
            .max(0.0)
    })
}

/// Fits the gyro's (I+Σ) and b to `record` given its static `poses` (in
/// order), the accelerometer means of those poses and the accelerometer fit
/// made from them; `full_scale` is the gyro's range, rad/s.
pub fn fit(
    record: Record,
    poses: &[Segment],
    accel_means: &[[f64; 3]],
    accel: &AccelFit,
    full_scale: f64,
) -> Result<RigFreeGyroFit, RigFreeError> {
    check_range(&record, full_scale)?;
    let all = Used::All(poses.len().saturating_sub(1));
    fit_used(record, poses, all, accel_means, accel, full_scale)
}

/// The moves a fit uses: all of them (the count), or a list of j (the move
/// from pose j to pose j+1).
#[derive(Clone, Copy, Debug)]
enum Used<'a> {
    All(usize),
    Listed(&'a [usize]),
}

impl Used<'_> {
    fn len(&self) -> usize {
        match self {
            Used::All(n) => *n,
            Used::Listed(l) => l.len(),
        }
    }

    /// The `m`th used move's j.
    fn get(&self, m: usize) -> usize {
        match self {
            Used::All(_) => m,
            Used::Listed(l) => l[m],
        }
    }
}

/// [`fit`] with only the moves `used` (j: from pose j to pose j+1, in
/// increasing order), as when a move clipped or crossed a gap in the
/// record; the range is checked on the samples the fit uses (the poses and
/// the used moves), not on the rest of the record.
pub fn fit_moves(
    record: Record,
    poses: &[Segment],
    used: &[usize],
    accel_means: &[[f64; 3]],
    accel: &AccelFit,
    full_scale: f64,
) -> Result<RigFreeGyroFit, RigFreeError> {
    fit_used(
        record,
        poses,
        Used::Listed(used),
        accel_means,
        accel,
        full_scale,
    )
}

fn fit_used(
    record: Record,
    poses: &[Segment],
    used: Used,
    accel_means: &[[f64; 3]],
    accel: &AccelFit,
    full_scale: f64,
) -> Result<RigFreeGyroFit, RigFreeError> {
    check_poses(&record, poses, accel_means)?;
    if let Some(j) = (0..used.len())
        .map(|m| used.get(m))
        .find(|&j| j + 1 >= poses.len())
    {
        return Err(RigFreeError::PosesOutOfRecord {
            pose: j + 1,
            samples: record.gyro.len(),
        });
    }
    let mut peak_rate = 0.0f64;
    for pose in poses {
        peak_rate = peak_rate.max(check_range_of(&record, pose.start..pose.end, full_scale)?);
    }
    for m in 0..used.len() {
        let samples = move_samples(poses, used.get(m));
        peak_rate = peak_rate.max(check_range_of(&record, samples, full_scale)?);
    }
    let rotations = used.len();
    if rotations < MIN_ROTATIONS {
        return Err(RigFreeError::TooFewRotations(TooFewRotations {
            rotations,
            turns: rotations,
            needed: MIN_ROTATIONS,
        }));
    }
    let AtRest {
        bias,
        sigma_bias,
        bias_dof,
        support: g_support,
        check: pose_check,
    } = poses_at_rest(&record, poses, accel_means, accel)?;
    let g_applied = g_support.applied().map(|fit| fit.g);
    let (sample, step) = fastest_step_of(&record, poses, &bias, used);
    let limit = MAX_ROTATION_PER_SAMPLE_DEG.to_radians();
    if step > limit {
        return Err(RigFreeError::TooFastForRate(TooFastForRate {
            sample,
            rotation_deg: step.to_degrees(),
            limit_deg: MAX_ROTATION_PER_SAMPLE_DEG,
            rate_hz: 1.0 / (record.t[sample + 1] - record.t[sample]),
        }));
    }
    let (turns, spread) = axis_spread(&record, poses, used, &bias);
    if turns < MIN_ROTATIONS {
        return Err(RigFreeError::TooFewRotations(TooFewRotations {
            rotations,
            turns,
            needed: MIN_ROTATIONS,
        }));
    }
    if spread[0].is_nan() || spread[0] < MIN_AXIS_SPREAD {
        return Err(RigFreeError::RotationAxesDegenerate {
            turns,
            spread,
            needed: MIN_AXIS_SPREAD,
        });
    }
    let problem = Moves {
        record,
        poses,
        used,
        accel_means,
        accel,
        bias,
        g_sensitivity: g_applied,
    };
    let start = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let (p, iterations) = levenberg_marquardt::minimise(&problem, start, MAX_ITERATIONS)?;
    let mut ls = GivensLs::<9>::new();
    let mut sum_sq = 0.0;
    let mut worst = 0.0f64;
    problem.rows(&p, &mut |grad, r| {
        ls.add_row(grad, -r);
        sum_sq += r * r;
        worst = worst.max(r.abs());
    });
    let condition = ls.scaled_condition();
    check_condition(condition, MAX_CONDITION)?;
    let residuals = 2 * rotations;
    let gyro_dof = residuals - 9;
    let (sigma_scale_misalignment, dof_entries) = match (gyro_dof, accel.covariance) {
        (1.., Some(accel_cov)) => {
            let inv = ls.inverse_normal_matrix().map_err(NumericsError::from)?;
            let s2 = sum_sq / gyro_dof as f64;
            let own: [f64; 9] = core::array::from_fn(|k| s2 * inv[k][k]);
            let carried = carried_variance(&problem, &p, &inv, &accel_cov);
            let var: [f64; 9] = core::array::from_fn(|k| own[k] + carried[k]);
            // Welch–Satterthwaite: the degrees of freedom of a sum of two
            // variance estimates with ν_g and ν_a.
            let dof: [f64; 9] = core::array::from_fn(|k| {
                var[k] * var[k]
                    / (own[k] * own[k] / gyro_dof as f64
                        + carried[k] * carried[k] / accel.dof as f64)
            });
            (Some(matrix_of(&var.map(libm::sqrt))), Some(matrix_of(&dof)))
        }
        _ => (None, None),
    };
    let dof = dof_entries.map_or(0, |d| {
        d.iter().flatten().fold(f64::INFINITY, |a, &x| a.min(x)) as usize
    });
    Ok(RigFreeGyroFit {
        scale_misalignment: matrix_of(&p),
        bias,
        sigma_scale_misalignment,
        sigma_bias,
        segments: poses.len(),
        rotations,
        turns,
        dof,
        dof_entries,
        gyro_dof,
        bias_dof,
        residual_rms: libm::sqrt(sum_sq / residuals as f64),
        residual_max: worst,
        condition,
        iterations,
        axis_spread: spread,
        max_rotation_per_sample_deg: step.to_degrees(),
        peak_rate,
        g_sensitivity: g_support,
        pose_check,
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::calib_fit::hand_record::{self, Unit};
    use crate::calib_fit::static_segments::Detector;
    use std::vec;
    use triad_sim::effects::rng::Rng;

    /// The one-pass Jacobian ([`turn_sensitivity`]) against central
    /// differences of the re-integrated residuals (the method it replaced),
    /// in (I+Σ) and in the accelerometer's parameters, on a hand session
    /// with a g-sensitivity (so G's force terms are in it). The one pass
    /// differentiates the continuous turn, the differences the RK4 steps:
    /// at 100 Hz they agree to 1e-5 of the row's size here (1e-4 is the
    /// bound; a wrong sign or index gives an error of the row's own size).
    #[test]
    fn the_one_pass_jacobian_matches_central_differences() {
        let unit = Unit {
            g_sensitivity: Some([
                [2e-3, 4e-4, -3e-4],
                [1e-4, -2e-3, 5e-4],
                [-2e-4, 3e-4, 1.5e-3],
            ]),
            ..hand_record::MEMS_UNIT
        };
        let mut rng = Rng::from_seed(5);
        let (mut t, mut accel, mut gyro) = (Vec::new(), Vec::new(), Vec::new());
        hand_record::generate(&hand_record::SESSION, &unit, &mut || rng.uniform(), |s| {
            t.push(s.t);
            accel.push(s.accel);
            gyro.push(s.gyro);
        });
        let detector = Detector {
            block: 50,
            min_blocks: 4,
        };
        let mut poses = vec![Segment { start: 0, end: 0 }; accel.len() / 50 + 1];
        let n = detector.detect(&accel, &mut poses).unwrap();
        poses.truncate(n);
        let means: Vec<[f64; 3]> = poses
            .iter()
            .map(|s| crate::calib_fit::static_segments::mean(&accel[s.start..s.end]))
            .collect();
        let accel_fit = accel_fit::fit(&means, unit.gravity).unwrap();
        let record = Record { t: &t, gyro: &gyro };
        let problem = Moves {
            record,
            poses: &poses,
            used: Used::All(poses.len() - 1),
            accel_means: &means,
            accel: &accel_fit,
            bias: unit.gyro.bias,
            g_sensitivity: unit.g_sensitivity,
        };
        let p = [
            1.02, 0.006, -0.004, -0.003, 0.98, 0.005, 0.002, -0.006, 1.01,
        ];
        let h = DERIVATIVE_STEP;
        for m in 0..problem.moves() {
            let turn = problem.turn(m, &p, true).unwrap();
            let (r, gyro_rows) = problem.gyro_rows(&turn);
            let accel_rows = problem.accel_rows(&turn);
            assert_eq!(r, problem.residuals(m, &p));
            let j = problem.used.get(m);
            let differences = |gyro_side: bool| -> [[f64; 9]; 2] {
                let mut out = [[0.0; 9]; 2];
                for k in 0..9 {
                    let shifted = |x: f64| {
                        let (mut pg, mut pa) = (p, accel_fit.params);
                        if gyro_side {
                            pg[k] += x;
                        } else {
                            pa[k] += x;
                        }
                        let k = matrix::inverse(&matrix_of(&pg)).unwrap();
                        let q = integrate(
                            &record,
                            &poses[j],
                            &poses[j + 1],
                            &k,
                            &problem.move_bias(&pa, j),
                        );
                        problem.residuals_after(j, &q, &pa)
                    };
                    let (rp, rm) = (shifted(h), shifted(-h));
                    for c in 0..2 {
                        out[c][k] = (rp[c] - rm[c]) / (2.0 * h);
                    }
                }
                out
            };
            for (analytic, numeric) in [
                (gyro_rows, differences(true)),
                (accel_rows, differences(false)),
            ] {
                for c in 0..2 {
                    let size = numeric[c].iter().fold(0.0f64, |a, x| a.max(x.abs()));
                    for k in 0..9 {
                        assert!(
                            (analytic[c][k] - numeric[c][k]).abs() <= 1e-4 * size,
                            "move {m} row {c} entry {k}: {} vs {} (row size {size})",
                            analytic[c][k],
                            numeric[c][k]
                        );
                    }
                }
            }
        }
    }
}
