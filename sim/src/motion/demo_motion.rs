//! The emulated board's documented test motion: a sensor resting at a known
//! tilt on a table turning slowly about the vertical, with a small vibration.
//! Deterministic (a function of the sample index only) so a host test can
//! regenerate exactly what the firmware's chip model served.
//!
//! In the sensor frame, with roll φ and pitch θ (z-y-x Euler angles) and the
//! world z axis up:
//!
//! - specific force f = g·(−sin θ, sin φ cos θ, cos φ cos θ) + a·sin(2π f_v t)·x̂
//! - angular rate ω = Ω·(−sin θ, sin φ cos θ, cos φ cos θ) (the table's vertical
//!   rotation seen in the tilted sensor frame)
//! - temperature T(t) = T₀ + ramp·t

use crate::chips::source::{SampleSource, TrueSample};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

/// Parameters of the demo motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemoMotion {
    /// Roll φ, radians.
    pub roll: f64,
    /// Pitch θ, radians.
    pub pitch: f64,
    /// Table rate Ω about the world vertical, rad/s.
    pub table_rate: f64,
    /// Vibration amplitude along sensor x, m/s².
    pub vibration_amplitude: f64,
    /// Vibration frequency, Hz.
    pub vibration_hz: f64,
    /// Temperature at t = 0, °C.
    pub temperature_start: f64,
    /// Temperature slope, °C/s.
    pub temperature_ramp: f64,
    /// Sample rate, Hz.
    pub sample_rate: f64,
}

impl DemoMotion {
    /// The motion the emulated board streams: roll 30°, pitch 15°, table at
    /// 10 °/s, 0.5 m/s² of 5 Hz vibration, 25 °C rising 0.01 °C/s, at `sample_rate` Hz.
    pub fn standard(sample_rate: f64) -> Self {
        Self {
            roll: deg_to_rad(30.0),
            pitch: deg_to_rad(15.0),
            table_rate: deg_to_rad(10.0),
            vibration_amplitude: 0.5,
            vibration_hz: 5.0,
            temperature_start: 25.0,
            temperature_ramp: 0.01,
            sample_rate,
        }
    }

    /// The true sample at index `n` (time n / sample_rate).
    pub fn at(&self, n: u64) -> TrueSample {
        DemoTerms::of(self).at(n)
    }
}

/// What of the demo motion is constant, computed once: the vertical in the
/// sensor frame and the vibration's angular frequency. Sampling then costs
/// one sine and a few products, the very operations [`DemoMotion::at`]
/// would do, so the samples are the same bits (the end-to-end tests
/// recompute them): on the emulated board's Cortex-M4F, whose FPU has no
/// `f64`, the five software sines and cosines per sample were most of the
/// chip model's ~28 k instructions per sample.
#[derive(Clone, Copy, Debug, PartialEq)]
struct DemoTerms {
    motion: DemoMotion,
    /// The world vertical expressed in the sensor frame.
    up: [f64; 3],
    /// 2π·f_v, rad/s.
    vibration_rad_s: f64,
}

impl DemoTerms {
    fn of(motion: &DemoMotion) -> Self {
        let (sin_roll, cos_roll) = (libm::sin(motion.roll), libm::cos(motion.roll));
        let (sin_pitch, cos_pitch) = (libm::sin(motion.pitch), libm::cos(motion.pitch));
        Self {
            motion: *motion,
            up: [-sin_pitch, sin_roll * cos_pitch, cos_roll * cos_pitch],
            vibration_rad_s: 2.0 * core::f64::consts::PI * motion.vibration_hz,
        }
    }

    fn at(&self, n: u64) -> TrueSample {
        let m = &self.motion;
        let up = self.up;
        let t = n as f64 / m.sample_rate;
        let vibration = m.vibration_amplitude * libm::sin(self.vibration_rad_s * t);
        TrueSample {
            specific_force: [
                STANDARD_GRAVITY * up[0] + vibration,
                STANDARD_GRAVITY * up[1],
                STANDARD_GRAVITY * up[2],
            ],
            angular_rate: [
                m.table_rate * up[0],
                m.table_rate * up[1],
                m.table_rate * up[2],
            ],
            temperature: m.temperature_start + m.temperature_ramp * t,
        }
    }
}

/// [`DemoMotion`] as a [`SampleSource`]: serves samples 0, 1, 2, ...
#[derive(Clone, Debug)]
pub struct DemoSource {
    terms: DemoTerms,
    next: u64,
}

impl DemoSource {
    /// A source starting at sample 0.
    pub fn new(motion: DemoMotion) -> Self {
        Self {
            terms: DemoTerms::of(&motion),
            next: 0,
        }
    }
}

impl SampleSource for DemoSource {
    fn next_sample(&mut self) -> TrueSample {
        let sample = self.terms.at(self.next);
        self.next += 1;
        sample
    }
}
