//! Band-limited sampled white noise.
//!
//! A white-noise density N (units/√Hz, the coefficient of the two-sided PSD,
//! IEEE Std 952 Annex C) sampled at period Ts has per-sample standard deviation
//! σ_d = N/√Ts: the sampled sequence holds the power N²·(1/Ts) of the band
//! ±1/(2Ts). Integrated, it gives the random walk σ(t) = N·√t.

use super::rng::Rng;

/// White noise of a given density at a given sample period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhiteNoise {
    sigma_d: f64,
}

impl WhiteNoise {
    /// Noise of density `density` (units/√Hz) sampled every `ts` seconds.
    pub fn new(density: f64, ts: f64) -> Self {
        Self {
            sigma_d: density / libm::sqrt(ts),
        }
    }

    /// The per-sample standard deviation σ_d = N/√Ts.
    pub fn sigma_d(&self) -> f64 {
        self.sigma_d
    }

    /// One sample.
    pub fn sample(&self, rng: &mut Rng) -> f64 {
        self.sigma_d * rng.gaussian()
    }
}
