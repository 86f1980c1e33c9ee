//! What the gyro fits that integrate turns between poses ([`rig_free`],
//! [`thermal_gyro`]) both refuse: a record near the gyro's range, a turn too
//! fast for the sample rate, too few turns. Each fit's own error wraps them.
//!
//! [`rig_free`]: crate::calib_fit::fits::rig_free
//! [`thermal_gyro`]: crate::calib_fit::fits::thermal_gyro

use core::fmt;

use crate::calib_fit::fits::rig_free::MIN_TURN_DEG;

/// The gyro's range: the full scale given, or a sample near it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RangeError {
    /// The gyro's full scale given is not a positive finite rate.
    InvalidFullScale {
        /// The value, rad/s.
        value: f64,
    },
    /// A gyro sample is near the gyro's range: the turn may have clipped.
    GyroNearRange {
        /// The sample (0-based).
        sample: usize,
        /// Its largest |axis|, rad/s.
        rate: f64,
        /// The gyro's full scale, rad/s.
        full_scale: f64,
        /// The accepted fraction of the full scale.
        fraction: f64,
    },
}

/// The record turns too far between two samples for the integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooFastForRate {
    /// The sample (0-based) where the turn is fastest.
    pub sample: usize,
    /// The rotation between it and the next sample, degrees.
    pub rotation_deg: f64,
    /// The largest accepted, degrees.
    pub limit_deg: f64,
    /// The record's sample rate, Hz.
    pub rate_hz: f64,
}

/// Fewer turns between consecutive poses than the gyro fit needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooFewRotations {
    /// Consecutive pose pairs (poses − 1).
    pub rotations: usize,
    /// Those that turn by at least the smallest counted angle.
    pub turns: usize,
    /// The minimum.
    pub needed: usize,
}

impl fmt::Display for RangeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            RangeError::InvalidFullScale { value } => {
                write!(f, "gyro full scale {value} rad/s: must be a positive finite rate")
            }
            RangeError::GyroNearRange {
                sample,
                rate,
                full_scale,
                fraction,
            } => write!(
                f,
                "sample {}: the gyro reads {:.1} °/s, beyond {:.0} % of its full scale {:.0} °/s, so the turn may \
                 have clipped: turn more slowly (or set a wider gyro range)",
                sample + 1,
                rate.to_degrees(),
                100.0 * fraction,
                full_scale.to_degrees()
            ),
        }
    }
}

impl fmt::Display for TooFastForRate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "sample {}: the unit turns {:.2}° between two samples (limit {}° at \
             {:.1} Hz, i.e. {:.0} °/s): turn more slowly or record at a higher rate",
            self.sample + 1,
            self.rotation_deg,
            self.limit_deg,
            self.rate_hz,
            self.limit_deg * self.rate_hz
        )
    }
}

impl fmt::Display for TooFewRotations {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of the {} moves between consecutive poses turn by ≥ {MIN_TURN_DEG} degrees; the gyro fit \
             (9 entries of I+Σ, 2 equations per turn: the gravity direction at the next pose) needs at least \
             {}: add poses, turning the unit between each",
            self.turns, self.rotations, self.needed
        )
    }
}
