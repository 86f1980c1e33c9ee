//! Deterministic sample sources for the chip-model tests, and the code a chip
//! reports for a value, computed independently of the models.
#![allow(dead_code)] // each test binary uses a different part

pub mod bus;
pub mod self_test;

use triad_sim::chips::source::{SampleSource, TrueSample};

/// The same true sample forever.
#[derive(Clone, Copy, Debug)]
pub struct ConstantSource(pub TrueSample);

impl SampleSource for ConstantSource {
    fn next_sample(&mut self) -> TrueSample {
        self.0
    }
}

/// Sample k has every component a distinct function of k, so order and loss
/// are visible: specific force (k, −k/2, 9.8 + k/1000)·0.01 m/s² per step,
/// angular rate k·1e-3 rad/s (x), −k·2e-3 (y), 0.5 rad/s (z), 20 + k/100 °C.
#[derive(Clone, Copy, Debug, Default)]
pub struct RampSource {
    /// Samples handed out so far.
    pub k: u64,
}

impl RampSource {
    /// The sample with index `k` (0-based).
    pub fn sample(k: u64) -> TrueSample {
        let k = k as f64;
        TrueSample {
            specific_force: [0.01 * k, -0.005 * k, 9.8 + 1e-5 * k],
            angular_rate: [1e-3 * k, -2e-3 * k, 0.5],
            temperature: 20.0 + 0.01 * k,
        }
    }
}

impl SampleSource for RampSource {
    fn next_sample(&mut self) -> TrueSample {
        let s = Self::sample(self.k);
        self.k += 1;
        s
    }
}

/// Reproducible random samples (xorshift64*), uniform within ±`accel_max`
/// m/s² and ±`gyro_max` rad/s, temperature in 0..50 °C.
#[derive(Clone, Copy, Debug)]
pub struct RandomSource {
    state: u64,
    accel_max: f64,
    gyro_max: f64,
}

impl RandomSource {
    /// A source seeded with `seed` (non-zero).
    pub fn new(seed: u64, accel_max: f64, gyro_max: f64) -> Self {
        Self {
            state: seed | 1,
            accel_max,
            gyro_max,
        }
    }

    /// Uniform in [-1, 1).
    fn unit(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let x = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

impl SampleSource for RandomSource {
    fn next_sample(&mut self) -> TrueSample {
        let mut s = TrueSample::default();
        for axis in 0..3 {
            s.specific_force[axis] = self.unit() * self.accel_max;
            s.angular_rate[axis] = self.unit() * self.gyro_max;
        }
        s.temperature = 25.0 + 25.0 * self.unit();
        s
    }
}

/// What a chip reports for `value` at `si_per_lsb`: rounded to the nearest
/// code and saturated at ±`limit`, computed independently of the models.
pub fn expected_code(value: f64, si_per_lsb: f64, limit: i16) -> i16 {
    let code = (value / si_per_lsb).round();
    code.clamp(-f64::from(limit), f64::from(limit)) as i16
}
