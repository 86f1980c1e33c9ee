//! `fit imu` whole: both triads from one record of the IMU turned by hand
//! between static poses, no rate table and no fixture. The poses are
//! detected ([`poses`]) or given; the accelerometer is fitted first from
//! the poses in unknown orientations ([`accel_fit`]) or, on a cube's faces,
//! from the known face directions ([`accel_cube`]); then the moves the gyro
//! fit can use are chosen ([`move_selection`]) and the gyroscope's bias, G
//! and (I+Σ) fitted by integrating it between consecutive poses
//! ([`rig_free`]). The result carries what a report says: every pose with
//! its number and samples, what was left out and why.

use alloc::boxed::Box;
use alloc::vec::Vec;
use core::fmt;
use core::ops::Range;

use crate::calib_fit::fits::accel_cube::{self, AccelCubeError};
use crate::calib_fit::fits::accel_fit::{self, AccelFit, AccelFitError};
use crate::calib_fit::fits::gyro_fit::LinearFit;
use crate::calib_fit::fits::move_selection::{self, LeftOut};
use crate::calib_fit::fits::rig_free::{self, RigFreeError, RigFreeGyroFit};
use crate::calib_fit::poses::{self, Statistics};
use crate::calib_fit::static_segments::{DetectError, Detector, Dropped, Segment};

/// One record of the IMU: both triads at the same times.
#[derive(Clone, Copy, Debug)]
pub struct ImuRecord<'a> {
    /// Times, s, increasing.
    pub t: &'a [f64],
    /// The accelerometer's samples, m/s².
    pub accel: &'a [[f64; 3]],
    /// The gyroscope's samples, rad/s.
    pub gyro: &'a [[f64; 3]],
    /// The record's parts (sample ranges, in order): where its time stamps
    /// leave a gap, no pose spans it and no move is integrated across it.
    pub parts: &'a [Range<usize>],
}

/// Where the poses come from.
#[derive(Clone, Debug, PartialEq)]
pub enum PoseSource {
    /// The accelerometer's static stretches, found by this detector.
    Detect(Detector),
    /// These sample ranges, in order.
    Given(Vec<Segment>),
}

/// How the fit finds and uses the poses.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuOptions {
    /// Local gravity, m/s².
    pub gravity: f64,
    /// The gyro's full scale, rad/s.
    pub full_scale: f64,
    /// The poses.
    pub poses: PoseSource,
    /// Numbers (1-based, as found) of poses to leave out.
    pub exclude: Vec<usize>,
    /// The poses are a cube's faces: the accelerometer's full (I+Σ) from
    /// the face directions, both triads in the faces' frame.
    pub axis_aligned: bool,
}

/// A pose the fit used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Its number among the poses found (1-based, as the report names it).
    pub number: usize,
    /// Its samples.
    pub samples: Segment,
    /// Its accelerometer statistics.
    pub accel: Statistics,
}

/// A move between consecutive used poses that the gyro fit left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeftOutMove {
    /// The poses' numbers, from and to.
    pub poses: [usize; 2],
    /// Its samples: the first pose's last to the next pose's first.
    pub samples: Segment,
    /// Why.
    pub why: LeftOut,
}

/// Both triads fitted from one record, with what the report says.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuFit {
    /// The poses used, in order.
    pub poses: Vec<Pose>,
    /// The poses left out as the options asked (number, samples).
    pub excluded: Vec<(usize, Segment)>,
    /// The candidates detection dropped.
    pub dropped: Vec<Dropped>,
    /// The accelerometer fit (on a cube's faces: that fit in the form the
    /// gyro fit takes, [`faces_frame`]).
    pub accel: AccelFit,
    /// Whether the poses were fitted as a cube's faces.
    pub axis_aligned: bool,
    /// The gyroscope fit.
    pub gyro: RigFreeGyroFit,
    /// The moves left out.
    pub left_out: Vec<LeftOutMove>,
    /// Samples beyond [`rig_free::MAX_RANGE_FRACTION`] of the gyro's full
    /// scale outside the poses and moves the fit used (ignored).
    pub outside: Vec<usize>,
}

/// Why `fit imu` refused a record.
#[derive(Clone, Debug, PartialEq)]
pub enum ImuFitError {
    /// Static detection failed.
    Detection(DetectError),
    /// A pose to leave out is not among those found.
    NoSuchPose {
        /// The number asked for.
        pose: usize,
        /// Poses found.
        poses: usize,
    },
    /// The accelerometer fit (poses in unknown orientations) refused the poses.
    Accel {
        /// Why.
        error: AccelFitError,
        /// Poses used.
        poses: usize,
    },
    /// The accelerometer's fit on a cube's faces refused the poses.
    AccelCube {
        /// Why.
        error: AccelCubeError,
        /// Poses used.
        poses: usize,
    },
    /// The gyroscope fit refused the poses or moves.
    Gyro(Box<GyroRefusal>),
}

/// The gyroscope fit's refusal, with the poses and moves it concerns.
#[derive(Clone, Debug, PartialEq)]
pub struct GyroRefusal {
    /// Why.
    pub error: RigFreeError,
    /// The pose the error names (a pose that is not static), if any.
    pub pose: Option<Pose>,
    /// The moves left out before the fit.
    pub left_out: Vec<LeftOutMove>,
}

impl fmt::Display for ImuFitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImuFitError::Detection(e) => write!(f, "{e}"),
            ImuFitError::NoSuchPose { pose, poses } => write!(
                f,
                "pose {pose} to leave out: the record has {poses} pose(s), numbered from 1"
            ),
            ImuFitError::Accel { error, .. } => write!(f, "accelerometer: {error}"),
            ImuFitError::AccelCube { error, .. } => write!(f, "accelerometer: {error}"),
            ImuFitError::Gyro(refusal) => write!(f, "gyroscope: {}", refusal.error),
        }
    }
}

/// Fits both triads to `record` as `options` say.
pub fn fit(record: &ImuRecord, options: &ImuOptions) -> Result<ImuFit, ImuFitError> {
    let (found, dropped) = match &options.poses {
        PoseSource::Given(segments) => (segments.clone(), Vec::new()),
        PoseSource::Detect(detector) => {
            let d = poses::detect(detector, record.accel, record.parts)
                .map_err(ImuFitError::Detection)?;
            (d.segments, d.dropped)
        }
    };
    if let Some(&pose) = options.exclude.iter().find(|&&n| n == 0 || n > found.len()) {
        return Err(ImuFitError::NoSuchPose {
            pose,
            poses: found.len(),
        });
    }
    let used: Vec<Pose> = found
        .iter()
        .enumerate()
        .map(|(i, &samples)| Pose {
            number: i + 1,
            samples,
            accel: poses::statistics(&record.accel[samples.start..samples.end]),
        })
        .filter(|p| !options.exclude.contains(&p.number))
        .collect();
    let excluded = options.exclude.iter().map(|&n| (n, found[n - 1])).collect();
    let segments: Vec<Segment> = used.iter().map(|p| p.samples).collect();
    let means: Vec<[f64; 3]> = used.iter().map(|p| p.accel.mean).collect();
    let poses = means.len();
    // The gravity direction of each pose comes from the accelerometer fit
    // (unknown orientations) or, on a cube's faces, from the face itself.
    let (accel, directions) = if options.axis_aligned {
        let fit = accel_cube::fit(&means, options.gravity)
            .map_err(|error| ImuFitError::AccelCube { error, poses })?;
        let faces: Vec<[f64; 3]> = means
            .iter()
            .map(|m| accel_cube::reference(m, options.gravity).unwrap_or([0.0; 3]))
            .collect();
        (faces_frame(&fit, &faces), faces)
    } else {
        let fit = accel_fit::fit(&means, options.gravity)
            .map_err(|error| ImuFitError::Accel { error, poses })?;
        (fit, means.clone())
    };

    // The moves: between consecutive used poses in one part of the record,
    // within the gyro's range.
    let gyro_record = rig_free::Record {
        t: record.t,
        gyro: record.gyro,
    };
    let selection =
        move_selection::select(&gyro_record, &segments, record.parts, options.full_scale);
    let left_out: Vec<LeftOutMove> = selection
        .left_out
        .iter()
        .map(|&(j, why)| {
            let (a, b) = (used[j], used[j + 1]);
            LeftOutMove {
                poses: [a.number, b.number],
                samples: Segment {
                    start: a.samples.end - 1,
                    end: b.samples.start + 1,
                },
                why,
            }
        })
        .collect();
    let gyro = rig_free::fit_moves(
        gyro_record,
        &segments,
        &selection.moves,
        &directions,
        &accel,
        options.full_scale,
    )
    .map_err(|error| {
        ImuFitError::Gyro(Box::new(GyroRefusal {
            pose: match error {
                RigFreeError::PoseNotStatic(e) => used.get(e.pose).copied(),
                _ => None,
            },
            error,
            left_out: left_out.clone(),
        }))
    })?;
    Ok(ImuFit {
        poses: used,
        excluded,
        dropped,
        accel,
        axis_aligned: options.axis_aligned,
        gyro,
        left_out,
        outside: selection.outside,
    })
}

/// The cube fit `fit` as the rig-free gyro fit takes an accelerometer fit:
/// its (I+Σ), b and statistics for the report, and the faces' frame for
/// the gravity directions (T = I, b = 0 applied to the `faces`' ±g e_k,
/// taken as exact: no variance carried into the gyro's σ's).
pub fn faces_frame(fit: &LinearFit, faces: &[[f64; 3]]) -> AccelFit {
    let mut distinct: Vec<[f64; 3]> = Vec::new();
    for f in faces {
        if !distinct.contains(f) {
            distinct.push(*f);
        }
    }
    AccelFit {
        inverse: triad::model::matrix::inverse(&fit.scale_misalignment)
            .unwrap_or(triad::model::matrix::IDENTITY),
        scale_misalignment: fit.scale_misalignment,
        bias: fit.bias,
        params: [1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        covariance: Some([[0.0; 9]; 9]),
        sigma_scale_misalignment: fit.sigma_scale_misalignment,
        sigma_bias: fit.sigma_bias,
        residual_rms: fit.residual_rms,
        residual_max: fit.residual_max,
        segments: fit.segments,
        dof: fit.dof.max(1),
        orientations: distinct.len(),
        condition: fit.condition,
        iterations: 0,
    }
}
