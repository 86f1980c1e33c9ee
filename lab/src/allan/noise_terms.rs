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
//! The fit itself is [`super::gls::fit`]: generalised least squares with
//! the covariance of the estimates ([`super::covariance`]). This module
//! holds the model, its types and `first_guess`, the fit that treats the
//! points as independent (weights from their EDF), which starts it.
//!
//! First guess: weighted non-negative least squares of σ²(τᵢ). A variance
//! estimate with ν EDF has Var(s²) = 2σ⁴/ν (χ²), so the weight is wᵢ =
//! νᵢ/(2σᵢ⁴). Using the measured s² for σ² would favour points that happen
//! to fall low (with ν = 1 a draw can be 100 times below σ²); the weights
//! therefore come from the confidence intervals and are iterated
//! ([`ITERATIONS`] passes): the first uses the upper end of each point's 1σ
//! interval, σ² ≈ ν s²/χ²_{0.159}(ν), each next one the previous fit's
//! model. Its uncertainties are not reported: the points are correlated.

use super::{chi2, nnls};

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
    /// Its standard deviation: σ_c/(2√c) for c > 0 (first order); for c = 0,
    /// √σ_c, the size of a term one standard deviation would hide.
    pub sigma: f64,
    /// The squared coefficient c as fitted.
    pub squared: f64,
    /// The standard deviation of c (from the estimates' covariance).
    pub squared_sigma: f64,
    /// False when the non-negativity constraint set the term to zero.
    pub in_support: bool,
    /// The test statistic c/σ_c (0 off the support).
    pub z: f64,
    /// True when the data support the term: in the support and
    /// z ≥ [`SIGNIFICANCE_Z`](super::gls::SIGNIFICANCE_Z).
    pub significant: bool,
    /// The τ range (s) that decided the term: the points where it is the
    /// largest part of the fitted σ²(τ); where it leads nowhere, the points
    /// where its share is at least half its largest. NaN without a share.
    pub tau_range: (f64, f64),
    /// The term's largest share of the fitted σ²(τ) over the points (0–1).
    pub share: f64,
}

impl TermEstimate {
    /// A term at zero with no information.
    pub const ZERO: Self = Self {
        value: 0.0,
        sigma: 0.0,
        squared: 0.0,
        squared_sigma: 0.0,
        in_support: false,
        z: 0.0,
        significant: false,
        tau_range: (f64::NAN, f64::NAN),
        share: 0.0,
    };
}

/// The fitted model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseFit {
    /// The coefficients, in [`Term::ALL`] order.
    pub terms: [TermEstimate; TERMS],
    /// The generalised residual rᵀV⁻¹r.
    pub chi2: f64,
    /// Degrees of freedom of the residual: points − terms in the support.
    pub dof: usize,
    /// The factor the standard deviations were scaled by: √(χ²/dof) when χ²
    /// fails the goodness-of-fit test (the model explains the curve worse
    /// than its covariance says), else 1.
    pub inflation: f64,
}

impl NoiseFit {
    /// The estimate of `term`.
    pub fn term(&self, term: Term) -> &TermEstimate {
        &self.terms[term as usize]
    }

    /// The model's Allan variance at τ.
    pub fn avar(&self, tau: f64) -> f64 {
        model_avar(&self.terms.map(|t| t.squared), tau)
    }
}

/// Why a curve is not fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FitError {
    /// Fewer points than a fit needs.
    TooFewPoints {
        /// The points given.
        count: usize,
        /// The fewest a fit takes.
        needed: usize,
    },
    /// Every estimate is zero: the data hold no noise (a dead or constant channel).
    NoNoise,
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
    /// The covariance was computed for other points (count or τ).
    CovarianceMismatch,
    /// The covariance of the estimates is not positive definite.
    Covariance,
}

impl core::fmt::Display for FitError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FitError::TooFewPoints { count, needed } => write!(
                f,
                "{count} tau points: too few to fit the noise terms (at least {needed})"
            ),
            FitError::NoNoise => write!(f, "no noise detected: the Allan variance is 0 at every tau"),
            FitError::BadPoint {
                index,
                tau,
                avar,
                edf,
            } => write!(
                f,
                "point {index} (tau {tau:e} s, variance {avar:e}, edf {edf:e}) is not a valid estimate"
            ),
            FitError::CovarianceMismatch => {
                write!(f, "the covariance was computed for other tau points")
            }
            FitError::Covariance => write!(
                f,
                "the covariance of the Allan estimates is not positive definite"
            ),
        }
    }
}

/// Checks every point: τ > 0, variance ≥ 0, EDF > 0, all finite.
pub(crate) fn check_points(points: &[CurvePoint]) -> Result<(), FitError> {
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
    Ok(())
}

/// The model's Allan variance at τ for the squared coefficients `c`
/// (Q², N², B², K², R², in [`Term::ALL`] order).
pub fn model_avar(c: &[f64; TERMS], tau: f64) -> f64 {
    Term::ALL
        .iter()
        .map(|&t| c[t as usize] * t.basis(tau))
        .sum()
}

/// The first guess of the squared coefficients (see the module comment):
/// `rows` and `data` are scratch space of the points' length (the core does
/// not allocate). The points must have been checked and hold some noise.
pub(crate) fn first_guess(
    points: &[CurvePoint],
    rows: &mut [[f64; TERMS]],
    data: &mut [f64],
) -> [f64; TERMS] {
    let (rows, data) = (&mut rows[..points.len()], &mut data[..points.len()]);
    let peak = points.iter().map(|p| p.avar).fold(0.0f64, f64::max);
    // A floor keeps weights finite where a variance (or the model) is zero.
    let floor = peak * 1e-30;
    let lower_tail = 0.5 * (1.0 - super::edf::ONE_SIGMA);
    let weigh = |rows: &mut [[f64; TERMS]], data: &mut [f64], i: usize, p: &CurvePoint, v: f64| {
        let sw = libm::sqrt(p.edf / 2.0) / v.max(floor);
        for (k, t) in Term::ALL.iter().enumerate() {
            rows[i][k] = sw * t.basis(p.tau);
        }
        data[i] = sw * p.avar;
    };
    for (i, p) in points.iter().enumerate() {
        let upper = p.avar * p.edf / chi2::quantile(lower_tail, p.edf);
        let v = if upper.is_finite() { upper } else { p.avar };
        weigh(rows, data, i, p, v);
    }
    let mut c = nnls::solve(rows, data).coef;
    for _ in 1..ITERATIONS {
        for (i, p) in points.iter().enumerate() {
            weigh(rows, data, i, p, model_avar(&c, p.tau));
        }
        c = nnls::solve(rows, data).coef;
    }
    c
}
