//! The five-term noise model of IEEE Std 952-1997 Annex C, fitted jointly to
//! an Allan-variance curve:
//!
//!   σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²τ/3 + R²τ²/2,
//!
//! quantisation Q (slope −1 of σ), white noise N (−½), bias instability B
//! (0; the flat floor is √(2 ln 2/π)·B ≈ 0.664·B), rate random walk K (+½)
//! and rate ramp R (+1). The model is linear in the squared coefficients
//! c = (Q², N², B², K², R²) ≥ 0.
//!
//! Fit: weighted non-negative least squares of σ²(τᵢ). A variance estimate
//! with ν EDF has Var(s²) = 2σ⁴/ν (χ²), so the weight is wᵢ = νᵢ/(2σᵢ⁴).
//! Using the measured s² for σ² would favour points that happen to fall low
//! (with ν = 1 a draw can be 100 times below σ²); the weights therefore come
//! from the confidence intervals and are iterated ([`ITERATIONS`] passes):
//! the first uses the upper end of each point's 1σ interval,
//! σ² ≈ ν s²/χ²_{0.159}(ν) (≈ s² for many EDF, ≈ 25 s² for ν = 1), each
//! next one the previous fit's model. The
//! non-negativity is exact: with five terms every support set (31 of them)
//! is solved by unconstrained weighted least squares (Cholesky of the
//! column-scaled normal matrix) and the feasible solution of least weighted
//! residual is kept — the NNLS optimum is the unconstrained optimum on its
//! own support.
//!
//! Uncertainties: the covariance of c on the support is the inverse normal
//! matrix, scaled by the reduced χ² when that exceeds 1 (the model explains
//! the curve worse than the EDF say). A term outside the support is reported
//! as 0 with the standard deviation it would have with its column added.
//! For a coefficient √c the standard deviation is σ_c/(2√c) (first order);
//! for c = 0 it is √σ_c, the size of a term one standard deviation would hide.
//!
//! Limitation: the weights treat the points as independent. Overlapping
//! estimates at neighbouring octaves are correlated — strongly for flicker
//! noise, whose long memory can hold several long-τ octaves 10–20 % above
//! the floor in one record — so a K or R term fitted from the last few
//! octaves of a record (τ within a factor ~10 of its length) can be
//! reported with an uncertainty several times too small.

use super::chi2;

/// Weight iterations of the fit.
pub const ITERATIONS: usize = 4;

/// Number of model terms.
pub const TERMS: usize = 5;

/// 2 ln 2 / π: the Allan variance of flicker noise per unit B².
pub const FLICKER_FACTOR: f64 = 2.0 * core::f64::consts::LN_2 / core::f64::consts::PI;

/// One term of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Term {
    /// Quantisation Q (angle or velocity units).
    Quantisation,
    /// White noise N (units/√Hz: ARW or VRW).
    WhiteNoise,
    /// Bias instability B (rate units).
    BiasInstability,
    /// Rate random walk K (units/√s).
    RandomWalk,
    /// Rate ramp R (units/s).
    RateRamp,
}

impl Term {
    /// Every term, in model order.
    pub const ALL: [Term; TERMS] = [
        Term::Quantisation,
        Term::WhiteNoise,
        Term::BiasInstability,
        Term::RandomWalk,
        Term::RateRamp,
    ];

    /// The term's contribution to σ²(τ) per unit squared coefficient.
    pub fn basis(self, tau: f64) -> f64 {
        match self {
            Term::Quantisation => 3.0 / (tau * tau),
            Term::WhiteNoise => 1.0 / tau,
            Term::BiasInstability => FLICKER_FACTOR,
            Term::RandomWalk => tau / 3.0,
            Term::RateRamp => tau * tau / 2.0,
        }
    }

    /// The usual symbol: Q, N, B, K, R.
    pub fn symbol(self) -> &'static str {
        match self {
            Term::Quantisation => "Q",
            Term::WhiteNoise => "N",
            Term::BiasInstability => "B",
            Term::RandomWalk => "K",
            Term::RateRamp => "R",
        }
    }

    /// The slope of σ(τ) in log-log where the term dominates.
    pub fn slope(self) -> f64 {
        match self {
            Term::Quantisation => -1.0,
            Term::WhiteNoise => -0.5,
            Term::BiasInstability => 0.0,
            Term::RandomWalk => 0.5,
            Term::RateRamp => 1.0,
        }
    }
}

/// One point of an Allan-variance curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// Averaging time τ, s.
    pub tau: f64,
    /// The Allan variance estimate at τ (squared SI units).
    pub avar: f64,
    /// Its equivalent degrees of freedom.
    pub edf: f64,
}

/// One fitted coefficient, SI units (Q in rad or m/s, N in (rad/s)/√Hz or
/// (m/s²)/√Hz, B in rad/s or m/s², K in (rad/s)/√s or (m/s²)/√s, R in
/// rad/s² or m/s³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermEstimate {
    /// The coefficient (≥ 0).
    pub value: f64,
    /// Its standard deviation (see the module comment).
    pub sigma: f64,
    /// The squared coefficient as fitted.
    pub squared: f64,
    /// The standard deviation of the squared coefficient.
    pub squared_sigma: f64,
    /// False when the non-negativity constraint set the term to zero.
    pub in_support: bool,
}

/// The fitted model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseFit {
    /// The coefficients, in [`Term::ALL`] order.
    pub terms: [TermEstimate; TERMS],
    /// The weighted residual Σ wᵢ (sᵢ² − model(τᵢ))².
    pub chi2: f64,
    /// Degrees of freedom of the residual: points − terms in the support.
    pub dof: usize,
}

impl NoiseFit {
    /// The estimate of `term`.
    pub fn term(&self, term: Term) -> &TermEstimate {
        &self.terms[term as usize]
    }

    /// The model's Allan variance at τ.
    pub fn avar(&self, tau: f64) -> f64 {
        Term::ALL
            .iter()
            .map(|&t| self.terms[t as usize].squared * t.basis(tau))
            .sum()
    }
}

/// Why a curve cannot be fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FitError {
    /// No point at all.
    NoPoints,
    /// A point whose τ is not positive, variance negative or EDF not positive (or NaN).
    BadPoint {
        /// Index of the point.
        index: usize,
        /// Its τ.
        tau: f64,
        /// Its variance.
        avar: f64,
        /// Its EDF.
        edf: f64,
    },
}

impl core::fmt::Display for FitError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FitError::NoPoints => write!(f, "no Allan-variance point to fit"),
            FitError::BadPoint {
                index,
                tau,
                avar,
                edf,
            } => write!(
                f,
                "point {index} (tau {tau} s, variance {avar}, edf {edf}) is not a valid estimate"
            ),
        }
    }
}

type Matrix = [[f64; TERMS]; TERMS];

/// The weighted normal equations of the terms `idx[..n]`.
#[allow(clippy::needless_range_loop)]
fn normal_equations(
    points: &[CurvePoint],
    weights: &[f64],
    n: usize,
    idx: &[usize; TERMS],
) -> (Matrix, [f64; TERMS]) {
    let mut g = [[0.0; TERMS]; TERMS];
    let mut r = [0.0; TERMS];
    for (p, &w) in points.iter().zip(weights) {
        let mut a = [0.0; TERMS];
        for (i, &k) in idx[..n].iter().enumerate() {
            a[i] = Term::ALL[k].basis(p.tau);
        }
        for i in 0..n {
            r[i] += w * a[i] * p.avar;
            for j in 0..n {
                g[i][j] += w * a[i] * a[j];
            }
        }
    }
    (g, r)
}

/// Cholesky factor (lower) of the n×n leading block; None when not positive definite.
// Indices as in the textbook formula: checkable at a glance.
#[allow(clippy::needless_range_loop)]
fn cholesky(g: &Matrix, n: usize) -> Option<Matrix> {
    let mut l = [[0.0; TERMS]; TERMS];
    for i in 0..n {
        for j in 0..=i {
            let mut s = g[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                let positive = s > 1e-13 * g[i][i].abs() && s.is_finite();
                if !positive {
                    return None;
                }
                l[i][i] = libm::sqrt(s);
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

#[allow(clippy::needless_range_loop)]
fn cholesky_solve(l: &Matrix, n: usize, b: &[f64; TERMS]) -> [f64; TERMS] {
    let mut y = [0.0; TERMS];
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i][k] * y[k];
        }
        y[i] = s / l[i][i];
    }
    let mut x = [0.0; TERMS];
    for i in (0..n).rev() {
        let mut s = y[i];
        for k in i + 1..n {
            s -= l[k][i] * x[k];
        }
        x[i] = s / l[i][i];
    }
    x
}

/// The support's term indices.
fn members(support: u32) -> ([usize; TERMS], usize) {
    let mut idx = [0; TERMS];
    let mut n = 0;
    for (k, slot) in (0..TERMS).filter(|k| support & (1 << k) != 0).zip(0..) {
        idx[slot] = k;
        n += 1;
    }
    (idx, n)
}

/// A weighted least-squares solve on one support: the squared coefficients
/// (full length, zero off the support) and the diagonal of their covariance;
/// None when the normal matrix is singular.
#[allow(clippy::needless_range_loop)]
fn solve_support(
    points: &[CurvePoint],
    weights: &[f64],
    support: u32,
) -> Option<([f64; TERMS], [f64; TERMS])> {
    let (idx, n) = members(support);
    if n == 0 || n > points.len() {
        return None;
    }
    let (g, r) = normal_equations(points, weights, n, &idx);
    // Column scaling: the bases differ by many decades over the τ range.
    let mut scale = [1.0; TERMS];
    for i in 0..n {
        if g[i][i].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        scale[i] = 1.0 / libm::sqrt(g[i][i]);
    }
    let mut gs = [[0.0; TERMS]; TERMS];
    let mut rs = [0.0; TERMS];
    for i in 0..n {
        rs[i] = r[i] * scale[i];
        for j in 0..n {
            gs[i][j] = g[i][j] * scale[i] * scale[j];
        }
    }
    let l = cholesky(&gs, n)?;
    let xs = cholesky_solve(&l, n, &rs);
    let mut coef = [0.0; TERMS];
    let mut var = [0.0; TERMS];
    for i in 0..n {
        coef[idx[i]] = xs[i] * scale[i];
        let mut e = [0.0; TERMS];
        e[i] = 1.0;
        let col = cholesky_solve(&l, n, &e);
        var[idx[i]] = col[i] * scale[i] * scale[i];
    }
    Some((coef, var))
}

fn residual(points: &[CurvePoint], weights: &[f64], coef: &[f64; TERMS]) -> f64 {
    points
        .iter()
        .zip(weights)
        .map(|(p, &w)| {
            let model: f64 = Term::ALL
                .iter()
                .map(|&t| coef[t as usize] * t.basis(p.tau))
                .sum();
            w * (p.avar - model) * (p.avar - model)
        })
        .sum()
}

/// The NNLS solution for fixed weights: (coefficients, covariance diagonal, support, χ²).
fn nnls(points: &[CurvePoint], weights: &[f64]) -> ([f64; TERMS], [f64; TERMS], u32, f64) {
    let zero = [0.0; TERMS];
    let mut best = (zero, zero, 0u32, residual(points, weights, &zero));
    for support in 1u32..(1 << TERMS) {
        if let Some((coef, var)) = solve_support(points, weights, support) {
            if coef.iter().all(|&c| c >= 0.0 && c.is_finite()) {
                let chi2 = residual(points, weights, &coef);
                if chi2 < best.3 {
                    best = (coef, var, support, chi2);
                }
            }
        }
    }
    best
}

/// Fits the five-term model to `points`; `weights` is scratch space of the
/// same length (the core does not allocate). Points with zero variance are
/// kept (they pull the model down) with the weight of the model there.
pub fn fit(points: &[CurvePoint], weights: &mut [f64]) -> Result<NoiseFit, FitError> {
    if points.is_empty() || weights.len() < points.len() {
        return Err(FitError::NoPoints);
    }
    for (index, p) in points.iter().enumerate() {
        let ok = p.tau.is_finite()
            && p.tau > 0.0
            && p.avar.is_finite()
            && p.avar >= 0.0
            && p.edf.is_finite()
            && p.edf > 0.0;
        if !ok {
            return Err(FitError::BadPoint {
                index,
                tau: p.tau,
                avar: p.avar,
                edf: p.edf,
            });
        }
    }
    let weights = &mut weights[..points.len()];
    let peak = points.iter().map(|p| p.avar).fold(0.0f64, f64::max);
    if peak == 0.0 {
        let zero = TermEstimate {
            value: 0.0,
            sigma: 0.0,
            squared: 0.0,
            squared_sigma: 0.0,
            in_support: false,
        };
        return Ok(NoiseFit {
            terms: [zero; TERMS],
            chi2: 0.0,
            dof: points.len(),
        });
    }
    // A floor keeps weights finite where a variance (or the model) is zero.
    let floor = peak * 1e-30;
    let lower_tail = 0.5 * (1.0 - super::edf::ONE_SIGMA);
    for (w, p) in weights.iter_mut().zip(points) {
        let upper = p.avar * p.edf / chi2::quantile(lower_tail, p.edf);
        let v = if upper.is_finite() { upper } else { p.avar }.max(floor);
        *w = p.edf / (2.0 * v * v);
    }
    let mut solution = nnls(points, weights);
    for _ in 1..ITERATIONS {
        for (w, p) in weights.iter_mut().zip(points) {
            let model: f64 = Term::ALL
                .iter()
                .map(|&t| solution.0[t as usize] * t.basis(p.tau))
                .sum();
            let v = model.max(floor);
            *w = p.edf / (2.0 * v * v);
        }
        solution = nnls(points, weights);
    }
    let (coef, var, support, chi2) = solution;
    let in_support = support.count_ones() as usize;
    let dof = points.len().saturating_sub(in_support);
    let inflation = if dof > 0 {
        (chi2 / dof as f64).max(1.0)
    } else {
        1.0
    };
    let mut terms = [TermEstimate {
        value: 0.0,
        sigma: 0.0,
        squared: 0.0,
        squared_sigma: 0.0,
        in_support: false,
    }; TERMS];
    for (k, est) in terms.iter_mut().enumerate() {
        let inside = support & (1 << k) != 0;
        let v = if inside {
            var[k]
        } else {
            solve_support(points, weights, support | (1 << k))
                .map(|(_, v)| v[k])
                .unwrap_or(f64::INFINITY)
        };
        let squared_sigma = libm::sqrt(v * inflation);
        let c = coef[k];
        let value = libm::sqrt(c);
        let sigma = if c > 0.0 {
            squared_sigma / (2.0 * value)
        } else {
            libm::sqrt(squared_sigma)
        };
        *est = TermEstimate {
            value,
            sigma,
            squared: c,
            squared_sigma,
            in_support: inside,
        };
    }
    Ok(NoiseFit { terms, chi2, dof })
}
