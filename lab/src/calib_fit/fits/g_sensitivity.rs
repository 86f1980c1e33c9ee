//! The gyroscope's g-sensitivity G from static poses, and the poses'
//! consistency test that accounts for it.
//!
//! At rest the gyro reads m̂_p = c + G·f_p + noise in pose p, f_p the
//! specific force there (the corrected accelerometer mean, the frame of the
//! calibration's G) and c the bias (Earth's rate, ≤ 0.004 °/s, is left in
//! the noise). Per gyro axis that is a linear least-squares problem in four
//! unknowns (c_i and row i of G) over the poses: it determines G when the
//! poses' f_p span three dimensions affinely (gravity along three
//! independent directions and at least one opposite, e.g. four faces of a
//! cube), which the design's column-scaled condition number checks. The σ's
//! are s·√((XᵀX)⁻¹) from the residual scatter, with poses − 4 degrees of
//! freedom: the pose means' own noise and the bias's wander between poses
//! are both in it, and Student-t with that many degrees of freedom gives its
//! coverage. Whether G is there at all is an F-test per row (G's row = 0
//! against the fit, F(3, poses − 4)) at [`SIGNIFICANCE`] family-wise over the
//! three rows: a G the poses do not show is reported as consistent with zero
//! and left out of the calibration, never invented.
//!
//! The consistency test ([`check_poses`]): each pose's gyro mean against
//! what the other poses predict for it (their bias, and their G when the
//! poses support one), an externally studentised residual: r = m̂_q − x_qᵀβ̂₍q₎
//! with variance max(s₍q₎², se_q²) + s₍q₎²·x_qᵀ(X₍q₎ᵀX₍q₎)⁻¹x_q, s₍q₎ the
//! other poses' residual scatter and se_q the pose's own standard error; the
//! limit is Student-t's two-sided quantile at [`POSE_FAMILY_LEVEL`]
//! family-wise (Bonferroni over poses × 3 axes) with the others' degrees of
//! freedom. So the limit scales with the noise the record shows, and a pose
//! whose mean differs only by G·f is not called turned.

use core::fmt;

use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::static_segments::Segment;
use crate::f_dist;
use triad::units::STANDARD_GRAVITY;

/// One static pose as the fit sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseMean {
    /// The gyro's mean, rad/s.
    pub gyro: [f64; 3],
    /// Its standard error per axis (s/√n), rad/s.
    pub standard_error: [f64; 3],
    /// The specific force, m/s²: the corrected accelerometer mean, in G's frame.
    pub force: [f64; 3],
}

/// The fewest poses for a G with a σ: four unknowns per axis and one degree
/// of freedom.
pub const MIN_POSES: usize = 5;

/// The largest accepted condition number of the column-scaled design
/// [1, f/g]: poses in three independent directions with their opposites
/// give about 3; poses nearly on one circle (a plane of gravity
/// directions) give hundreds and more, and G is then not determined.
pub const MAX_CONDITION: f64 = 50.0;

/// The family-wise level of the F-tests that decide whether the poses show
/// a G at all (over the three rows).
pub const SIGNIFICANCE: f64 = 0.01;

/// The family-wise level of the pose-consistency test, over every pose and
/// axis: a still unit is refused this rarely.
pub const POSE_FAMILY_LEVEL: f64 = 1.0e-3;

/// Why the poses do not determine G.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NotSupported {
    /// Fewer poses than [`MIN_POSES`].
    TooFewPoses {
        /// The poses.
        poses: usize,
        /// The minimum.
        needed: usize,
    },
    /// The poses' specific forces do not span three directions.
    Directions {
        /// The design's column-scaled condition number (∞ when singular).
        condition: f64,
        /// [`MAX_CONDITION`].
        limit: f64,
    },
}

/// G fitted from the poses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// G, (rad/s)/(m/s²): row i the gyro axis, column j the force axis.
    pub g: Mat3,
    /// σ of each entry of G.
    pub sigma_g: Mat3,
    /// The bias c, rad/s (the gyro's reading at zero specific force).
    pub bias: [f64; 3],
    /// σ of c.
    pub sigma_bias: [f64; 3],
    /// Degrees of freedom of the σ's: poses − 4.
    pub dof: usize,
    /// The design's column-scaled condition number.
    pub condition: f64,
    /// Per row, the F-test's p-value for "this row of G is zero".
    pub p_values: [f64; 3],
    /// Whether some row's p-value is below [`SIGNIFICANCE`]/3: the poses
    /// show a G, and the calibration carries it.
    pub significant: bool,
    /// RMS of the residuals after G, per axis, rad/s.
    pub residual_rms: [f64; 3],
}

/// The fit of G, or why the poses cannot give one.
#[derive(Clone, Copy, Debug, PartialEq)]
// Copied a few times per fit, never in a hot loop: boxing would need an allocator.
#[allow(clippy::large_enum_variant)]
pub enum Support {
    /// Fitted (significant or not: [`Fit::significant`]).
    Fitted(Fit),
    /// Not determined by these poses.
    NotSupported(NotSupported),
}

impl Support {
    /// G when the poses show one (significant), else `None`.
    pub fn applied(&self) -> Option<&Fit> {
        match self {
            Support::Fitted(fit) if fit.significant => Some(fit),
            _ => None,
        }
    }
}

/// The design row of a pose: [1] for a constant bias, [1, f/g] with G.
fn design<const K: usize>(p: &PoseMean) -> [f64; K] {
    core::array::from_fn(|k| {
        if k == 0 {
            1.0
        } else {
            p.force[k - 1] / STANDARD_GRAVITY
        }
    })
}

/// The least squares of gyro axis `axis` over the poses `0..n` but `skip`.
fn axis_fit<const K: usize>(
    n: usize,
    pose: &impl Fn(usize) -> PoseMean,
    axis: usize,
    skip: Option<usize>,
) -> GivensLs<K> {
    let mut ls = GivensLs::<K>::new();
    for q in (0..n).filter(|&q| Some(q) != skip) {
        let p = pose(q);
        ls.add_row(design::<K>(&p), p.gyro[axis]);
    }
    ls
}

/// Fits G (and the bias) to the `n` poses `pose(0..n)`.
pub fn fit(n: usize, pose: impl Fn(usize) -> PoseMean) -> Support {
    if n < MIN_POSES {
        return Support::NotSupported(NotSupported::TooFewPoses {
            poses: n,
            needed: MIN_POSES,
        });
    }
    let condition = axis_fit::<4>(n, &pose, 0, None).scaled_condition();
    if condition.is_nan() || condition > MAX_CONDITION {
        return Support::NotSupported(NotSupported::Directions {
            condition,
            limit: MAX_CONDITION,
        });
    }
    let dof = n - 4;
    let mut out = Fit {
        g: [[0.0; 3]; 3],
        sigma_g: [[0.0; 3]; 3],
        bias: [0.0; 3],
        sigma_bias: [0.0; 3],
        dof,
        condition,
        p_values: [1.0; 3],
        significant: false,
        residual_rms: [0.0; 3],
    };
    for axis in 0..3 {
        let ls = axis_fit::<4>(n, &pose, axis, None);
        let (Ok(beta), Ok(inv)) = (ls.solve(), ls.inverse_normal_matrix()) else {
            return Support::NotSupported(NotSupported::Directions {
                condition: f64::INFINITY,
                limit: MAX_CONDITION,
            });
        };
        let rss = ls.residual_sum_of_squares();
        let s2 = rss / dof as f64;
        out.bias[axis] = beta[0];
        out.sigma_bias[axis] = libm::sqrt(s2 * inv[0][0]);
        for j in 0..3 {
            out.g[axis][j] = beta[j + 1] / STANDARD_GRAVITY;
            out.sigma_g[axis][j] = libm::sqrt(s2 * inv[j + 1][j + 1]) / STANDARD_GRAVITY;
        }
        out.residual_rms[axis] = libm::sqrt(rss / n as f64);
        // The constant model's residual sum of squares: the scatter about the mean.
        let rss0 = axis_fit::<1>(n, &pose, axis, None).residual_sum_of_squares();
        let f = ((rss0 - rss) / 3.0) / s2;
        out.p_values[axis] = if rss > 0.0 {
            1.0 - f_dist::cdf(f, 3.0, dof as f64)
        } else {
            0.0
        };
    }
    out.significant = out.p_values.iter().any(|&p| p < SIGNIFICANCE / 3.0);
    Support::Fitted(out)
}

/// What static poses say about the gyro at rest ([`at_rest`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtRest {
    /// The bias, rad/s: the fit's intercept c when the poses show a G, else
    /// the mean of the poses' means.
    pub bias: [f64; 3],
    /// Its σ (the scatter of the poses' means about the model over
    /// √poses); `None` with one pose.
    pub sigma_bias: Option<[f64; 3]>,
    /// Degrees of freedom of those σ's: poses − 4 with G, else poses − 1.
    pub bias_dof: usize,
    /// G from the poses, or why they do not give one.
    pub support: Support,
    /// How the poses were checked against each other.
    pub check: Consistency,
}

/// The gyro at rest in the `n` poses `pose(0..n)`: G where they support
/// one ([`fit`]), each pose checked against the others ([`check_poses`],
/// with G when the poses determine one), and the bias with its σ. The
/// first pose that strays is refused.
pub fn at_rest(n: usize, pose: impl Fn(usize) -> PoseMean) -> Result<AtRest, Stray> {
    let support = fit(n, &pose);
    let check = check_poses(n, &pose, matches!(support, Support::Fitted(_)))?;
    if let Some(g) = support.applied() {
        return Ok(AtRest {
            bias: g.bias,
            sigma_bias: Some(g.sigma_bias),
            bias_dof: g.dof,
            support,
            check,
        });
    }
    let nf = n as f64;
    let mut sum = [0.0; 3];
    for q in 0..n {
        let m = pose(q).gyro;
        for i in 0..3 {
            sum[i] += m[i];
        }
    }
    let bias = sum.map(|x| x / nf);
    let mut sum_sq = [0.0; 3];
    for q in 0..n {
        let m = pose(q).gyro;
        for i in 0..3 {
            sum_sq[i] += (m[i] - bias[i]) * (m[i] - bias[i]);
        }
    }
    Ok(AtRest {
        bias,
        sigma_bias: (n >= 2).then(|| sum_sq.map(|s| libm::sqrt(s / (nf - 1.0) / nf))),
        bias_dof: n.saturating_sub(1),
        support,
        check,
    })
}

/// How the poses were checked against each other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Consistency {
    /// Whether the prediction included G (the poses support one).
    pub with_g: bool,
    /// Degrees of freedom of each leave-one-out scatter: poses − 1 − unknowns
    /// (0: too few poses to check, nothing was).
    pub dof: usize,
    /// The limit in σ's: Student-t's two-sided quantile at
    /// [`POSE_FAMILY_LEVEL`]/(3·poses).
    pub sigmas: f64,
    /// The largest |residual|/σ found, with its pose and axis.
    pub worst: (usize, usize, f64),
}

/// A pose whose gyro mean is not what the others predict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stray {
    /// The pose (0-based).
    pub pose: usize,
    /// The gyro axis (0..3).
    pub axis: usize,
    /// Its mean minus the others' prediction, rad/s.
    pub residual: f64,
    /// The limit, rad/s ([`Consistency::sigmas`] × the residual's σ).
    pub limit: f64,
    /// How the poses were checked.
    pub check: Consistency,
}

/// The refusal of a stray pose: the gyro's mean over a static pose strays
/// from what the other poses predict for it (their bias, and their
/// g-sensitivity where they support one): the unit turned during the pose
/// (about the vertical, which the accelerometer does not see).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseNotStatic {
    /// The pose (0-based).
    pub pose: usize,
    /// Its first and last sample's times, s.
    pub time_s: [f64; 2],
    /// The gyro axis (0..3).
    pub axis: usize,
    /// Its mean minus the others' prediction, rad/s.
    pub rate: f64,
    /// The largest accepted, rad/s.
    pub limit: f64,
    /// The limit in σ's of the residual.
    pub sigmas: f64,
    /// Whether the prediction included the g-sensitivity.
    pub with_g: bool,
    /// Poses checked.
    pub poses: usize,
}

impl PoseNotStatic {
    /// The refusal of `stray` among the `poses` (sample ranges of the
    /// record), with its times from `t`.
    pub fn new(stray: &Stray, poses: &[Segment], t: &[f64]) -> Self {
        let s = &poses[stray.pose];
        PoseNotStatic {
            pose: stray.pose,
            time_s: [t[s.start], t[s.end - 1]],
            axis: stray.axis,
            rate: stray.residual.abs(),
            limit: stray.limit,
            sigmas: stray.check.sigmas,
            with_g: stray.check.with_g,
            poses: poses.len(),
        }
    }
}

impl fmt::Display for PoseNotStatic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "pose {} ({:.2}–{:.2} s): the gyro's {} mean differs from what the other poses predict \
             (their bias{}) by {:.4} °/s (limit {:.4} °/s: {:.1} σ of that difference, \
             from the poses' own scatter and standard errors, at a family-wise level of {} over \
             {} poses × 3 axes): the unit turned during that pose (about the vertical, which \
             the accelerometer does not see); hold it still at each pose",
            self.pose + 1,
            self.time_s[0],
            self.time_s[1],
            ["x", "y", "z"].get(self.axis).copied().unwrap_or("?"),
            if self.with_g { " and g-sensitivity" } else { "" },
            self.rate.to_degrees(),
            self.limit.to_degrees(),
            self.sigmas,
            POSE_FAMILY_LEVEL,
            self.poses,
        )
    }
}

/// Checks each of the `n` poses against the others (module doc), with G
/// when `with_g`; the first pose that strays beyond its limit is refused.
pub fn check_poses(
    n: usize,
    pose: impl Fn(usize) -> PoseMean,
    with_g: bool,
) -> Result<Consistency, Stray> {
    if with_g {
        check::<4>(n, &pose, true)
    } else {
        check::<1>(n, &pose, false)
    }
}

fn check<const K: usize>(
    n: usize,
    pose: &impl Fn(usize) -> PoseMean,
    with_g: bool,
) -> Result<Consistency, Stray> {
    let dof = n.saturating_sub(1 + K);
    let mut check = Consistency {
        with_g,
        dof,
        sigmas: f64::INFINITY,
        worst: (0, 0, 0.0),
    };
    if dof == 0 {
        return Ok(check);
    }
    let tests = (3 * n) as f64;
    // t² with ν degrees of freedom is F(1, ν).
    check.sigmas = libm::sqrt(f_dist::quantile(
        1.0 - POSE_FAMILY_LEVEL / tests,
        1.0,
        dof as f64,
    ));
    for q in 0..n {
        let p = pose(q);
        let x = design::<K>(&p);
        for axis in 0..3 {
            let ls = axis_fit::<K>(n, pose, axis, Some(q));
            let (Ok(beta), Ok(inv)) = (ls.solve(), ls.inverse_normal_matrix()) else {
                continue;
            };
            let s2 = ls.residual_sum_of_squares() / dof as f64;
            let h: f64 = (0..K)
                .map(|a| (0..K).map(|b| x[a] * inv[a][b] * x[b]).sum::<f64>())
                .sum();
            let se = p.standard_error[axis];
            let sigma = libm::sqrt(s2.max(se * se) + s2 * h);
            let predicted: f64 = (0..K).map(|k| x[k] * beta[k]).sum();
            let residual = p.gyro[axis] - predicted;
            // A record held at one value has no scatter at all: no residual is then no stray.
            let ratio = if residual == 0.0 {
                0.0
            } else {
                residual.abs() / sigma
            };
            if ratio > check.worst.2 || ratio.is_nan() {
                check.worst = (q, axis, ratio);
            }
            // NaN (no σ) is refused too.
            if ratio.is_nan() || ratio > check.sigmas {
                return Err(Stray {
                    pose: q,
                    axis,
                    residual,
                    limit: check.sigmas * sigma,
                    check,
                });
            }
        }
    }
    Ok(check)
}
