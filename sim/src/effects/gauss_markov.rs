//! First-order Gauss–Markov process with exact discretisation.
//!
//! dμ = −α μ dt + q dw with stationary variance σ² (α = 1/T_c). Over one step
//! Ts the exact solution is μ_{k+1} = φ μ_k + w_k with φ = e^(−αTs) and
//! Var(w_k) = σ²(1 − φ²) (Gelb, "Applied Optimal Estimation", §3.8; Maybeck,
//! vol. 1 §4.9). Both 1 − φ and 1 − φ² cancel catastrophically for small αTs
//! (at αTs = 1e-12, 1 − e^(−αTs) keeps only 4 significant digits), so they are
//! computed with expm1 and the update is written μ += (φ − 1)·μ + w.
//! For large αTs (up to 1e3 and beyond) φ underflows cleanly to 0 and the
//! process becomes white with variance σ².

use super::rng::Rng;

/// The discretisation of one Gauss–Markov process and its current state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussMarkov {
    /// φ − 1 = expm1(−αTs).
    phi_minus_one: f64,
    /// √Var(w) = σ·√(−expm1(−2αTs)).
    drive_sd: f64,
    state: f64,
}

/// The exact discretisation coefficients (φ − 1, 1 − φ²) for αTs = `alpha_ts`,
/// both computed without cancellation.
pub fn discretisation(alpha_ts: f64) -> (f64, f64) {
    (libm::expm1(-alpha_ts), -libm::expm1(-2.0 * alpha_ts))
}

/// The Allan variance at averaging time τ of a Gauss–Markov process of
/// variance `variance` and correlation time `tc` (rate-like process):
/// σ²_A(τ) = (q·Tc²/τ²)·(2τ/Tc − 3 + 4e^(−τ/Tc) − e^(−2τ/Tc)).
/// Limits: 2qτ/(3Tc) for τ ≪ Tc (a rate random walk) and 2qTc/τ for
/// τ ≫ Tc (white noise of density √(2qTc)). The bracket cancels for small
/// τ/Tc, so below 1e-3 the series (2/3)x³ − (1/2)x⁴ + ... is used.
pub fn allan_variance(variance: f64, tc: f64, tau: f64) -> f64 {
    let x = tau / tc;
    let bracket = if x < 1e-3 {
        // 2x − 3 + 4e^(−x) − e^(−2x) = (2/3)x³ − (1/2)x⁴ + (7/30)x⁵ − ...
        x * x * x * (2.0 / 3.0 - 0.5 * x + (7.0 / 30.0) * x * x)
    } else {
        2.0 * x - 3.0 + 4.0 * libm::exp(-x) - libm::exp(-2.0 * x)
    };
    variance * bracket / (x * x)
}

impl GaussMarkov {
    /// A process of stationary standard deviation `sigma` and correlation time
    /// `correlation_time` (seconds) sampled every `ts` seconds, starting at `initial`.
    pub fn new(sigma: f64, correlation_time: f64, ts: f64, initial: f64) -> Self {
        let (phi_minus_one, one_minus_phi2) = discretisation(ts / correlation_time);
        Self {
            phi_minus_one,
            drive_sd: sigma * libm::sqrt(one_minus_phi2),
            state: initial,
        }
    }

    /// A process that starts stationary: its first state is drawn from N(0, σ²).
    pub fn new_stationary(sigma: f64, correlation_time: f64, ts: f64, rng: &mut Rng) -> Self {
        let initial = sigma * rng.gaussian();
        Self::new(sigma, correlation_time, ts, initial)
    }

    /// The current state.
    pub fn state(&self) -> f64 {
        self.state
    }

    /// φ − 1 of the discretisation.
    pub fn phi_minus_one(&self) -> f64 {
        self.phi_minus_one
    }

    /// Standard deviation of the driving noise per step.
    pub fn drive_sd(&self) -> f64 {
        self.drive_sd
    }

    /// Advances one step and returns the new state.
    pub fn step(&mut self, rng: &mut Rng) -> f64 {
        let w = self.drive_sd * rng.gaussian();
        self.state += self.phi_minus_one * self.state + w;
        self.state
    }
}
