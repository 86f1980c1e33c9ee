//! Is a record still? `calib fit gyro --static` takes each axis's mean rate
//! as the bias, which is only right if the sensor did not turn (and the
//! live session holds a pose by the same measure). Two tests, each refusing
//! with the figure it measured ([`NotStill`]):
//!
//! 1. **Steadiness.** The record is cut into [`BLOCKS`] equal blocks. Any
//!    turn during part of the record moves the block means of the gyro
//!    (and of the accelerometer, whose view of gravity turns with it) far
//!    beyond what noise does. A block mean may differ from the record's
//!    mean by at most max(6 standard errors of a block mean, a floor); the
//!    standard error comes from the median within-block deviation (a block
//!    with a turn in it does not inflate it). Six standard errors over 8
//!    blocks × 3 axes of white noise are exceeded with probability ~5e-8;
//!    the floors ([`GYRO_FLOOR_DPS`], [`ACCEL_FLOOR`]) sit above the bias
//!    instability of every MEMS grade, which also moves block means.
//! 2. **A plausible bias.** A turn at one constant rate (a rate table) is
//!    steady; then the mean rate itself must be a plausible bias: at most
//!    `--max-bias` (default [`DEFAULT_MAX_BIAS_DPS`]).

use alloc::vec::Vec;
use core::fmt;

use crate::calib_fit::static_segments;
use triad::units::{deg_to_rad, rad_to_deg};

/// Blocks the record is cut into.
pub const BLOCKS: usize = 8;

/// Standard errors a block mean may stray from the record's mean.
const SIGMAS: f64 = 6.0;

/// Floor of the gyro's steadiness threshold, °/s: above the worst bias
/// instability of the MEMS grades (rate grade up to 1000 °/h ≈ 0.28 °/s);
/// a turn of 5° within a block of 10 s already moves its mean by 0.5 °/s.
pub const GYRO_FLOOR_DPS: f64 = 0.5;

/// Floor of the accelerometer's steadiness threshold, m/s² (about 10 mg):
/// above the bias instability of tactical and navigation accelerometers
/// (≤ 1 mg, THEORY.md's table), not of automotive ones (10–100 mg there),
/// whose block means wander by tens of mg: a still automotive record is
/// refused. A tilt of 1° moves a horizontal component by 0.17 m/s².
pub const ACCEL_FLOOR: f64 = 0.1;

/// Default `--max-bias`, °/s: above the zero-rate offset of MEMS gyros
/// (data sheets give ±0.5 to ±5 °/s; older parts up to ±20, which need the
/// option raised), below the rates a table or a hand turns at.
pub const DEFAULT_MAX_BIAS_DPS: f64 = 10.0;

/// The largest stray of a block mean from the record's mean (per axis,
/// the worst axis) and the threshold it was held to, in the record's unit.
#[derive(Debug, PartialEq)]
pub struct Steadiness {
    /// The worst block's distance from the record's mean.
    pub stray: f64,
    /// The axis (0, 1, 2) and block (0-based) where it is.
    pub axis: usize,
    /// The block.
    pub block: usize,
    /// max(6 standard errors of a block mean, floor).
    pub limit: f64,
}

/// The steadiness of `samples` with the threshold's `floor`; None when the
/// record is too short to cut into blocks of two samples.
pub fn steadiness(samples: &[[f64; 3]], floor: f64) -> Option<Steadiness> {
    let per_block = samples.len() / BLOCKS;
    if per_block < 2 {
        return None;
    }
    // Each block's mean and standard deviation, all three axes at once.
    let (block_means, block_sds): (Vec<[f64; 3]>, Vec<[f64; 3]>) = samples
        .chunks_exact(per_block)
        .take(BLOCKS)
        .map(|b| {
            (
                static_segments::mean(b),
                static_segments::standard_deviation(b),
            )
        })
        .unzip();
    let mean = static_segments::mean(&samples[..per_block * BLOCKS]);
    // The block farthest from the mean relative to its limit.
    let mut worst: Option<(f64, Steadiness)> = None;
    for (axis, &axis_mean) in mean.iter().enumerate() {
        let mut sd: Vec<f64> = block_sds.iter().map(|s| s[axis]).collect();
        sd.sort_by(f64::total_cmp);
        let se = sd[BLOCKS / 2] / libm::sqrt(per_block as f64);
        let limit = (SIGMAS * se).max(floor);
        for (block, block_mean) in block_means.iter().enumerate() {
            let stray = (block_mean[axis] - axis_mean).abs();
            let ratio = stray / limit;
            if worst.as_ref().is_none_or(|(r, _)| ratio > *r) {
                let s = Steadiness {
                    stray,
                    axis,
                    block,
                    limit,
                };
                worst = Some((ratio, s));
            }
        }
    }
    worst.map(|(_, s)| s)
}

/// Why a record is not still: the worst block of the gyro or of the
/// accelerometer, or a steady mean rate too large for a bias.
#[derive(Debug, PartialEq)]
pub enum NotStill {
    /// A block mean of the gyro (rad/s) strays: the sensor turned, or its
    /// bias drifts.
    Turned(Steadiness),
    /// A block mean of the accelerometer (m/s²) strays: the sensor turned or moved.
    Moved(Steadiness),
    /// The record is steady but its mean rate is above the largest bias
    /// accepted: a turn at a steady rate.
    NotABias {
        /// The axis (0, 1, 2).
        axis: usize,
        /// Its |mean rate|, °/s.
        rate_dps: f64,
        /// The largest accepted, °/s.
        max_bias_dps: f64,
    },
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Refuses a gyro record (rad/s) that is not still, by the two tests, with
/// `accel` (m/s²) when the record has it; `mean_rate` is the gyro's mean,
/// `max_bias_dps` the largest plausible bias (°/s).
pub fn check(
    gyro: &[[f64; 3]],
    accel: Option<&[[f64; 3]]>,
    mean_rate: &[f64; 3],
    max_bias_dps: f64,
) -> Result<(), NotStill> {
    if let Some(s) = steadiness(gyro, deg_to_rad(GYRO_FLOOR_DPS)) {
        if s.stray > s.limit {
            return Err(NotStill::Turned(s));
        }
    }
    if let Some(s) = accel.and_then(|a| steadiness(a, ACCEL_FLOOR)) {
        if s.stray > s.limit {
            return Err(NotStill::Moved(s));
        }
    }
    let (axis, worst) = mean_rate
        .iter()
        .enumerate()
        .map(|(k, w)| (k, rad_to_deg(w.abs())))
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    if worst > max_bias_dps {
        return Err(NotStill::NotABias {
            axis,
            rate_dps: worst,
            max_bias_dps,
        });
    }
    Ok(())
}

impl NotStill {
    /// The refusal as a sentence about the record `name`.
    pub fn named<'a>(&'a self, name: &'a str) -> Named<'a> {
        Named { error: self, name }
    }
}

/// [`NotStill`] about a named record ([`NotStill::named`]).
pub struct Named<'a> {
    error: &'a NotStill,
    name: &'a str,
}

impl fmt::Display for Named<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.name;
        match self.error {
            NotStill::Turned(s) => write!(
                f,
                "{name} is not static: the mean rate about {} in part {} of {BLOCKS} differs from the record's \
                 by {:.3} °/s (limit {:.3} °/s): the sensor turned, or its bias drifts; --static needs a still record",
                AXES[s.axis],
                s.block + 1,
                rad_to_deg(s.stray),
                rad_to_deg(s.limit)
            ),
            NotStill::Moved(s) => write!(
                f,
                "{name} is not static: the mean specific force along {} in part {} of {BLOCKS} differs from the \
                 record's by {:.3} m/s² (limit {:.3} m/s²): the sensor turned or moved; --static needs a still record",
                AXES[s.axis],
                s.block + 1,
                s.stray,
                s.limit
            ),
            NotStill::NotABias {
                axis,
                rate_dps,
                max_bias_dps,
            } => write!(
                f,
                "{name}: the mean rate about {} is {rate_dps:.3} °/s, above --max-bias {max_bias_dps} °/s: \
                 a turn at a steady rate (a rate table?), not a bias; raise --max-bias if the gyro's offset is that large",
                AXES[*axis]
            ),
        }
    }
}

impl fmt::Display for NotStill {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.named("the record"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::{String, ToString};

    /// [`check`], refused as the message about `name`.
    fn checked(
        name: &str,
        gyro: &[[f64; 3]],
        accel: Option<&[[f64; 3]]>,
        mean_rate: &[f64; 3],
        max_bias_dps: f64,
    ) -> Result<(), String> {
        check(gyro, accel, mean_rate, max_bias_dps).map_err(|e| e.named(name).to_string())
    }

    /// `n` samples of alternating ±`noise` around `level` on every axis.
    fn steady(n: usize, level: f64, noise: f64) -> Vec<[f64; 3]> {
        (0..n)
            .map(|i| [level + if i % 2 == 0 { noise } else { -noise }; 3])
            .collect()
    }

    #[test]
    fn a_still_record_passes_and_a_turn_in_one_part_is_found() {
        let still = steady(800, 0.01, 0.002);
        let s = steadiness(&still, 0.0).unwrap();
        assert!(s.stray < 1e-12, "{s:?}");
        assert!(checked("r.csv", &still, None, &[0.01; 3], 10.0).is_ok());
        // A turn at 20 °/s about y for the 5th block.
        let mut turned = still.clone();
        for v in &mut turned[400..500] {
            v[1] += deg_to_rad(20.0);
        }
        let s = steadiness(&turned, deg_to_rad(GYRO_FLOOR_DPS)).unwrap();
        assert_eq!((s.axis, s.block), (1, 4));
        let err = checked("r.csv", &turned, None, &[0.01; 3], 10.0)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("r.csv is not static: the mean rate about y in part 5 of 8 differs from the record's by 17.500 °/s (limit 0.500 °/s)"),
            "{err}"
        );
    }

    #[test]
    fn a_steady_turn_is_refused_by_its_rate_and_a_tilt_by_the_accelerometer() {
        let table = steady(800, deg_to_rad(30.0), 1e-3);
        let err = checked("t.csv", &table, None, &[0.0, 0.0, deg_to_rad(30.0)], 10.0)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("t.csv: the mean rate about z is 30.000 °/s, above --max-bias 10 °/s"),
            "{err}"
        );
        assert!(checked("t.csv", &table, None, &[0.0, 0.0, deg_to_rad(30.0)], 40.0).is_ok());
        let still = steady(800, 0.0, 1e-3);
        let mut accel = steady(800, 9.8, 0.01);
        for v in &mut accel[700..] {
            v[0] -= 1.0;
        }
        let err = checked("a.csv", &still, Some(&accel), &[0.0; 3], 10.0)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("specific force along x in part 8 of 8"),
            "{err}"
        );
        // Too short to cut: only the rate test applies.
        assert!(steadiness(&still[..15], 0.1).is_none());
    }
}
