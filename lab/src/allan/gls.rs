//! The noise terms by generalised least squares: the five-term model of
//! [`super::noise_terms`] fitted to the octave Allan variances with their
//! full covariance ([`super::covariance`]), non-negative, with a test per term.
//!
//! Why GLS rather than a parametric bootstrap: both account for the
//! correlation of the overlapping estimates, but a bootstrap simulates the
//! fitted model a few hundred times at the record's length (for a 36 h
//! record at 100 Hz, 10⁹–10¹⁰ samples per column), while the covariance is
//! computed once per record from lag sums (0.04 s in release for 2^19
//! samples, 19 octaves), and checked against simulation in
//! lab/tests/allan_covariance.rs (within 4 % of the measured one).
//! Each iteration below then costs one Cholesky of a points × points
//! matrix and the 31 support solves: well under a millisecond.
//!
//! Fit: the covariance V depends on the model, so the fit iterates
//! ([`ITERATIONS`] at most): V from the current coefficients (the first from
//! `first_guess`(super::noise_terms)), V = LLᵀ, the design and the
//! estimates whitened by L⁻¹, then the exact non-negative least squares of
//! `super::nnls`. The covariance of the coefficients on the support is
//! (AᵀV⁻¹A)⁻¹, scaled by √(χ²/dof) when χ² fails the goodness-of-fit test
//! at [`FIT_TEST_LEVEL`] (the model does not explain the curve).
//!
//! Model error: V gets a diagonal (MODEL_ERROR·σ²(τ))² added
//! ([`MODEL_ERROR`] relative): the five-term model is an idealisation (a
//! real sensor's flicker is 1/f only over a band, a sampled random walk adds
//! K²τ₀²/(6τ), …), and with 10⁶ samples the shortest-τ estimates are known
//! to 0.1 %, so a 0.2 % departure from the model would otherwise decide N.
//! 0.1 % is what lab/tests/allan_coverage.rs needs for N's errors to be
//! ≈ 1σ rms on the simulator's presets, whose flicker droops below its
//! band (N reads 0.1–0.2 % low there); 0.5 % made every σ of N twice too large.
//!
//! The test: a term is reported (significant) when it is in the support and
//! its squared coefficient is at least [`SIGNIFICANCE_Z`] standard deviations
//! above zero (a one-sided Wald test: 2.3 % false reports per absent term
//! when the covariance is right). The τ range that decided it: the points
//! where it is the largest part of the fitted σ²(τ).

use super::chi2;
use super::cholesky::{cholesky, forward_subst};
use super::covariance::{OctaveCovariance, MAX_POINTS};
use super::nnls::{self, Solution};
use super::noise_terms::{
    check_points, first_guess, model_avar, CurvePoint, FitError, NoiseFit, Term, TermEstimate,
    TERMS,
};

/// Fewest points a fit takes: one per term and one degree of freedom to judge it.
pub const MIN_POINTS: usize = TERMS + 1;

/// The z a term's squared coefficient must reach to be reported.
pub const SIGNIFICANCE_Z: f64 = 2.0;

/// Relative model error added to each estimate's standard deviation (see the module comment).
pub const MODEL_ERROR: f64 = 0.001;

/// The level of the χ² goodness-of-fit test that decides whether the
/// σ's are scaled by √(χ²/dof).
pub const FIT_TEST_LEVEL: f64 = 0.95;

/// Most iterations of the covariance.
pub const ITERATIONS: usize = 8;

/// The whitened problem of one iteration.
struct Whitened {
    rows: [[f64; TERMS]; MAX_POINTS],
    data: [f64; MAX_POINTS],
    v: [f64; MAX_POINTS * MAX_POINTS],
}

impl Whitened {
    /// V for the coefficients `c`, its Cholesky factor, and the design and
    /// estimates whitened by it.
    fn build(
        &mut self,
        points: &[CurvePoint],
        cov: &OctaveCovariance,
        c: &[f64; TERMS],
    ) -> Result<(), FitError> {
        let p = points.len();
        let v = &mut self.v[..p * p];
        cov.matrix(c, v);
        for (i, pt) in points.iter().enumerate() {
            let m = model_avar(c, pt.tau).max(pt.avar);
            // The model error, and a floor that keeps V positive definite
            // when the model is a bare ramp (deterministic: V = 0).
            v[i * p + i] += (MODEL_ERROR * m) * (MODEL_ERROR * m) + (1e-9 * m) * (1e-9 * m);
        }
        cholesky(v, p, p, 0.0).map_err(|_| FitError::Covariance)?;
        // rows = L⁻¹A, data = L⁻¹s, a column at a time.
        let mut column = [0.0; MAX_POINTS];
        for (k, t) in Term::ALL.iter().enumerate() {
            for (x, pt) in column.iter_mut().zip(points) {
                *x = t.basis(pt.tau);
            }
            forward_subst(v, p, &mut column[..p]);
            for (row, &x) in self.rows.iter_mut().zip(&column[..p]) {
                row[k] = x;
            }
        }
        for (d, pt) in self.data.iter_mut().zip(points) {
            *d = pt.avar;
        }
        forward_subst(v, p, &mut self.data[..p]);
        Ok(())
    }
}

/// Fits the five-term model to the octave points with their covariance
/// `cov` (computed for the same points).
pub fn fit(points: &[CurvePoint], cov: &OctaveCovariance) -> Result<NoiseFit, FitError> {
    if points.len() < MIN_POINTS {
        return Err(FitError::TooFewPoints {
            count: points.len(),
            needed: MIN_POINTS,
        });
    }
    if points.len() != cov.points() {
        return Err(FitError::CovarianceMismatch);
    }
    check_points(points)?;
    if points.iter().all(|p| p.avar == 0.0) {
        return Err(FitError::NoNoise);
    }
    let p = points.len();
    let mut w = Whitened {
        rows: [[0.0; TERMS]; MAX_POINTS],
        data: [0.0; MAX_POINTS],
        v: [0.0; MAX_POINTS * MAX_POINTS],
    };
    let mut c = first_guess(points, &mut w.rows, &mut w.data);
    let mut solution = None;
    for _ in 0..ITERATIONS {
        w.build(points, cov, &c)?;
        let s = nnls::solve(&w.rows[..p], &w.data[..p]);
        let moved = s
            .coef
            .iter()
            .zip(&c)
            .any(|(a, b)| libm::fabs(a - b) > 1e-6 * libm::fabs(*b).max(1e-300));
        c = s.coef;
        solution = Some(s);
        if !moved {
            break;
        }
    }
    // At least one iteration ran (ITERATIONS ≥ 1).
    let solution = solution.ok_or(FitError::Covariance)?;
    Ok(finish(points, &w, &solution))
}

/// The estimates, their tests and τ ranges from the final solution.
fn finish(points: &[CurvePoint], w: &Whitened, s: &Solution) -> NoiseFit {
    let p = points.len();
    let in_support = s.support.count_ones() as usize;
    let dof = p.saturating_sub(in_support);
    // Scaled only when the model fails its goodness-of-fit test: scaling
    // whenever χ² > dof would widen a correct fit's σ's half the time.
    let inflation = if dof > 0 && s.chi2 > chi2::quantile(FIT_TEST_LEVEL, dof as f64) {
        libm::sqrt(s.chi2 / dof as f64)
    } else {
        1.0
    };
    let mut terms = [TermEstimate::ZERO; TERMS];
    for (k, est) in terms.iter_mut().enumerate() {
        let inside = s.support & (1 << k) != 0;
        let var = if inside {
            s.covariance[k][k]
        } else {
            nnls::solve_support(&w.rows[..p], &w.data[..p], s.support | (1 << k))
                .map(|(_, cov)| cov[k][k])
                .unwrap_or(f64::INFINITY)
        };
        let squared_sigma = libm::sqrt(var) * inflation;
        let c = s.coef[k];
        let value = libm::sqrt(c);
        let sigma = if c > 0.0 {
            squared_sigma / (2.0 * value)
        } else {
            libm::sqrt(squared_sigma)
        };
        let z = if inside && squared_sigma > 0.0 {
            c / squared_sigma
        } else {
            0.0
        };
        let (tau_range, share) = decided_by(points, &s.coef, k);
        *est = TermEstimate {
            value,
            sigma,
            squared: c,
            squared_sigma,
            in_support: inside,
            z,
            significant: inside && z >= SIGNIFICANCE_Z,
            tau_range,
            share,
        };
    }
    NoiseFit {
        terms,
        chi2: s.chi2,
        dof,
        inflation,
    }
}

/// Term k's τ range and largest share of the fitted σ²(τ) (see the module comment).
fn decided_by(points: &[CurvePoint], c: &[f64; TERMS], k: usize) -> ((f64, f64), f64) {
    let share = |pt: &CurvePoint, j: usize| {
        let m = model_avar(c, pt.tau);
        if m > 0.0 {
            c[j] * Term::ALL[j].basis(pt.tau) / m
        } else {
            0.0
        }
    };
    let peak = points.iter().map(|pt| share(pt, k)).fold(0.0, f64::max);
    if peak == 0.0 {
        return ((f64::NAN, f64::NAN), 0.0);
    }
    let leads = |pt: &CurvePoint| (0..TERMS).all(|j| share(pt, j) <= share(pt, k));
    let any_lead = points.iter().any(leads);
    let chosen = |pt: &&CurvePoint| {
        if any_lead {
            leads(pt)
        } else {
            share(pt, k) >= 0.5 * peak
        }
    };
    let lo = points.iter().find(chosen).map_or(f64::NAN, |pt| pt.tau);
    let hi = points
        .iter()
        .rev()
        .find(chosen)
        .map_or(f64::NAN, |pt| pt.tau);
    ((lo, hi), peak)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact curve of N = 1e-3 and K = 1e-5 on 12 octaves of 2^16 samples at 1 Hz.
    fn curve(scale: f64) -> ([CurvePoint; 12], OctaveCovariance) {
        let m: [u64; 12] = core::array::from_fn(|i| 1u64 << i);
        let points = m.map(|m| {
            let tau = m as f64;
            CurvePoint {
                tau,
                avar: scale * (1e-6 / tau + 1e-10 * tau / 3.0),
                edf: 100.0,
            }
        });
        (points, OctaveCovariance::new(1 << 16, 1.0, &m).unwrap())
    }

    #[test]
    fn the_exact_curve_gives_its_terms_back() {
        let (points, cov) = curve(1.0);
        let f = fit(&points, &cov).unwrap();
        let n = f.term(Term::WhiteNoise);
        let k = f.term(Term::RandomWalk);
        assert!(libm::fabs(n.value - 1e-3) < 1e-9, "N {}", n.value);
        assert!(libm::fabs(k.value - 1e-5) < 1e-10, "K {}", k.value);
        assert!(n.significant && k.significant);
        assert!(!f.term(Term::Quantisation).significant);
        // N leads from the first point, K at the end.
        assert_eq!(n.tau_range.0, 1.0);
        assert_eq!(k.tau_range.1, 2048.0);
        assert!(n.tau_range.1 < k.tau_range.0);
    }

    #[test]
    fn too_few_points_and_no_noise_are_refused() {
        let (points, cov) = curve(1.0);
        let two = OctaveCovariance::new(1 << 16, 1.0, &[1, 2]).unwrap();
        assert_eq!(
            fit(&points[..2], &two),
            Err(FitError::TooFewPoints {
                count: 2,
                needed: MIN_POINTS
            })
        );
        let (zero, _) = curve(0.0);
        assert_eq!(fit(&zero, &cov), Err(FitError::NoNoise));
        assert_eq!(fit(&points[..6], &cov), Err(FitError::CovarianceMismatch));
    }
}
