//! A synthetic hand-rotated record with known truth, for testing the
//! rig-free fit ([`crate::calib_fit::fits::rig_free`]): the unit rests in a random first
//! orientation, then is turned about a random body axis (by a random angle,
//! with a smooth rate profile that starts and ends at rest) and rests again,
//! pose after pose, as a person turns a board on a table. Each sample is
//! f̂ = (I+Σ)_a·f + b_a + noise and ω̂ = (I+Σ)_g·ω + b_g + G·f + noise
//! (G the gyro's g-sensitivity, when the unit has one), with f
//! the exact specific force in body axes and ω the exact body rate (no
//! Earth rate). [`generate`] allocates nothing: samples go to a callback,
//! randomness comes from the caller's uniform generator; [`recorded`]
//! keeps them, with the poses detection finds.

use alloc::vec::Vec;

use crate::calib_fit::numerics::quaternion::{self, Quat};
use crate::calib_fit::numerics::small3::Mat3;
use crate::calib_fit::poses;
use crate::calib_fit::static_segments::Segment;
use triad::model::matrix::mul_vec;

/// One triad of the simulated unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadTruth {
    /// (I+Σ).
    pub scale_misalignment: Mat3,
    /// b (SI).
    pub bias: [f64; 3],
    /// Standard deviation of the white noise of one sample (SI).
    pub noise: f64,
}

/// The simulated unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    /// The accelerometer, m/s².
    pub accel: TriadTruth,
    /// The gyroscope, rad/s.
    pub gyro: TriadTruth,
    /// |g|, m/s².
    pub gravity: f64,
    /// The gyro's g-sensitivity G, (rad/s)/(m/s²), on the body-axis specific force.
    pub g_sensitivity: Option<Mat3>,
}

/// Which body axes the turns are about.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axes {
    /// Any direction, uniform on the sphere.
    Any,
    /// Random directions in the plane perpendicular to this (unit) normal.
    Plane([f64; 3]),
    /// This one (unit) axis, either sense.
    One([f64; 3]),
}

/// What the hand does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Script {
    /// Samples per second.
    pub rate_hz: f64,
    /// Static poses (turns = poses − 1).
    pub poses: usize,
    /// Rest at each pose, s.
    pub static_s: f64,
    /// Duration of each turn, s (peak rate = 2 × angle / duration).
    pub turn_s: f64,
    /// Smallest and largest turn angle, degrees.
    pub angle_deg: (f64, f64),
    /// The turns' axes.
    pub axes: Axes,
    /// A slow turn about the vertical during one pose (pose index, rad/s),
    /// which the accelerometer cannot see: a pose that is not static.
    pub drift: Option<(usize, f64)>,
}

/// A typical hand session: 14 poses of 4 s at 100 Hz, turns of 60..150°
/// in 1.5 s (peak 200 °/s, 2° per sample) about any axis.
pub const SESSION: Script = Script {
    rate_hz: 100.0,
    poses: 14,
    static_s: 4.0,
    turn_s: 1.5,
    angle_deg: (60.0, 150.0),
    axes: Axes::Any,
    drift: None,
};

/// A consumer MEMS unit for tests and benchmarks: the accelerometer's
/// (I+Σ) upper triangular (the fit's convention, so its corrected axes are
/// the sensor's and the gyro's truth compares entry by entry), the gyro's
/// full with 2 % scale errors; noise 0.01 m/s² and 1e-3 rad/s per sample.
pub const MEMS_UNIT: Unit = Unit {
    accel: TriadTruth {
        scale_misalignment: [[1.01, 0.004, -0.003], [0.0, 0.99, 0.002], [0.0, 0.0, 1.015]],
        bias: [0.1, -0.15, 0.05],
        noise: 0.01,
    },
    gyro: TriadTruth {
        scale_misalignment: [
            [1.02, 0.006, -0.004],
            [-0.003, 0.98, 0.005],
            [0.002, -0.006, 1.01],
        ],
        bias: [0.01, -0.02, 0.015],
        noise: 1e-3,
    },
    g_sensitivity: None,
    gravity: 9.80665,
};

/// One sample of the record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Accelerometer, m/s².
    pub accel: [f64; 3],
    /// Gyroscope, rad/s.
    pub gyro: [f64; 3],
}

/// A standard normal deviate from two uniform ones (Box–Muller).
pub fn normal(uniform: &mut impl FnMut() -> f64) -> f64 {
    let u1 = uniform().max(f64::MIN_POSITIVE);
    let u2 = uniform();
    libm::sqrt(-2.0 * libm::log(u1)) * libm::cos(2.0 * core::f64::consts::PI * u2)
}

fn unit_vector(v: [f64; 3]) -> [f64; 3] {
    let n = libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v.map(|x| x / n)
}

/// A random direction uniform on the sphere.
fn random_direction(uniform: &mut impl FnMut() -> f64) -> [f64; 3] {
    unit_vector([normal(uniform), normal(uniform), normal(uniform)])
}

fn turn_axis(axes: Axes, uniform: &mut impl FnMut() -> f64) -> [f64; 3] {
    match axes {
        Axes::Any => random_direction(uniform),
        Axes::Plane(n) => {
            let v = random_direction(uniform);
            let d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
            unit_vector([v[0] - d * n[0], v[1] - d * n[1], v[2] - d * n[2]])
        }
        Axes::One(a) => {
            let sign = if uniform() < 0.5 { -1.0 } else { 1.0 };
            a.map(|x| sign * x)
        }
    }
}

fn measured(truth: &TriadTruth, v: &[f64; 3], uniform: &mut impl FnMut() -> f64) -> [f64; 3] {
    let m = mul_vec(&truth.scale_misalignment, v);
    [0, 1, 2].map(|i| m[i] + truth.bias[i] + truth.noise * normal(uniform))
}

/// Generates the record of `script` on `unit`, sample by sample into `out`.
pub fn generate(
    script: &Script,
    unit: &Unit,
    uniform: &mut impl FnMut() -> f64,
    mut out: impl FnMut(Sample),
) {
    let dt = 1.0 / script.rate_hz;
    let up = [0.0, 0.0, unit.gravity];
    // Body to world: a random first orientation.
    let first_axis = random_direction(uniform);
    let first_angle = core::f64::consts::PI * uniform();
    let mut attitude: Quat = quaternion::from_rotation_vector(&first_axis.map(|x| x * first_angle));
    let static_n = libm::round(script.static_s * script.rate_hz) as usize;
    let turn_n = libm::round(script.turn_s * script.rate_hz) as usize;
    let mut k = 0usize;
    let mut emit =
        |attitude: &Quat, w: &[f64; 3], uniform: &mut dyn FnMut() -> f64, k: &mut usize| {
            let mut u = || uniform();
            let f = quaternion::rotate_inverse(attitude, &up);
            let mut gyro = measured(&unit.gyro, w, &mut u);
            if let Some(g) = &unit.g_sensitivity {
                let gf = mul_vec(g, &f);
                gyro = [0, 1, 2].map(|i| gyro[i] + gf[i]);
            }
            out(Sample {
                t: *k as f64 * dt,
                accel: measured(&unit.accel, &f, &mut u),
                gyro,
            });
            *k += 1;
        };
    for pose in 0..script.poses {
        let drift = match script.drift {
            Some((p, rate)) if p == pose => rate,
            _ => 0.0,
        };
        for _ in 0..static_n {
            // About the vertical: body gravity, and so the accelerometer, unchanged.
            let vertical = unit_vector(quaternion::rotate_inverse(&attitude, &up));
            let w = vertical.map(|x| x * drift);
            emit(&attitude, &w, uniform, &mut k);
            attitude = quaternion::mul(
                &attitude,
                &quaternion::from_rotation_vector(&w.map(|x| x * dt)),
            );
        }
        if pose + 1 == script.poses {
            break;
        }
        let axis = turn_axis(script.axes, uniform);
        let (lo, hi) = script.angle_deg;
        let angle = (lo + (hi - lo) * uniform()).to_radians();
        let start = attitude;
        // θ(s) = Θ·(s − sin(2πs)/2π): rate Θ/T·(1 − cos 2πs), zero at both ends.
        for i in 0..turn_n {
            let s = i as f64 / turn_n as f64;
            let two_pi_s = 2.0 * core::f64::consts::PI * s;
            let theta = angle * (s - libm::sin(two_pi_s) / (2.0 * core::f64::consts::PI));
            let rate = angle / script.turn_s * (1.0 - libm::cos(two_pi_s));
            attitude = quaternion::mul(
                &start,
                &quaternion::from_rotation_vector(&axis.map(|x| x * theta)),
            );
            emit(&attitude, &axis.map(|x| x * rate), uniform, &mut k);
        }
        attitude = quaternion::mul(
            &start,
            &quaternion::from_rotation_vector(&axis.map(|x| x * angle)),
        );
    }
}

/// A generated record held in memory, with its static poses.
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    /// Times, s.
    pub t: Vec<f64>,
    /// The accelerometer's samples, m/s².
    pub accel: Vec<[f64; 3]>,
    /// The gyroscope's samples, rad/s.
    pub gyro: Vec<[f64; 3]>,
    /// The poses detection finds (0.5 s blocks, poses of at least 2 s).
    pub poses: Vec<Segment>,
}

/// [`generate`]'s record kept, with its poses found as `fit imu` finds
/// them; panics if detection fails (too many segments: not a hand script).
pub fn recorded(script: &Script, unit: &Unit, uniform: &mut impl FnMut() -> f64) -> Recorded {
    let (mut t, mut accel, mut gyro) = (Vec::new(), Vec::new(), Vec::new());
    generate(script, unit, uniform, |s| {
        t.push(s.t);
        accel.push(s.accel);
        gyro.push(s.gyro);
    });
    let detector = poses::detector(script.rate_hz, 2.0);
    let whole = 0..accel.len();
    let found = poses::detect(&detector, &accel, core::slice::from_ref(&whole))
        .expect("a hand script's poses are found");
    Recorded {
        t,
        accel,
        gyro,
        poses: found.segments,
    }
}
