//! The gyroscope at rest in several orientations (`triad calib fit gyro
//! --static` on a record of static poses with turns between them): its
//! bias, and its g-sensitivity G where the poses' gravity directions
//! support one ([`g_sensitivity`]: at least three independent directions
//! and one opposite), with σ's and degrees of freedom as `fit imu` gives
//! them; else G is reported as not supported and the bias is the mean of
//! the poses' means.
//!
//! The specific force of each pose is its accelerometer mean corrected by
//! the accelerometer calibration the caller gives (the one the file will
//! carry with G, so that the corrector's f is the fit's). With a latitude
//! the vertical Earth rate is removed from each pose's mean along that
//! pose's own vertical: it turns with the pose, and left in it would look
//! like a G of Ω·sin φ per g.

use alloc::vec::Vec;

use crate::calib_fit::fits::g_sensitivity::{self, AtRest, PoseMean, PoseNotStatic};
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::static_segments::{self, Segment};
use triad::model::matrix;

/// How a pose's means are turned into the fit's inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The accelerometer's (I+Σ)⁻¹.
    pub accel_inverse: Mat3,
    /// The accelerometer's b, m/s².
    pub accel_bias: [f64; 3],
    /// The vertical Earth rate Ω·sin φ (rad/s) and the gyro's (I+Σ) through
    /// which the gyro sees it, when a latitude is given.
    pub earth: Option<(f64, Mat3)>,
}

/// Fits the gyro at rest to the static `poses` (sample ranges of `t`,
/// `gyro` and `accel`, two samples or more each), in the `frame`. A pose
/// whose mean is not what the others predict is refused with its times:
/// that is the only refusal of this fit, so it is its error.
pub fn fit(
    t: &[f64],
    gyro: &[[f64; 3]],
    accel: &[[f64; 3]],
    poses: &[Segment],
    frame: &Frame,
) -> Result<AtRest, PoseNotStatic> {
    let means: Vec<PoseMean> = poses
        .iter()
        .map(|s| pose_mean(&gyro[s.start..s.end], &accel[s.start..s.end], frame))
        .collect();
    g_sensitivity::at_rest(means.len(), |q| means[q])
        .map_err(|stray| PoseNotStatic::new(&stray, poses, t))
}

/// The corrected specific force of a pose: its accelerometer mean through
/// the `frame`'s calibration, m/s².
pub fn specific_force(accel: &[[f64; 3]], frame: &Frame) -> [f64; 3] {
    let a = static_segments::mean(accel);
    matrix::mul_vec(
        &frame.accel_inverse,
        &[0, 1, 2].map(|i| a[i] - frame.accel_bias[i]),
    )
}

fn pose_mean(gyro: &[[f64; 3]], accel: &[[f64; 3]], frame: &Frame) -> PoseMean {
    let n = libm::sqrt(gyro.len() as f64);
    let standard_error = static_segments::standard_deviation(gyro).map(|s| s / n);
    let force = specific_force(accel, frame);
    let mut mean = static_segments::mean(gyro);
    if let Some((vertical, scale)) = &frame.earth {
        let norm = libm::sqrt(force.iter().map(|x| x * x).sum::<f64>());
        if norm > 0.0 {
            let seen = matrix::mul_vec(scale, &force.map(|x| vertical * x / norm));
            for (m, x) in mean.iter_mut().zip(seen) {
                *m -= x;
            }
        }
    }
    PoseMean {
        gyro: mean,
        standard_error,
        force,
    }
}
