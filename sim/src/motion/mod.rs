//! True motion: what an ideal triad measures in each of the scene kinds.
//!
//! The level frame is x east, y north, z up. A sensor at rest measures the
//! specific force f = (0, 0, g) (the reaction to gravity) and, when the Earth
//! rate is on, ω_ie = Ω·(0, cos φ, sin φ) at latitude φ. R maps body to level;
//! body quantities are Rᵀ·(level quantities) plus the motion's own terms.

pub mod demo_motion;
pub mod hand_poses;
pub mod rotation;

use crate::motion::hand_poses::hand_poses;
use crate::motion::rotation::Mat3;
use triad::units::{EARTH_RATE, STANDARD_GRAVITY};

/// A signed body axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub enum Axis {
    /// +x.
    PlusX,
    /// −x.
    MinusX,
    /// +y.
    PlusY,
    /// −y.
    MinusY,
    /// +z.
    PlusZ,
    /// −z.
    MinusZ,
}

impl Axis {
    /// (index 0..3, sign ±1).
    pub fn index_sign(self) -> (usize, f64) {
        match self {
            Axis::PlusX => (0, 1.0),
            Axis::MinusX => (0, -1.0),
            Axis::PlusY => (1, 1.0),
            Axis::MinusY => (1, -1.0),
            Axis::PlusZ => (2, 1.0),
            Axis::MinusZ => (2, -1.0),
        }
    }
}

/// Where the scene happens.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct Environment {
    /// Magnitude of gravity, m/s² (9.80665 standard, or a local value).
    pub gravity: f64,
    /// Latitude in radians when the Earth rate is on; `None` leaves it out.
    pub latitude: Option<f64>,
}

impl Default for Environment {
    fn default() -> Self {
        Self {
            gravity: STANDARD_GRAVITY,
            latitude: None,
        }
    }
}

/// The motion of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub enum Motion {
    /// At rest at a fixed attitude (z-y-x Euler angles roll, pitch, yaw; radians).
    Static {
        /// [roll, pitch, yaw], radians.
        attitude: [f64; 3],
    },
    /// On a rate table turning about the vertical at a constant rate, with the
    /// body `axis` along the table axis (pointing up).
    RateTable {
        /// The body axis along the table axis.
        axis: Axis,
        /// Table rate, rad/s (positive counter-clockwise seen from above).
        rate: f64,
    },
    /// Multi-position tumble: each face of the cube up in turn (6), then
    /// again at 180° of heading (12), then at 90° and 270° (24); at rest for
    /// `dwell` seconds at each position, turning at constant rate for
    /// `transition` seconds between them; the cycle repeats.
    Tumble {
        /// 6, 12 or 24.
        positions: u8,
        /// Rest at each position, seconds.
        dwell: f64,
        /// Turn between positions, seconds.
        transition: f64,
    },
    /// At rest at a fixed attitude, shaken sinusoidally along a body direction.
    Vibration {
        /// [roll, pitch, yaw], radians.
        attitude: [f64; 3],
        /// Direction of the shake in the body frame (normalised on use).
        direction: [f64; 3],
        /// Acceleration amplitude, m/s².
        amplitude: f64,
        /// Frequency, Hz.
        frequency: f64,
    },
    /// A board turned by hand between `poses` static poses in random
    /// orientations drawn from `seed` ([`mod@crate::motion::hand_poses`]): at rest for
    /// `dwell` seconds at each, then turned to the next about the axis of
    /// the rotation between them in `turn` seconds, the rate rising and
    /// falling smoothly (ω ∝ 1 − cos 2πu, zero at both ends); the last pose
    /// turns back to the first and the cycle repeats.
    Hand {
        /// 12 ..= 24.
        poses: u8,
        /// The seed of the poses.
        seed: u64,
        /// Rest at each pose, seconds.
        dwell: f64,
        /// Turn between poses, seconds.
        turn: f64,
    },
    /// A rate-table set: the body axes +x, −x, +y, −y, +z, −z up on the
    /// table in turn, each at rest for `rest` seconds (remounted, table
    /// still) and then turning at `rate` for `run` seconds; the six runs
    /// repeat. Run k (0..6) turns from (rest + run)·k + rest seconds on.
    RateTableSet {
        /// Table rate, rad/s (positive counter-clockwise seen from above).
        rate: f64,
        /// Each run's turning time, seconds.
        run: f64,
        /// The rest before each run, seconds.
        rest: f64,
    },
}

/// The axes a [`Motion::RateTableSet`] puts up, in order.
pub const RATE_TABLE_SET_AXES: [Axis; 6] = [
    Axis::PlusX,
    Axis::MinusX,
    Axis::PlusY,
    Axis::MinusY,
    Axis::PlusZ,
    Axis::MinusZ,
];

/// Specific force and angular rate in the body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics {
    /// Specific force, m/s².
    pub specific_force: [f64; 3],
    /// Angular rate, rad/s.
    pub angular_rate: [f64; 3],
}

/// The most tumble positions.
pub const MAX_POSITIONS: usize = 24;

/// The body-to-level rotation of tumble position `i`: the faces +z, −z, +x,
/// −x, +y, −y up in turn, at headings 0°, 180°, 90°, 270° for i / 6 = 0..3.
pub fn tumble_position(i: usize) -> Mat3 {
    const FACES: [(usize, f64); 6] = [
        (2, 1.0),
        (2, -1.0),
        (0, 1.0),
        (0, -1.0),
        (1, 1.0),
        (1, -1.0),
    ];
    const HEADINGS: [[f64; 3]; 4] = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let (a, s) = FACES[i % 6];
    let h = HEADINGS[(i / 6) % 4];
    face_up(a, s, h)
}

/// The rotation that puts body axis `a` (sign `s`) up and the next body axis
/// (cyclically) along the horizontal unit vector `h`.
fn face_up(a: usize, s: f64, h: [f64; 3]) -> Mat3 {
    let up = [0.0, 0.0, s];
    let third = [
        up[1] * h[2] - up[2] * h[1],
        up[2] * h[0] - up[0] * h[2],
        up[0] * h[1] - up[1] * h[0],
    ];
    // Columns of R are the body axes in level coordinates.
    let mut r = [[0.0; 3]; 3];
    let cols = [(a, up), ((a + 1) % 3, h), ((a + 2) % 3, third)];
    for (col, v) in cols {
        for row in 0..3 {
            r[row][col] = v[row];
        }
    }
    r
}

/// A motion prepared for evaluation: constant parts and tumble tables are
/// computed once.
#[derive(Clone, Copy, Debug)]
pub struct Trajectory {
    motion: Motion,
    /// Specific force at rest in level coordinates.
    f_level: [f64; 3],
    /// Earth rate in level coordinates.
    w_level: [f64; 3],
    /// Static and vibration: the constant body kinematics; rate table: mount.
    at_rest: Kinematics,
    mount: Mat3,
    /// Tumble: each position's rotation and the body axis/angle of the turn to the next.
    positions: [Mat3; MAX_POSITIONS],
    turns: [([f64; 3], f64); MAX_POSITIONS],
    direction: [f64; 3],
}

impl Trajectory {
    /// Prepares `motion` in `environment`.
    pub fn new(motion: &Motion, environment: &Environment) -> Self {
        let f_level = [0.0, 0.0, environment.gravity];
        let w_level = match environment.latitude {
            Some(lat) => [
                0.0,
                EARTH_RATE * libm::cos(lat),
                EARTH_RATE * libm::sin(lat),
            ],
            None => [0.0; 3],
        };
        let mut t = Self {
            motion: *motion,
            f_level,
            w_level,
            at_rest: Kinematics::default(),
            mount: rotation::IDENTITY,
            positions: [rotation::IDENTITY; MAX_POSITIONS],
            turns: [([0.0, 0.0, 1.0], 0.0); MAX_POSITIONS],
            direction: [0.0; 3],
        };
        match *motion {
            Motion::Static { attitude } | Motion::Vibration { attitude, .. } => {
                let r = rotation::from_euler(attitude[0], attitude[1], attitude[2]);
                t.at_rest = t.body(&r);
                if let Motion::Vibration { direction, .. } = *motion {
                    t.direction = rotation::normalise(direction);
                }
            }
            Motion::RateTable { axis, .. } => {
                let (a, s) = axis.index_sign();
                t.mount = face_up(a, s, [1.0, 0.0, 0.0]);
            }
            Motion::Tumble { positions, .. } => {
                let n = (positions as usize).clamp(1, MAX_POSITIONS);
                for i in 0..n {
                    t.positions[i] = tumble_position(i);
                }
                t.prepare_turns(n);
            }
            Motion::Hand { poses, seed, .. } => {
                let n = (poses as usize).clamp(1, MAX_POSITIONS);
                t.positions = hand_poses(seed, n);
                t.prepare_turns(n);
            }
            Motion::RateTableSet { .. } => {
                for (i, axis) in RATE_TABLE_SET_AXES.iter().enumerate() {
                    let (a, s) = axis.index_sign();
                    t.positions[i] = face_up(a, s, [1.0, 0.0, 0.0]);
                }
            }
        }
        t
    }

    /// The axis and angle of the turn from each of the first `n` positions
    /// to the next (the last to the first).
    fn prepare_turns(&mut self, n: usize) {
        for i in 0..n {
            let relative =
                rotation::transpose_mul(&self.positions[i], &self.positions[(i + 1) % n]);
            self.turns[i] = rotation::log(&relative);
        }
    }

    /// Positions with turns between them (tumble, hand): at rest for
    /// `dwell`, then turning for `turn` seconds, the turned fraction of the
    /// angle and its rate (per second, as a fraction of the angle) given by
    /// `profile(u)` at u = elapsed / turn.
    fn legs(
        &self,
        t: f64,
        n: u8,
        dwell: f64,
        turn: f64,
        profile: fn(f64) -> (f64, f64),
    ) -> Kinematics {
        let n = (n as usize).clamp(1, MAX_POSITIONS);
        let leg = dwell + turn;
        let cycle = leg * n as f64;
        let tc = t - cycle * libm::floor(t / cycle);
        let i = ((tc / leg) as usize).min(n - 1);
        let s = tc - leg * i as f64;
        if s < dwell || turn <= 0.0 {
            return self.body(&self.positions[i]);
        }
        let (axis, angle) = self.turns[i];
        let u = ((s - dwell) / turn).clamp(0.0, 1.0);
        let (fraction, rate) = profile(u);
        let r = rotation::mul(&self.positions[i], &rotation::exp(&axis, fraction * angle));
        let mut k = self.body(&r);
        let rate = rate * angle / turn;
        for (w, a) in k.angular_rate.iter_mut().zip(axis) {
            *w += rate * a;
        }
        k
    }

    /// Body kinematics of a sensor at rest at attitude `r`.
    fn body(&self, r: &Mat3) -> Kinematics {
        Kinematics {
            specific_force: rotation::mul_transpose_vec(r, &self.f_level),
            angular_rate: rotation::mul_transpose_vec(r, &self.w_level),
        }
    }

    /// The true kinematics at time `t` (seconds).
    pub fn at(&self, t: f64) -> Kinematics {
        match self.motion {
            Motion::Static { .. } => self.at_rest,
            Motion::Vibration {
                amplitude,
                frequency,
                ..
            } => {
                let a = amplitude * libm::sin(2.0 * core::f64::consts::PI * frequency * t);
                let mut k = self.at_rest;
                for (f, d) in k.specific_force.iter_mut().zip(self.direction) {
                    *f += a * d;
                }
                k
            }
            Motion::RateTable { axis, rate } => {
                let r = rotation::mul(&rotation::rot_z(rate * t), &self.mount);
                let mut k = self.body(&r);
                let (a, s) = axis.index_sign();
                k.angular_rate[a] += s * rate;
                k
            }
            Motion::Tumble {
                positions,
                dwell,
                transition,
            } => self.legs(t, positions, dwell, transition, constant_rate),
            Motion::Hand {
                poses, dwell, turn, ..
            } => self.legs(t, poses, dwell, turn, smooth_rate),
            Motion::RateTableSet { rate, run, rest } => {
                let leg = rest + run;
                let cycle = 6.0 * leg;
                let tc = t - cycle * libm::floor(t / cycle);
                let i = ((tc / leg) as usize).min(5);
                let s = tc - leg * i as f64;
                if s < rest {
                    return self.body(&self.positions[i]);
                }
                let r = rotation::mul(&rotation::rot_z(rate * (s - rest)), &self.positions[i]);
                let mut k = self.body(&r);
                {
                    let (a, s) = RATE_TABLE_SET_AXES[i].index_sign();
                    k.angular_rate[a] += s * rate;
                }
                k
            }
        }
    }
}

/// A turn at constant rate: fraction u, rate 1.
fn constant_rate(u: f64) -> (f64, f64) {
    (u, 1.0)
}

/// A turn whose rate rises and falls smoothly, 1 − cos 2πu (zero rate and
/// zero angular acceleration at both ends): fraction u − sin(2πu)/2π.
fn smooth_rate(u: f64) -> (f64, f64) {
    let a = 2.0 * core::f64::consts::PI * u;
    (
        u - libm::sin(a) / (2.0 * core::f64::consts::PI),
        1.0 - libm::cos(a),
    )
}
