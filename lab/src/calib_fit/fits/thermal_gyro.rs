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
//! the nine derivatives in (I+Σ) from one pass over the move
//! ([`crate::calib_fit::fits::turn_sensitivity`], as the rig-free fit)
//! give all eighteen columns. The σ's are
//! s²·(JᵀJ)⁻¹ with 2·moves − 18 degrees of freedom plus the variance carried
//! from the accelerometer fit's covariance (its error moves every gravity
//! direction), combined per entry by Welch–Satterthwaite; the bias
//! polynomial's error is not carried (its effect, σ_b × a turn's duration,
//! is far below the noise integrated over a turn, as in the rig-free fit).

use core::fmt;

use crate::calib_fit::fits::bias_polynomial::BiasPolynomial;
use crate::calib_fit::fits::rig_free::{
    self, across, dot, MoveBias, Record, MIN_ROTATIONS, MIN_TURN_DEG,
};
use crate::calib_fit::fits::thermal_accel::{self, ThermalAccelFit, MAX_CONDITION, PARAMETERS};
use crate::calib_fit::fits::thermal_coverage::LEVEL_C;
use crate::calib_fit::fits::turn_refusals::{RangeError, TooFastForRate, TooFewRotations};
use crate::calib_fit::fits::turn_sensitivity::{self, TurnSensitivity};
use crate::calib_fit::numerics::error::{check_condition, NumericsError};
use crate::calib_fit::numerics::levenberg_marquardt::{self, Problem};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::quaternion;
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::static_segments::Segment;
use triad::model::matrix;

/// Parameters: (I+Σ)₀ row by row, then D row by row.
pub const GYRO_PARAMETERS: usize = 18;

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

    fn move_bias(&self, m: Move) -> MoveBias {
        MoveBias::constant(self.bias.at(self.reference_c + m.delta))
    }

    fn turn(&self, m: Move, k: &Mat3) -> quaternion::Quat {
        let s = &self.sets[m.set];
        rig_free::integrate(
            &s.record,
            &s.segments[m.pose],
            &s.segments[m.pose + 1],
            k,
            &self.move_bias(m),
        )
    }

    /// Move `m` integrated once at `k` = (I+Σ)⁻¹, with its sensitivity to (I+Σ).
    fn turn_with_sensitivity(&self, m: Move, k: &Mat3) -> (quaternion::Quat, TurnSensitivity) {
        let s = &self.sets[m.set];
        let mut gather = turn_sensitivity::Accumulator::new(None);
        let q = rig_free::integrate_observed(
            &s.record,
            &s.segments[m.pose],
            &s.segments[m.pose + 1],
            k,
            &self.move_bias(m),
            |x| gather.add(x),
        );
        (q, gather.finish())
    }

    /// Move `m`'s gravity directions before and after, for accelerometer parameters `a`.
    fn ends(&self, m: Move, a: &[f64; PARAMETERS]) -> [[f64; 3]; 2] {
        let s = &self.sets[m.set];
        let up =
            |i: usize| thermal_accel::up(a, self.reference_c, &s.accel_means[i], s.temperatures[i]);
        [up(m.pose), up(m.pose + 1)]
    }

    fn residuals_of_turn(&self, m: Move, q: &quaternion::Quat, a: &[f64; PARAMETERS]) -> [f64; 2] {
        let [before, after] = self.ends(m, a);
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

    /// (residuals, ∂/∂ the 18 parameters, the end attitude) of move `m` at
    /// `p`, from one integration ([`turn_sensitivity::scale_gradient`]);
    /// NaN when (I+Σ)(ΔT) is singular.
    fn rows_of(
        &self,
        m: Move,
        p: &[f64; GYRO_PARAMETERS],
    ) -> ([f64; 2], [[f64; GYRO_PARAMETERS]; 2], quaternion::Quat) {
        let Some(k) = matrix::inverse(&matrix_at(p, m.delta)) else {
            return (
                [f64::NAN; 2],
                [[f64::NAN; GYRO_PARAMETERS]; 2],
                quaternion::IDENTITY,
            );
        };
        let (q, sensitivity) = self.turn_with_sensitivity(m, &k);
        let a = &self.accel.params;
        let [before, after] = self.ends(m, a);
        let predicted = quaternion::rotate_inverse(&q, &before);
        let at =
            turn_sensitivity::scale_gradient(&sensitivity, &q, &k, &predicted, &across(&after));
        let grad = at
            .map(|row| core::array::from_fn(|e| if e < 9 { row[e] } else { m.delta * row[e - 9] }));
        (self.residuals_of_turn(m, &q, a), grad, q)
    }

    /// ∂(residuals of move m)/∂(the accelerometer's parameters), by central
    /// differences of the gravity directions at the integrated turn `q`
    /// (the turn does not depend on them).
    fn accel_rows(&self, m: Move, q: &quaternion::Quat) -> [[f64; PARAMETERS]; 2] {
        let mut out = [[0.0; PARAMETERS]; 2];
        for j in 0..PARAMETERS {
            let h = ACCEL_STEP_SIGMAS * libm::sqrt(self.accel.covariance[j][j]);
            if h == 0.0 {
                continue;
            }
            let shifted = |h: f64| {
                let mut a = self.accel.params;
                a[j] += h;
                self.residuals_of_turn(m, q, &a)
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
            let (r, grad, _) = self.rows_of(m, p);
            row(grad[0], r[0]);
            row(grad[1], r[1]);
        });
    }
}

/// Why the gyroscope's (I+Σ) against temperature was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThermalGyroError {
    /// The full scale given is not a rate, or a record comes near it.
    Range(RangeError),
    /// A record turns too far between two samples for the integration.
    TooFastForRate(TooFastForRate),
    /// Too few turns both colder and warmer than the reference temperature.
    TooFewTurnsForScale {
        /// Turns of ≥ 10° colder than the reference.
        colder: usize,
        /// Warmer.
        warmer: usize,
        /// The reference temperature, °C.
        reference_c: f64,
        /// The minimum on each side.
        needed: usize,
    },
    /// Too few moves for the 18 parameters to leave a degree of freedom.
    TooFewRotations(TooFewRotations),
    /// The parameters are not determined, or the iteration did not converge.
    Numerics(NumericsError),
}

impl From<NumericsError> for ThermalGyroError {
    fn from(e: NumericsError) -> Self {
        ThermalGyroError::Numerics(e)
    }
}

impl From<RangeError> for ThermalGyroError {
    fn from(e: RangeError) -> Self {
        ThermalGyroError::Range(e)
    }
}

impl fmt::Display for ThermalGyroError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalGyroError::Range(e) => write!(f, "{e}"),
            ThermalGyroError::TooFastForRate(e) => write!(f, "{e}"),
            ThermalGyroError::TooFewTurnsForScale {
                colder,
                warmer,
                reference_c,
                needed,
            } => write!(
                f,
                "the gyro's (I+Σ) against temperature needs ≥ {needed} turns of ≥ {MIN_TURN_DEG} degrees between static \
                 poses both colder and warmer than the reference {reference_c:.1} °C; found {colder} colder and \
                 {warmer} warmer: turn the unit by hand between poses at each end of the range (the hand-soak script)"
            ),
            ThermalGyroError::TooFewRotations(e) => write!(f, "{e}"),
            ThermalGyroError::Numerics(e) => write!(f, "{e}"),
        }
    }
}

/// Fits the gyro's (I+Σ)₀ and D; `full_scale` is the gyro's range, rad/s.
pub fn fit(
    sets: &[Poses],
    accel: &ThermalAccelFit,
    bias: &BiasPolynomial,
    full_scale: f64,
) -> Result<ThermalGyroFit, ThermalGyroError> {
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
            return Err(ThermalGyroError::TooFastForRate(TooFastForRate {
                sample,
                rotation_deg: step.to_degrees(),
                limit_deg: rig_free::MAX_ROTATION_PER_SAMPLE_DEG,
                rate_hz: 1.0 / (s.record.t[sample + 1] - s.record.t[sample]),
            }));
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
        return Err(ThermalGyroError::TooFewTurnsForScale {
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
        let (r, grad, q) = problem.rows_of(m, &p);
        let ja = problem.accel_rows(m, &q);
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
    check_condition(condition, MAX_CONDITION)?;
    let gyro_dof = (2 * moves).saturating_sub(GYRO_PARAMETERS);
    if gyro_dof == 0 {
        return Err(ThermalGyroError::TooFewRotations(TooFewRotations {
            rotations: moves,
            turns: turns[0] + turns[1],
            needed: GYRO_PARAMETERS / 2 + 1,
        }));
    }
    let inv = ls.inverse_normal_matrix().map_err(NumericsError::from)?;
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

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::calib_fit::fits::bias_polynomial::{self, StaticMean};
    use crate::calib_fit::fits::thermal_accel::Terms;
    use crate::calib_fit::hand_record;
    use crate::calib_fit::poses as found;
    use std::vec;
    use std::vec::Vec;
    use triad_sim::effects::rng::Rng;

    /// The one-pass Jacobian against central differences of the
    /// re-integrated residuals (the method it replaced), on a hand session
    /// whose poses step through 20..33 °C (1 °C apart: every move counts,
    /// at ΔT from −5 to +8 °C about the reference, so D's columns are
    /// ΔT times (I+Σ)₀'s and not zero). As in the rig-free fit's test, the
    /// one pass differentiates the continuous turn, the differences the
    /// RK4 steps: 1e-4 of the row's size bounds their difference (a wrong
    /// sign or index gives an error of the row's own size).
    #[test]
    fn the_one_pass_jacobian_matches_central_differences() {
        let unit = hand_record::MEMS_UNIT;
        let mut rng = Rng::from_seed(8);
        let hand_record::Recorded {
            t,
            accel,
            gyro,
            poses,
        } = hand_record::recorded(&hand_record::SESSION, &unit, &mut || rng.uniform());
        let n = poses.len();
        let temperatures: Vec<f64> = (0..n).map(|j| 20.0 + j as f64).collect();
        let mean_of = |x: &[[f64; 3]], j: usize| {
            let s = found::statistics(&x[poses[j].start..poses[j].end]);
            StaticMean {
                temperature_c: temperatures[j],
                mean: s.mean,
                standard_error: s.standard_error,
            }
        };
        let accel_stats: Vec<StaticMean> = (0..n).map(|j| mean_of(&accel, j)).collect();
        let gyro_stats: Vec<StaticMean> = (0..n).map(|j| mean_of(&gyro, j)).collect();
        let terms = Terms {
            reference_c: 25.0,
            bias_order: 0,
            scale: false,
        };
        let (mut scratch, mut weights) = (vec![[0.0; 3]; n], vec![0.0; n]);
        let accel_fit = thermal_accel::fit(
            &accel_stats,
            unit.gravity,
            terms,
            &mut scratch,
            &mut weights,
        )
        .unwrap();
        let bias = bias_polynomial::fit(&gyro_stats, 25.0, 0).unwrap();
        let accel_means: Vec<[f64; 3]> = accel_stats.iter().map(|m| m.mean).collect();
        let sets = [Poses {
            record: Record { t: &t, gyro: &gyro },
            segments: &poses,
            accel_means: &accel_means,
            temperatures: &temperatures,
        }];
        let problem = Moves {
            sets: &sets,
            accel: &accel_fit,
            bias: &bias,
            reference_c: 25.0,
        };
        let mut p = [0.0; GYRO_PARAMETERS];
        for (i, row) in unit.gyro.scale_misalignment.iter().enumerate() {
            p[3 * i..3 * i + 3].copy_from_slice(row);
            p[9 + 4 * i] = [1e-4, -8e-5, 6e-5][i];
        }
        p[10] = 2e-5;
        let h = 1e-6;
        let mut moves = 0;
        problem.each(|m| {
            moves += 1;
            let (r, analytic, _) = problem.rows_of(m, &p);
            assert_eq!(r, problem.residuals(m, &matrix_at(&p, m.delta)));
            let mut numeric = [[0.0; GYRO_PARAMETERS]; 2];
            for k in 0..GYRO_PARAMETERS {
                let shifted = |x: f64| {
                    let mut q = p;
                    q[k] += x;
                    problem.residuals(m, &matrix_at(&q, m.delta))
                };
                let (rp, rm) = (shifted(h), shifted(-h));
                for c in 0..2 {
                    numeric[c][k] = (rp[c] - rm[c]) / (2.0 * h);
                }
            }
            for c in 0..2 {
                let size = numeric[c].iter().fold(0.0f64, |a, x| a.max(x.abs()));
                assert!(size > 0.0);
                for k in 0..GYRO_PARAMETERS {
                    assert!(
                        (analytic[c][k] - numeric[c][k]).abs() <= 1e-4 * size,
                        "move from pose {} row {c} entry {k}: {} vs {} (row size {size})",
                        m.pose,
                        analytic[c][k],
                        numeric[c][k]
                    );
                }
            }
        });
        assert_eq!(moves, n - 1);
    }
}
