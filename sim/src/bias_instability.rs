//! Bias instability (the flicker floor of the Allan deviation) as a sum of
//! first-order Gauss–Markov terms spread over decades.
//!
//! Flicker noise has the two-sided PSD S(f) = (B²/2π)/f and a flat Allan
//! deviation σ_A = √(2 ln 2/π)·B ≈ 0.664·B (IEEE Std 952 Annex C.3). A sum of
//! Lorentzians (Gauss–Markov terms) whose correlation times are spaced evenly
//! in log τ with equal variances approximates 1/f between the extreme corner
//! frequencies (Keshner, "1/f noise", Proc. IEEE 70(3), 1982). Each term's
//! Allan deviation peaks at τ ≈ 1.89·T_c; the peaks are spread evenly in log τ
//! over the band extended by one decade on each side (without that margin
//! the floor droops by 15–20 % at the band's ends, where only half the terms
//! reach), and the common variance is set so that the geometric mean of the
//! analytic Allan deviation over the band equals the floor 0.664·B. The
//! number of terms is the accuracy knob: 1–3 terms give a hump, not a floor;
//! from about one term per decade the floor is flat to about ±1 % (measured
//! by the `bench_sim` example and bounded in sim/tests/bias_instability.rs),
//! at a cost per sample proportional to the number of terms.

use super::gauss_markov::{allan_variance, GaussMarkov};
use super::rng::Rng;

/// The most terms one axis can hold (fixed capacity: no allocation).
pub const MAX_TERMS: usize = 16;

/// Decades added on each side of the band over which the terms are spread.
pub const MARGIN_DECADES: f64 = 1.0;

/// Points of the log grid on which the floor is normalised and its flatness measured.
pub const GRID_POINTS: usize = 41;

/// √(2 ln 2/π): the Allan deviation of flicker noise per unit B.
pub const FLICKER_FLOOR_FACTOR: f64 = 0.664_282_470_267_960_1;

/// Averaging time at which a Gauss–Markov term's Allan deviation peaks, per
/// unit correlation time: the root of d/dτ of [`allan_variance`], found
/// numerically (τ/Tc = 1.8926, where σ_A = 0.6174·σ).
pub const PEAK_TAU_PER_TC: f64 = 1.8926;

/// Where the flat floor should lie and how many terms build it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct BiasInstabilityParams {
    /// The bias-instability coefficient B (SI units of the triad); the Allan
    /// floor is 0.664·B.
    pub b: f64,
    /// Shortest averaging time of the flat band, seconds.
    pub tau_min: f64,
    /// Longest averaging time of the flat band, seconds.
    pub tau_max: f64,
    /// Number of Gauss–Markov terms, 1..=[`MAX_TERMS`].
    pub terms: u8,
}

impl BiasInstabilityParams {
    /// B with the default band (1 s to 10⁴ s) and one term per decade of the
    /// band plus its margins (7 terms: flat to about ±1.5 %).
    pub const fn with_default_band(b: f64) -> Self {
        Self {
            b,
            tau_min: 1.0,
            tau_max: 1e4,
            terms: 7,
        }
    }

    /// Correlation time of term `k` (Allan peaks log-spaced over the band
    /// extended by [`MARGIN_DECADES`] on each side).
    pub fn correlation_time(&self, k: usize) -> f64 {
        let n = self.terms.max(1) as usize;
        let tau = if n == 1 {
            libm::sqrt(self.tau_min * self.tau_max)
        } else {
            let lo = libm::log10(self.tau_min) - MARGIN_DECADES;
            let hi = libm::log10(self.tau_max) + MARGIN_DECADES;
            libm::pow(10.0, lo + (hi - lo) * (k as f64 / (n - 1) as f64))
        };
        tau / PEAK_TAU_PER_TC
    }

    /// The Allan deviation of the sum of unit-variance terms at τ.
    fn unit_allan_deviation(&self, tau: f64) -> f64 {
        let mut avar = 0.0;
        for k in 0..self.terms as usize {
            avar += allan_variance(1.0, self.correlation_time(k), tau);
        }
        libm::sqrt(avar)
    }

    /// The averaging time of point `i` of the [`GRID_POINTS`]-point log grid over the band.
    pub fn grid_tau(&self, i: usize) -> f64 {
        let ratio = self.tau_max / self.tau_min;
        self.tau_min * libm::pow(ratio, i as f64 / (GRID_POINTS - 1) as f64)
    }

    /// The geometric mean over the band's log grid of the Allan deviation of
    /// the sum of unit-variance terms.
    fn unit_geometric_mean(&self) -> f64 {
        let mut log_sum = 0.0;
        for i in 0..GRID_POINTS {
            log_sum += libm::log(self.unit_allan_deviation(self.grid_tau(i)));
        }
        libm::exp(log_sum / GRID_POINTS as f64)
    }

    /// The common variance of every term: the geometric mean over the band of
    /// the analytic Allan deviation equals 0.664·B.
    pub fn term_variance(&self) -> f64 {
        let unit = self.unit_geometric_mean();
        let floor = FLICKER_FLOOR_FACTOR * self.b;
        if unit > 0.0 && unit.is_finite() {
            (floor / unit) * (floor / unit)
        } else {
            0.0
        }
    }

    /// The lowest and highest ratio of the analytic Allan deviation to the
    /// flicker floor 0.664·B over the band (on the log grid): how flat the
    /// floor is. Independent of B.
    pub fn flatness(&self) -> (f64, f64) {
        let mean = self.unit_geometric_mean();
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..GRID_POINTS {
            let r = self.unit_allan_deviation(self.grid_tau(i)) / mean;
            lo = lo.min(r);
            hi = hi.max(r);
        }
        (lo, hi)
    }

    /// The analytic Allan deviation of the modelled process at averaging time τ.
    pub fn allan_deviation(&self, tau: f64) -> f64 {
        let q = self.term_variance();
        let mut avar = 0.0;
        for k in 0..self.terms as usize {
            avar += allan_variance(q, self.correlation_time(k), tau);
        }
        libm::sqrt(avar)
    }
}

/// The running process of one axis.
#[derive(Clone, Copy, Debug)]
pub struct BiasInstability {
    terms: [GaussMarkov; MAX_TERMS],
    n: usize,
}

impl BiasInstability {
    /// The process for `params` sampled every `ts` seconds; every term starts
    /// stationary (drawn from `rng`, which then drives all terms in order).
    /// `params.terms` is clamped to 1..=[`MAX_TERMS`] (scenes are validated first).
    pub fn new(params: &BiasInstabilityParams, ts: f64, rng: &mut Rng) -> Self {
        let n = (params.terms as usize).clamp(1, MAX_TERMS);
        let sigma = libm::sqrt(params.term_variance());
        let mut terms = [GaussMarkov::new(0.0, 1.0, ts, 0.0); MAX_TERMS];
        for (k, term) in terms.iter_mut().take(n).enumerate() {
            *term = GaussMarkov::new_stationary(sigma, params.correlation_time(k), ts, rng);
        }
        Self { terms, n }
    }

    /// Advances every term one step and returns their sum.
    pub fn step(&mut self, rng: &mut Rng) -> f64 {
        let mut sum = 0.0;
        for term in self.terms.iter_mut().take(self.n) {
            sum += term.step(rng);
        }
        sum
    }
}
