//! Random walk of a bias: rate random walk for gyros, acceleration random walk
//! for accelerometers (IEEE Std 952 Annex C, coefficient K).
//!
//! The bias integrates white noise of density K (units/√s): over one step Ts
//! it moves by N(0, K²·Ts), so Var(b(t)) = K²·t from b(0) = 0.

use super::rng::Rng;

/// A random walk starting at zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RandomWalk {
    step_sd: f64,
    state: f64,
}

impl RandomWalk {
    /// A walk of coefficient `k` (units/√s) sampled every `ts` seconds.
    pub fn new(k: f64, ts: f64) -> Self {
        Self {
            step_sd: k * libm::sqrt(ts),
            state: 0.0,
        }
    }

    /// The current value.
    pub fn state(&self) -> f64 {
        self.state
    }

    /// Advances one step and returns the new value.
    pub fn step(&mut self, rng: &mut Rng) -> f64 {
        self.state += self.step_sd * rng.gaussian();
        self.state
    }
}
