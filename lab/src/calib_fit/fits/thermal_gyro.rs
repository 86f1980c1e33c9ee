//! The gyroscope's (I+Σ) against temperature, (I+Σ)(ΔT) = (I+Σ)₀ + ΔT·D
//! (all 18 entries), from hand-turned records at several temperatures: the
//! rig-free fit ([`crate::calib_fit::fits::rig_free`]) with the matrix of each move taken at
//! the move's temperature.
//!
//! For each move from pose j to pose j+1 of one record (both within
//! [`LEVEL_C`] of each other: a chamber step between them is no move), the
//! corrected rate (I+Σ)(ΔT)⁻¹(ω̂ − b(ΔT)) is integrated over the move (RK4 on
//! the quaternion) and pose j's gravity direction, carried through the
//! turn, is matched to pose j+1's; the directions come from the thermal
//! accelerometer fit ([`crate::calib_fit::fits::thermal_accel::up`]) at each pose's
//! temperature, the bias b(ΔT) from the gyro's bias polynomial
//! ([`crate::calib_fit::fits::bias_polynomial`]). The frame is the accelerometer's corrected
//! frame at each temperature, as in `calib fit imu`.
//!
//! A move's residuals depend on (I+Σ)(ΔT_move) alone, so ∂r/∂D = ΔT·∂r/∂(I+Σ)₀:
//! nine central differences per move give all eighteen columns. The σ's are
//! s²·(JᵀJ)⁻¹ with 2·moves − 18 degrees of freedom plus the variance carried
//! from the accelerometer fit's covariance (its error moves every gravity
//! direction), combined per entry by Welch–Satterthwaite; the bias
//! polynomial's error is not carried (its effect, σ_b × a turn's duration,
//! is far below the noise integrated over a turn, as in the rig-free fit).

use crate::calib_fit::error::FitError;
use crate::calib_fit::fits::bias_polynomial::BiasPolynomial;
use crate::calib_fit::fits::rig_free::{self, across, dot, Record, MIN_ROTATIONS, MIN_TURN_DEG};
use crate::calib_fit::fits::thermal_accel::{self, ThermalAccelFit, MAX_CONDITION, PARAMETERS};
use crate::calib_fit::fits::thermal_coverage::LEVEL_C;
use crate::calib_fit::numerics::levenberg_marquardt::{self, Problem};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::quaternion;
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::static_segments::Segment;
use triad::model::matrix;

/// Parameters: (I+Σ)₀ row by row, then D row by row.
pub const GYRO_PARAMETERS: usize = 18;

/// Step of the central differences on the entries of (I+Σ) (see
/// [`crate::calib_fit::fits::rig_free`]'s).
const DERIVATIVE_STEP: f64 = 1.0e-6;

/// Step on the accelerometer's parameters, relative to each one's σ.
const ACCEL_STEP_SIGMAS: f64 = 1.0e-2;

/// The poses of one record.
#[derive(Clone, Copy, Debug)]
pub struct Poses<'a> {
    /// The record's times and gyro samples.
    pub record: Record<'a>,
    /// Its static poses, in order.
    pub segments: &'a [Segment],
    /// Their accelerometer means, m/s².
    pub accel_means: &'a [[f64; 3]],
    /// Their mean temperatures, °C.
    pub temperatures: &'a [f64],
}

/// The result of [`fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalGyroFit {
    /// (I+Σ)₀ in the accelerometer's corrected frame.
    pub scale_misalignment: Mat3,
    /// Its σ's.
    pub sigma_scale_misalignment: Mat3,
    /// D, 1/°C.
    pub scale_misalignment_per_c: Mat3,
    /// Its σ's.
    pub sigma_scale_misalignment_per_c: Mat3,
    /// Effective degrees of freedom of (I+Σ)₀'s and D's σ's (Welch–Satterthwaite).
    pub dof_entries: [Mat3; 2],
    /// The smallest of them, rounded down.
    pub dof: usize,
    /// 2·moves − 18.
    pub gyro_dof: usize,
    /// Moves fitted.
    pub moves: usize,
    /// Turns of ≥ [`MIN_TURN_DEG`] colder and warmer than the reference.
    pub turns: [usize; 2],
    /// RMS of the direction residuals, rad.
    pub residual_rms: f64,
    /// Largest |residual|, rad.
    pub residual_max: f64,
    /// Condition number of the column-scaled Jacobian.
    pub condition: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: u32,
}

struct Moves<'a> {
    sets: &'a [Poses<'a>],
    accel: &'a ThermalAccelFit,
    bias: &'a BiasPolynomial,
    reference_c: f64,
}

/// One move: the record, from/to pose and its temperature.
#[derive(Clone, Copy)]
struct Move {
    set: usize,
    pose: usize,
    delta: f64,
}

impl Moves<'_> {
    fn each(&self, mut f: impl FnMut(Move)) {
        for (set, s) in self.sets.iter().enumerate() {
            for pose in 0..s.segments.len().saturating_sub(1) {
                let (a, b) = (s.temperatures[pose], s.temperatures[pose + 1]);
                if (a - b).abs() < LEVEL_C {
                    f(Move {
                        set,
                        pose,
                        delta: (a + b) / 2.0 - self.reference_c,
                    });
                }
            }
        }
    }

    fn turn(&self, m: Move, k: &Mat3) -> quaternion::Quat {
        let s = &self.sets[m.set];
        let bias = self.bias.at(self.reference_c + m.delta);
        rig_free::integrate(
            &s.record,
            &s.segments[m.pose],
            &s.segments[m.pose + 1],
            k,
            &rig_free::MoveBias::constant(bias),
        )
    }

    fn residuals_of_turn(&self, m: Move, q: &quaternion::Quat, a: &[f64; PARAMETERS]) -> [f64; 2] {
        let s = &self.sets[m.set];
        let up =
            |i: usize| thermal_accel::up(a, self.reference_c, &s.accel_means[i], s.temperatures[i]);
        let (before, after) = (up(m.pose), up(m.pose + 1));
        let predicted = quaternion::rotate_inverse(q, &before);
        let d = [0, 1, 2].map(|i| predicted[i] - after[i]);
        across(&after).map(|e| dot(&d, &e))
    }

    fn residuals(&self, m: Move, matrix_at: &Mat3) -> [f64; 2] {
        let Some(k) = matrix::inverse(matrix_at) else {
            return [f64::NAN; 2];
        };
        self.residuals_of_turn(m, &self.turn(m, &k), &self.accel.params)
    }

    /// (residuals, ∂/∂ the 18 parameters) of move `m` at `p`.
    fn rows_of(
        &self,
        m: Move,
        p: &[f64; GYRO_PARAMETERS],
    ) -> ([f64; 2], [[f64; GYRO_PARAMETERS]; 2]) {
        let at = matrix_at(p, m.delta);
        let r = self.residuals(m, &at);
        let mut grad = [[0.0; GYRO_PARAMETERS]; 2];
        for e in 0..9 {
            let shifted = |h: f64| {
                let mut x = at;
                x[e / 3][e % 3] += h;
                self.residuals(m, &x)
            };
            let (rp, rm) = (shifted(DERIVATIVE_STEP), shifted(-DERIVATIVE_STEP));
            for c in 0..2 {
                let g = (rp[c] - rm[c]) / (2.0 * DERIVATIVE_STEP);
                grad[c][e] = g;
                grad[c][9 + e] = m.delta * g;
            }
        }
        (r, grad)
    }

    /// ∂(residuals of move m)/∂(the accelerometer's parameters), by central
    /// differences of the gravity directions (the turn does not depend on them).
    fn accel_rows(&self, m: Move, p: &[f64; GYRO_PARAMETERS]) -> [[f64; PARAMETERS]; 2] {
        let k = matrix::inverse(&matrix_at(p, m.delta)).unwrap_or(matrix::IDENTITY);
        let q = self.turn(m, &k);
        let mut out = [[0.0; PARAMETERS]; 2];
        for j in 0..PARAMETERS {
            let h = ACCEL_STEP_SIGMAS * libm::sqrt(self.accel.covariance[j][j]);
            if h == 0.0 {
                continue;
            }
            let shifted = |h: f64| {
                let mut a = self.accel.params;
                a[j] += h;
                self.residuals_of_turn(m, &q, &a)
            };
            let (rp, rm) = (shifted(h), shifted(-h));
            for c in 0..2 {
                out[c][j] = (rp[c] - rm[c]) / (2.0 * h);
            }
        }
        out
    }
}

fn matrix_at(p: &[f64; GYRO_PARAMETERS], delta: f64) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| p[3 * i + j] + delta * p[9 + 3 * i + j]))
}

impl Problem<GYRO_PARAMETERS> for Moves<'_> {
    fn cost(&self, p: &[f64; GYRO_PARAMETERS]) -> f64 {
        let mut c = 0.0;
        self.each(|m| {
            for r in self.residuals(m, &matrix_at(p, m.delta)) {
                c += r * r;
            }
        });
        if c.is_nan() {
            f64::INFINITY
        } else {
            c
        }
    }

    fn rows(&self, p: &[f64; GYRO_PARAMETERS], row: &mut dyn FnMut([f64; GYRO_PARAMETERS], f64)) {
        self.each(|m| {
            let (r, grad) = self.rows_of(m, p);
            row(grad[0], r[0]);
            row(grad[1], r[1]);
        });
    }
}

/// Fits the gyro's (I+Σ)₀ and D; `full_scale` is the gyro's range, rad/s.
pub fn fit(
    sets: &[Poses],
    accel: &ThermalAccelFit,
    bias: &BiasPolynomial,
    full_scale: f64,
) -> Result<ThermalGyroFit, FitError> {
    let reference_c = accel.terms.reference_c;
    let problem = Moves {
        sets,
        accel,
        bias,
        reference_c,
    };
    let mut turns = [0usize; 2];
    let mut moves = 0usize;
    for s in sets {
        rig_free::check_range(&s.record, full_scale)?;
        let b = bias.at(reference_c);
        let (sample, step) = rig_free::fastest_step(&s.record, s.segments, &b);
        let limit = rig_free::MAX_ROTATION_PER_SAMPLE_DEG.to_radians();
        if step > limit {
            return Err(FitError::TooFastForRate {
                sample,
                rotation_deg: step.to_degrees(),
                limit_deg: rig_free::MAX_ROTATION_PER_SAMPLE_DEG,
                rate_hz: 1.0 / (s.record.t[sample + 1] - s.record.t[sample]),
            });
        }
    }
    problem.each(|m| {
        moves += 1;
        let q = problem.turn(m, &matrix::IDENTITY);
        let phi = quaternion::to_rotation_vector(&q);
        if libm::sqrt(dot(&phi, &phi)) >= MIN_TURN_DEG.to_radians()
            && m.delta.abs() >= LEVEL_C / 2.0
        {
            turns[usize::from(m.delta > 0.0)] += 1;
        }
    });
    if turns[0] < MIN_ROTATIONS || turns[1] < MIN_ROTATIONS {
        return Err(FitError::TooFewTurnsForScale {
            colder: turns[0],
            warmer: turns[1],
            reference_c,
            needed: MIN_ROTATIONS,
        });
    }
    let mut start = [0.0; GYRO_PARAMETERS];
    for i in 0..3 {
        start[4 * i] = 1.0;
    }
    let (p, iterations) = levenberg_marquardt::minimise(&problem, start, rig_free::MAX_ITERATIONS)?;

    let mut ls = GivensLs::<GYRO_PARAMETERS>::new();
    let (mut sum_sq, mut worst) = (0.0, 0.0f64);
    let mut cross = [[0.0; PARAMETERS]; GYRO_PARAMETERS];
    problem.each(|m| {
        let (r, grad) = problem.rows_of(m, &p);
        let ja = problem.accel_rows(m, &p);
        for c in 0..2 {
            ls.add_row(grad[c], -r[c]);
            sum_sq += r[c] * r[c];
            worst = worst.max(r[c].abs());
            for (row, g) in cross.iter_mut().zip(grad[c]) {
                for (x, a) in row.iter_mut().zip(ja[c]) {
                    *x += g * a;
                }
            }
        }
    });
    let condition = ls.scaled_condition();
    if condition.is_nan() || condition > MAX_CONDITION {
        return Err(FitError::IllConditioned {
            condition,
            limit: MAX_CONDITION,
        });
    }
    let gyro_dof = (2 * moves).saturating_sub(GYRO_PARAMETERS);
    if gyro_dof == 0 {
        return Err(FitError::TooFewRotations {
            rotations: moves,
            turns: turns[0] + turns[1],
            needed: GYRO_PARAMETERS / 2 + 1,
        });
    }
    let inv = ls.inverse_normal_matrix()?;
    let s2 = sum_sq / gyro_dof as f64;
    // The solution moves by dp = G·da, G = −(JᵀJ)⁻¹·Jᵀ·J_a: its covariance G·C_a·Gᵀ.
    let g: [[f64; PARAMETERS]; GYRO_PARAMETERS] = core::array::from_fn(|i| {
        core::array::from_fn(|k| {
            -(0..GYRO_PARAMETERS)
                .map(|m| inv[i][m] * cross[m][k])
                .sum::<f64>()
        })
    });
    let c = &accel.covariance;
    let carried: [f64; GYRO_PARAMETERS] = core::array::from_fn(|i| {
        let mut v = 0.0;
        for k in 0..PARAMETERS {
            for l in 0..PARAMETERS {
                v += g[i][k] * c[k][l] * g[i][l];
            }
        }
        v.max(0.0)
    });
    let own: [f64; GYRO_PARAMETERS] = core::array::from_fn(|k| s2 * inv[k][k]);
    let var: [f64; GYRO_PARAMETERS] = core::array::from_fn(|k| own[k] + carried[k]);
    let dof: [f64; GYRO_PARAMETERS] = core::array::from_fn(|k| {
        var[k] * var[k]
            / (own[k] * own[k] / gyro_dof as f64 + carried[k] * carried[k] / accel.dof as f64)
    });
    let half = |v: &[f64; GYRO_PARAMETERS], at: usize| -> Mat3 {
        core::array::from_fn(|i| core::array::from_fn(|j| v[at + 3 * i + j]))
    };
    let sigma = var.map(libm::sqrt);
    let smallest = dof.iter().fold(f64::INFINITY, |a, &x| a.min(x));
    Ok(ThermalGyroFit {
        scale_misalignment: half(&p, 0),
        sigma_scale_misalignment: half(&sigma, 0),
        scale_misalignment_per_c: half(&p, 9),
        sigma_scale_misalignment_per_c: half(&sigma, 9),
        dof_entries: [half(&dof, 0), half(&dof, 9)],
        dof: smallest as usize,
        gyro_dof,
        moves,
        turns,
        residual_rms: libm::sqrt(sum_sq / (2 * moves) as f64),
        residual_max: worst,
        condition,
        iterations,
    })
}
