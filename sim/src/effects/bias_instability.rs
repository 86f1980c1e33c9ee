//! Bias instability (the flicker floor of the Allan deviation) as a sum of
//! first-order Gauss–Markov terms spread over decades.
//!
//! Flicker noise has the two-sided PSD S(f) = (B²/2π)/f and a flat Allan
//! deviation σ_A = √(2 ln 2/π)·B ≈ 0.664·B (IEEE Std 952 Annex C.3). A sum of
//! Lorentzians (Gauss–Markov terms) whose correlation times are spaced evenly
//! in log τ approximates 1/f between the extreme corner frequencies (Keshner,
//! "1/f noise", Proc. IEEE 70(3), 1982). Each term's Allan deviation peaks at
//! τ ≈ 1.89·T_c; the peaks are spread evenly in log τ over the band
//! extended by [`MARGIN_DECADES`] on each side, and the terms' variances are
//! the least-squares solution that puts the analytic Allan variance at the
//! floor (0.664·B)² on a log grid of the band ([`GRID_POINTS`] points).
//! Equal variances (the design before) droop at the band's ends; fitted
//! ones hold the floor to the ends.
//!
//! Flatness (analytic, [`BiasInstabilityParams::flatness`]): within ±1 %
//! of 0.664·B over the whole band [τ_min, τ_max] with a term per 0.85
//! decade of the band and its margins or closer (±0.4 % or better measured
//! for the default band, 0.01 s … 10⁵ s with 11 terms, and the bands of
//! the tests), ±1.3 % with a term per decade (sim/tests/bias_instability.rs
//! prints the figures). Outside the band the curve falls away from the
//! floor (the same at both ends whatever the band): −1.2 % at τ_min/2, −7 %
//! at τ_min/4, −26 % at τ_min/10, then as √τ from about τ_min/100 (every
//! term looks like a rate random walk there); above the band −2.3 % at
//! 2τ_max, −8.5 % at 4τ_max, −28 % at 10τ_max, then as 1/√τ (white
//! noise). There is no rise: each term is
//! read as its mean over the sample period
//! ([`super::averaged_gauss_markov`]), so a term faster than the sample
//! period does not alias into white noise, and the simulated record's Allan
//! variance is the analytic one at every τ = m·Ts.
//!
//! A least-squares solution with a non-positive variance (terms packed far
//! closer than the Allan kernels' width, e.g. 16 terms over one decade) is
//! not a process: the non-negative least-squares one is used instead. The
//! number of terms is the cost knob (two normal deviates per term and sample).

use super::averaged_gauss_markov::AveragedGaussMarkov;
use super::gauss_markov::allan_variance;
use super::rng::Rng;

/// The most terms one axis can hold (fixed capacity: no allocation).
pub const MAX_TERMS: usize = 16;

/// Decades added on each side of the band over which the terms are spread.
pub const MARGIN_DECADES: f64 = 0.5;

/// Points of the log grid on which the terms' variances are fitted.
pub const GRID_POINTS: usize = 41;

/// Points of the (finer) log grid on which the flatness is measured.
pub const FLATNESS_POINTS: usize = 401;

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
    /// B with the default band, 0.01 s to 10⁵ s (a record at up to 100 Hz
    /// and a day long sees the floor flat), and 11 terms (one per 0.8 decade
    /// of the band and its margins).
    pub const fn with_default_band(b: f64) -> Self {
        Self {
            b,
            tau_min: 0.01,
            tau_max: 1e5,
            terms: 11,
        }
    }

    /// The number of terms, clamped to 1..=[`MAX_TERMS`] (scenes are validated first).
    fn count(&self) -> usize {
        (self.terms as usize).clamp(1, MAX_TERMS)
    }

    /// Correlation time of term `k` (Allan peaks log-spaced over the band
    /// extended by [`MARGIN_DECADES`] on each side).
    pub fn correlation_time(&self, k: usize) -> f64 {
        let n = self.count();
        let tau = if n == 1 {
            libm::sqrt(self.tau_min * self.tau_max)
        } else {
            let lo = libm::log10(self.tau_min) - MARGIN_DECADES;
            let hi = libm::log10(self.tau_max) + MARGIN_DECADES;
            libm::pow(10.0, lo + (hi - lo) * (k as f64 / (n - 1) as f64))
        };
        tau / PEAK_TAU_PER_TC
    }

    /// The averaging time of point `i` of a `points`-point log grid over the band.
    fn log_grid(&self, i: usize, points: usize) -> f64 {
        let ratio = self.tau_max / self.tau_min;
        self.tau_min * libm::pow(ratio, i as f64 / (points - 1).max(1) as f64)
    }

    /// The averaging time of point `i` of the [`GRID_POINTS`]-point log grid over the band.
    pub fn grid_tau(&self, i: usize) -> f64 {
        self.log_grid(i, GRID_POINTS)
    }

    /// The variances of the terms (the first [`Self::terms`] entries; see
    /// the module comment): their analytic Allan variance is (0.664·B)² on
    /// the grid in the least-squares sense.
    pub fn term_variances(&self) -> [f64; MAX_TERMS] {
        let unit = self.unit_variances();
        let floor = FLICKER_FLOOR_FACTOR * self.b;
        unit.map(|v| v * floor * floor)
    }

    /// The variances for a floor of 1: least squares on the grid, the
    /// unit-variance Allan curves of the terms being the columns of A and
    /// the floor 1 the target (normal equations AᵀA v = Aᵀ1); where that
    /// solution has a variance that is not positive, the non-negative least
    /// squares one instead ([`NNLS_ITERATIONS`] multiplicative updates from
    /// equal variances).
    fn unit_variances(&self) -> [f64; MAX_TERMS] {
        let n = self.count();
        let mut ata = [[0.0; MAX_TERMS]; MAX_TERMS];
        let mut atb = [0.0; MAX_TERMS];
        for i in 0..GRID_POINTS {
            let tau = self.grid_tau(i);
            let mut row = [0.0; MAX_TERMS];
            for (k, r) in row.iter_mut().enumerate().take(n) {
                *r = allan_variance(1.0, self.correlation_time(k), tau);
            }
            for j in 0..n {
                atb[j] += row[j];
                for k in 0..n {
                    ata[j][k] += row[j] * row[k];
                }
            }
        }
        let positive = |v: &[f64; MAX_TERMS]| v[..n].iter().all(|&x| x > 0.0 && x.is_finite());
        if let Some(v) = solve(&mut ata.clone(), &mut atb.clone(), n).filter(positive) {
            return v;
        }
        non_negative(&ata, &atb, n)
    }

    /// The lowest and highest ratio of the analytic Allan deviation to the
    /// flicker floor 0.664·B over the band (on a [`FLATNESS_POINTS`]-point
    /// log grid): how flat the floor is. Independent of B.
    pub fn flatness(&self) -> (f64, f64) {
        let unit = BiasInstabilityParams { b: 1.0, ..*self };
        let floor = FLICKER_FLOOR_FACTOR;
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..FLATNESS_POINTS {
            let r = unit.allan_deviation(self.log_grid(i, FLATNESS_POINTS)) / floor;
            lo = lo.min(r);
            hi = hi.max(r);
        }
        (lo, hi)
    }

    /// The analytic Allan deviation of the modelled process at averaging
    /// time τ (also that of a simulated record at τ = m·Ts: see the module comment).
    pub fn allan_deviation(&self, tau: f64) -> f64 {
        let q = self.term_variances();
        let mut avar = 0.0;
        for (k, q) in q.iter().enumerate().take(self.count()) {
            avar += allan_variance(*q, self.correlation_time(k), tau);
        }
        libm::sqrt(avar)
    }
}

/// Multiplicative updates of the non-negative least-squares fallback.
pub const NNLS_ITERATIONS: usize = 2000;

/// Non-negative least squares from the normal equations (Lee & Seung's
/// multiplicative update, v_k ← v_k·(Aᵀ1)_k/(AᵀA v)_k, every entry of A
/// being positive): from equal variances scaled to the floor's mean level.
fn non_negative(
    ata: &[[f64; MAX_TERMS]; MAX_TERMS],
    atb: &[f64; MAX_TERMS],
    n: usize,
) -> [f64; MAX_TERMS] {
    let total: f64 = (0..n)
        .flat_map(|j| (0..n).map(move |k| (j, k)))
        .map(|(j, k)| ata[j][k])
        .sum();
    let level: f64 = atb[..n].iter().sum();
    let mut v = [0.0; MAX_TERMS];
    if !(total > 0.0 && level > 0.0) {
        return v;
    }
    v[..n].fill(level / total);
    for _ in 0..NNLS_ITERATIONS {
        for k in 0..n {
            let av: f64 = (0..n).map(|j| ata[k][j] * v[j]).sum();
            if av > 0.0 {
                v[k] *= atb[k] / av;
            }
        }
    }
    v
}

/// Solves the symmetric system `m`·x = `b` (its first `n` rows) by Gaussian
/// elimination with partial pivoting; None when it is singular.
fn solve(
    m: &mut [[f64; MAX_TERMS]; MAX_TERMS],
    b: &mut [f64; MAX_TERMS],
    n: usize,
) -> Option<[f64; MAX_TERMS]> {
    let scale = (0..n).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        let pivot = m[p][c].abs();
        if pivot.is_nan() || pivot <= scale * 1e-14 {
            return None;
        }
        m.swap(c, p);
        b.swap(c, p);
        let pivot_row = m[c];
        for r in c + 1..n {
            let f = m[r][c] / pivot_row[c];
            for (x, p) in m[r][c..n].iter_mut().zip(&pivot_row[c..n]) {
                *x -= f * p;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; MAX_TERMS];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| m[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / m[r][r];
    }
    Some(x)
}

/// The running process of one axis.
#[derive(Clone, Copy, Debug)]
pub struct BiasInstability {
    terms: [AveragedGaussMarkov; MAX_TERMS],
    n: usize,
}

impl BiasInstability {
    /// The process for `params` read as means over periods of `ts` seconds;
    /// every term starts stationary (drawn from `rng`, which then drives all
    /// terms in order). `params.terms` is clamped to 1..=[`MAX_TERMS`]
    /// (scenes are validated first).
    pub fn new(params: &BiasInstabilityParams, ts: f64, rng: &mut Rng) -> Self {
        let n = params.count();
        let q = params.term_variances();
        let mut terms = [AveragedGaussMarkov::IDLE; MAX_TERMS];
        for (k, term) in terms.iter_mut().enumerate().take(n) {
            let tc = params.correlation_time(k);
            *term = AveragedGaussMarkov::new_stationary(libm::sqrt(q[k]), tc, ts, rng);
        }
        Self { terms, n }
    }

    /// Advances every term one period and returns the sum of their means.
    pub fn step(&mut self, rng: &mut Rng) -> f64 {
        let mut sum = 0.0;
        for term in self.terms.iter_mut().take(self.n) {
            sum += term.step(rng);
        }
        sum
    }
}
