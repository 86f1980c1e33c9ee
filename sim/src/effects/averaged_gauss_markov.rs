//! A first-order Gauss–Markov process read as its mean over each sample
//! period, as an integrating sensor reads it, with exact discretisation.
//!
//! A point sample of a process whose correlation time Tc is shorter than the
//! sample period Ts aliases: the sample's variance is the whole σ², so the
//! record holds white noise of density σ·√Ts, where the process's own white
//! tail (its Allan variance for τ ≫ Tc, 2σ²Tc/τ) is far smaller. The mean
//! over the period does not alias: the Allan variance of a record of such
//! means at τ = m·Ts is exactly the continuous-time one
//! ([`super::gauss_markov::allan_variance`]) at every m ≥ 1.
//!
//! Over one step h = Ts from the state x (α = 1/Tc, a = αh, φ = e^(−a)),
//! the end state x' and the mean A = (1/h)∫x dt are jointly Gaussian
//! (Gillespie, "Exact numerical simulation of the Ornstein–Uhlenbeck process
//! and its integral", Phys. Rev. E 54, 1996):
//!
//!   mean of x' = φx,           variance of x' = σ²(1 − φ²),
//!   mean of A  = x(1 − φ)/a,   variance of A  = σ²(2a − 3 + 4φ − φ²)/a²,
//!   covariance of x' and A = σ²(1 − φ)²/a,
//!
//! drawn from two normal deviates (a 2×2 Cholesky factor). Each factor is
//! computed without cancellation for small a (expm1, and the series of the
//! bracket below a = 1e-3, as in `allan_variance`).

use super::gauss_markov::discretisation;
use super::rng::Rng;

/// The bracket 2a − 3 + 4e^(−a) − e^(−2a), without cancellation for small a.
fn bracket(a: f64) -> f64 {
    if a < 1e-3 {
        // (2/3)a³ − (1/2)a⁴ + (7/30)a⁵ − ...
        a * a * a * (2.0 / 3.0 - 0.5 * a + (7.0 / 30.0) * a * a)
    } else {
        2.0 * a - 3.0 + 4.0 * libm::exp(-a) - libm::exp(-2.0 * a)
    }
}

/// One averaged Gauss–Markov process: its discretisation and state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AveragedGaussMarkov {
    /// φ − 1.
    phi_minus_one: f64,
    /// (1 − φ)/a: the part of the state the mean keeps.
    mean_gain: f64,
    /// Cholesky factor of the step's covariance: x' noise = l11·g1,
    /// A noise = l21·g1 + l22·g2.
    l11: f64,
    l21: f64,
    l22: f64,
    state: f64,
}

impl AveragedGaussMarkov {
    /// A process of zero variance: every mean is 0 (a slot not in use).
    pub const IDLE: Self = Self {
        phi_minus_one: 0.0,
        mean_gain: 0.0,
        l11: 0.0,
        l21: 0.0,
        l22: 0.0,
        state: 0.0,
    };

    /// A process of stationary standard deviation `sigma` and correlation
    /// time `correlation_time` (s), averaged over periods of `ts` s,
    /// starting stationary (its state drawn from `rng`).
    pub fn new_stationary(sigma: f64, correlation_time: f64, ts: f64, rng: &mut Rng) -> Self {
        let a = ts / correlation_time;
        let (phi_minus_one, one_minus_phi2) = discretisation(a);
        let one_minus_phi = -phi_minus_one;
        let var_end = sigma * sigma * one_minus_phi2;
        let cov = sigma * sigma * one_minus_phi * one_minus_phi / a;
        let var_mean = sigma * sigma * bracket(a) / (a * a);
        let l11 = libm::sqrt(var_end);
        let l21 = if l11 > 0.0 { cov / l11 } else { 0.0 };
        // Non-negative in exact arithmetic (a covariance); rounding can dip below.
        let l22 = libm::sqrt((var_mean - l21 * l21).max(0.0));
        Self {
            phi_minus_one,
            mean_gain: one_minus_phi / a,
            l11,
            l21,
            l22,
            state: sigma * rng.gaussian(),
        }
    }

    /// The mean over the next period; the state moves to the period's end.
    pub fn step(&mut self, rng: &mut Rng) -> f64 {
        let (g1, g2) = (rng.gaussian(), rng.gaussian());
        let mean = self.state * self.mean_gain + self.l21 * g1 + self.l22 * g2;
        self.state += self.phi_minus_one * self.state + self.l11 * g1;
        mean
    }

    /// The state at the end of the last period.
    pub fn state(&self) -> f64 {
        self.state
    }
}
