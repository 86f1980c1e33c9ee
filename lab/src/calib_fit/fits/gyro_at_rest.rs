//! `fit gyro --static` whole: the gyroscope from one record at rest. A
//! record of several static poses (the accelerometer's, when it has one and
//! a detector is given) gives the bias and, where the poses' gravity
//! directions support it, the g-sensitivity G ([`static_gyro`]), each pose
//! checked still ([`stillness`]); any other record gives the bias alone,
//! the mean of each axis, the record checked still. With the vertical Earth
//! rate it is removed along the measured vertical (each pose's own, or the
//! record's).
//!
//! [`stillness`]: crate::calib_fit::stillness

use alloc::boxed::Box;
use alloc::vec::Vec;
use core::fmt;
use core::ops::Range;

use crate::calib_fit::fits::g_sensitivity::{AtRest, PoseNotStatic};
use crate::calib_fit::fits::static_gyro::{self, Frame};
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::poses::{self, Statistics};
use crate::calib_fit::static_segments::{self, Detector, Segment};
use crate::calib_fit::stillness::{self, NotStill};
use triad::model::matrix;

/// One record at rest: the gyroscope, and the accelerometer at the same
/// times when the record has it.
#[derive(Clone, Copy, Debug)]
pub struct AtRestRecord<'a> {
    /// Times, s, increasing.
    pub t: &'a [f64],
    /// The gyroscope's samples, rad/s.
    pub gyro: &'a [[f64; 3]],
    /// The accelerometer's samples, m/s², if the record has them.
    pub accel: Option<&'a [[f64; 3]]>,
    /// The record's parts (sample ranges, in order): no pose spans a gap.
    pub parts: &'a [Range<usize>],
}

/// What the fit is given besides the record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtRestOptions {
    /// The static poses' detector (for the record's rate); None: the bias alone.
    pub detector: Option<Detector>,
    /// The largest mean rate taken as a bias, °/s.
    pub max_bias_dps: f64,
    /// The vertical Earth rate Ω·sin φ to remove, rad/s, if a latitude is given.
    pub earth_vertical: Option<f64>,
    /// The accelerometer's (I+Σ) that corrects the poses' specific force
    /// (the one the calibration file carries with G).
    pub accel_scale_misalignment: Mat3,
    /// The accelerometer's b, m/s².
    pub accel_bias: [f64; 3],
    /// The gyro's (I+Σ), through which it sees the Earth rate.
    pub gyro_scale_misalignment: Mat3,
}

/// The gyroscope at rest, by the form the record gave.
#[derive(Clone, Debug, PartialEq)]
pub enum GyroAtRest {
    /// The bias alone, from a record still throughout.
    Bias(StaticBias),
    /// The bias (and G where supported) from several static poses.
    Poses(Box<PosesAtRest>),
}

/// The bias of a still record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticBias {
    /// The gyro's statistics over the record (mean, standard error s/√n, samples).
    pub statistics: Statistics,
    /// The bias: the mean, less the vertical Earth rate when given, rad/s.
    pub bias: [f64; 3],
    /// The static poses the accelerometer's detection found (fewer than
    /// two, so the bias alone); None where no detection ran.
    pub poses_detected: Option<usize>,
}

/// One static pose, for the report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseAtRest {
    /// Its samples.
    pub samples: Segment,
    /// |f| of its corrected specific force, m/s².
    pub force: f64,
}

/// The gyroscope at rest in several static poses.
#[derive(Clone, Debug, PartialEq)]
pub struct PosesAtRest {
    /// The poses, in order.
    pub poses: Vec<PoseAtRest>,
    /// The bias, G (or why not) and the poses' consistency.
    pub rest: AtRest,
}

/// A pose named in a refusal: its number (0-based) and first and last times, s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseTimes {
    /// The pose (0-based).
    pub pose: usize,
    /// Its first and last sample's times, s.
    pub time_s: [f64; 2],
}

/// Why `fit gyro --static` refused a record.
#[derive(Debug, PartialEq)]
pub enum GyroAtRestError {
    /// Fewer than two samples: no mean with a standard error.
    TooFewSamples {
        /// Samples in the record.
        count: usize,
    },
    /// The record (or a pose of it) is not still.
    NotStill {
        /// The pose, when the record has several.
        pose: Option<PoseTimes>,
        /// Why.
        why: NotStill,
        /// For the whole record: the static poses the accelerometer's
        /// detection found (fewer than two); None where no detection ran.
        poses_detected: Option<usize>,
    },
    /// The Earth rate's vertical needs the accelerometer, which the record lacks.
    NoAccelerometer,
    /// The mean specific force is zero: no vertical.
    NoVertical,
    /// The accelerometer's (I+Σ) given is singular.
    SingularAccel,
    /// A pose's gyro mean strays from what the others predict.
    PoseNotStatic(PoseNotStatic),
}

impl fmt::Display for GyroAtRestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GyroAtRestError::TooFewSamples { count } => write!(
                f,
                "{count} sample(s), need at least 2 for a mean and its standard error"
            ),
            GyroAtRestError::NotStill {
                pose: None,
                why,
                poses_detected,
            } => {
                write!(f, "{why}")?;
                match poses_detected {
                    Some(n) => write!(f, " ({})", fewer_than_two_poses(*n)),
                    None => Ok(()),
                }
            }
            GyroAtRestError::NotStill {
                pose: Some(p),
                why,
                ..
            } => write!(f, "{}", why.named(&alloc::format!("{p}"))),
            GyroAtRestError::NoAccelerometer => write!(
                f,
                "removing the vertical Earth rate needs the accelerometer (ax,ay,az) to tell the vertical"
            ),
            GyroAtRestError::NoVertical => {
                write!(f, "the mean specific force is zero: cannot tell the vertical")
            }
            GyroAtRestError::SingularAccel => write!(
                f,
                "the accelerometer's (I+Σ) is singular: cannot correct the poses' specific force"
            ),
            GyroAtRestError::PoseNotStatic(e) => write!(f, "gyroscope: {e}"),
        }
    }
}

impl fmt::Display for PoseTimes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "pose {} (t = {:.2}..{:.2} s)",
            self.pose + 1,
            self.time_s[0],
            self.time_s[1]
        )
    }
}

/// What a record with `n` (< 2) static poses detected is fitted as: said
/// with the bias alone and with its refusal, since a record that was meant
/// as several poses otherwise gets no word of why it was not.
pub fn fewer_than_two_poses(n: usize) -> alloc::string::String {
    alloc::format!(
        "the accelerometer's pose detection found {n} static pose(s) of at least --min-static: \
         the bias alone, of the whole record; G needs two or more"
    )
}

/// Fits the gyroscope at rest to `record` as `options` say.
pub fn fit(record: &AtRestRecord, options: &AtRestOptions) -> Result<GyroAtRest, GyroAtRestError> {
    let mut poses_detected = None;
    if let (Some(accel), Some(detector)) = (record.accel, &options.detector) {
        // Too many segments to hold is no count: nothing said of it.
        if let Ok(found) = poses::detect(detector, accel, record.parts) {
            if found.segments.len() >= 2 {
                return fit_poses(record, accel, &found.segments, options)
                    .map(|fit| GyroAtRest::Poses(Box::new(fit)));
            }
            poses_detected = Some(found.segments.len());
        }
    }
    fit_bias(record, options, poses_detected).map(GyroAtRest::Bias)
}

/// The bias alone: the mean of each axis of a still record.
fn fit_bias(
    record: &AtRestRecord,
    options: &AtRestOptions,
    poses_detected: Option<usize>,
) -> Result<StaticBias, GyroAtRestError> {
    let statistics = poses::statistics(record.gyro);
    if statistics.count < 2 {
        return Err(GyroAtRestError::TooFewSamples {
            count: statistics.count,
        });
    }
    stillness::check(
        record.gyro,
        record.accel,
        &statistics.mean,
        options.max_bias_dps,
    )
    .map_err(|why| GyroAtRestError::NotStill {
        pose: None,
        why,
        poses_detected,
    })?;
    let bias = match options.earth_vertical {
        Some(vertical) => {
            // At rest the specific force points up: its mean direction is
            // the vertical, which carries Ω·sin φ of the Earth rate.
            let accel = record.accel.ok_or(GyroAtRestError::NoAccelerometer)?;
            let up = static_segments::mean(accel);
            remove_vertical_rate(
                statistics.mean,
                up,
                vertical,
                &options.gyro_scale_misalignment,
            )
            .ok_or(GyroAtRestError::NoVertical)?
        }
        None => statistics.mean,
    };
    Ok(StaticBias {
        statistics,
        bias,
        poses_detected,
    })
}

/// The bias and G from several static poses, each checked still.
fn fit_poses(
    record: &AtRestRecord,
    accel: &[[f64; 3]],
    poses: &[Segment],
    options: &AtRestOptions,
) -> Result<PosesAtRest, GyroAtRestError> {
    for (pose, p) in poses.iter().enumerate() {
        let gyro = &record.gyro[p.start..p.end];
        let mean = poses::statistics(gyro).mean;
        stillness::check(
            gyro,
            Some(&accel[p.start..p.end]),
            &mean,
            options.max_bias_dps,
        )
        .map_err(|why| GyroAtRestError::NotStill {
            pose: Some(PoseTimes {
                pose,
                time_s: [record.t[p.start], record.t[p.end.max(p.start + 1) - 1]],
            }),
            why,
            poses_detected: None,
        })?;
    }
    let accel_inverse =
        matrix::inverse(&options.accel_scale_misalignment).ok_or(GyroAtRestError::SingularAccel)?;
    let frame = Frame {
        accel_inverse,
        accel_bias: options.accel_bias,
        earth: options
            .earth_vertical
            .map(|vertical| (vertical, options.gyro_scale_misalignment)),
    };
    let rest = static_gyro::fit(record.t, record.gyro, accel, poses, &frame)
        .map_err(GyroAtRestError::PoseNotStatic)?;
    let poses = poses
        .iter()
        .map(|&samples| {
            let f = static_gyro::specific_force(&accel[samples.start..samples.end], &frame);
            PoseAtRest {
                samples,
                force: libm::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]),
            }
        })
        .collect();
    Ok(PosesAtRest { poses, rest })
}

/// `mean` less the vertical Earth rate `vertical` (Ω·sin φ, rad/s) along
/// the direction of `up`, as the gyro measures it through (I+Σ) = `scale`:
/// ω̂ = (I+Σ)·ω_e + b. None when `up` is zero.
pub fn remove_vertical_rate(
    mean: [f64; 3],
    up: [f64; 3],
    vertical: f64,
    scale: &Mat3,
) -> Option<[f64; 3]> {
    let n = libm::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    if n.is_nan() || n <= 0.0 {
        return None;
    }
    let w = up.map(|fi| vertical * fi / n);
    let seen = matrix::mul_vec(scale, &w);
    let mut bias = mean;
    for (b, x) in bias.iter_mut().zip(seen) {
        *b -= x;
    }
    Some(bias)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::units::EARTH_RATE;

    #[test]
    fn the_vertical_earth_rate_is_removed_along_the_measured_up() {
        // Level, z up, at the pole: all of Ω on z.
        let b = remove_vertical_rate(
            [1.0, 2.0, 3.0],
            [0.0, 0.0, 9.8],
            EARTH_RATE,
            &matrix::IDENTITY,
        )
        .unwrap();
        assert_eq!((b[0], b[1]), (1.0, 2.0));
        assert!((b[2] - (3.0 - EARTH_RATE)).abs() < 1e-15);
        // At the equator nothing is vertical.
        let b = remove_vertical_rate([1.0; 3], [0.0, 9.8, 0.0], 0.0, &matrix::IDENTITY).unwrap();
        assert_eq!(b, [1.0; 3]);
        assert!(remove_vertical_rate([0.0; 3], [0.0; 3], EARTH_RATE, &matrix::IDENTITY).is_none());
    }
}
