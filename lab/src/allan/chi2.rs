//! The χ² distribution: its CDF through the regularized lower incomplete
//! gamma function P(a, x), and its quantile by safeguarded Newton iteration.
//!
//! P(a, x) is evaluated by its power series for x < a + 1 and by the
//! continued fraction of Q = 1 − P (modified Lentz) otherwise (Abramowitz &
//! Stegun 6.5.29 and 6.5.31); both converge to f64 precision. Degrees of
//! freedom need not be integers (equivalent degrees of freedom are not).

/// Relative accuracy the series, the continued fraction and the quantile aim at.
const EPS: f64 = 1e-15;

/// Iteration cap of the series and the continued fraction.
const MAX_ITER: usize = 10_000;

/// The regularized lower incomplete gamma function P(a, x) = γ(a, x)/Γ(a),
/// for a > 0 and x ≥ 0 (NaN otherwise).
pub fn regularized_lower_gamma(a: f64, x: f64) -> f64 {
    if !(a > 0.0 && x >= 0.0 && a.is_finite()) {
        return f64::NAN;
    }
    if x == 0.0 {
        return 0.0;
    }
    if x.is_infinite() {
        return 1.0;
    }
    // ln(x^a e^{−x} / Γ(a)), the common prefactor.
    let log_prefactor = a * libm::log(x) - x - libm::lgamma(a);
    if x < a + 1.0 {
        // γ(a,x)/Γ(a) = e^{−x} x^a / Γ(a+1) · Σ x^n / ((a+1)…(a+n)).
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut ap = a;
        for _ in 0..MAX_ITER {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if libm::fabs(term) < libm::fabs(sum) * EPS {
                break;
            }
        }
        (sum * libm::exp(log_prefactor)).min(1.0)
    } else {
        // Q(a,x) = e^{−x} x^a / Γ(a) · 1/(x+1−a− 1·(1−a)/(x+3−a− 2·(2−a)/(x+5−a− …))).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..MAX_ITER {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if libm::fabs(d) < tiny {
                d = tiny;
            }
            c = b + an / c;
            if libm::fabs(c) < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if libm::fabs(delta - 1.0) < EPS {
                break;
            }
        }
        (1.0 - libm::exp(log_prefactor) * h).max(0.0)
    }
}

/// The χ² CDF with `k` degrees of freedom: P(k/2, x/2).
pub fn cdf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return if k > 0.0 { 0.0 } else { f64::NAN };
    }
    regularized_lower_gamma(k / 2.0, x / 2.0)
}

/// The χ² density with `k` degrees of freedom.
pub fn pdf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let h = k / 2.0;
    libm::exp((h - 1.0) * libm::log(x) - x / 2.0 - h * core::f64::consts::LN_2 - libm::lgamma(h))
}

/// The p-quantile of χ² with `k` degrees of freedom: the x with
/// CDF(x) = p, for 0 < p < 1 and k > 0 (NaN otherwise).
///
/// Bracketed first (doubling from k), then Newton steps on the CDF that fall
/// back to bisection whenever a step leaves the bracket; stops when the
/// bracket or the step is below 10⁻¹⁵ relative.
pub fn quantile(p: f64, k: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && k > 0.0 && k.is_finite()) {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (0.0f64, k.max(1.0));
    while cdf(hi, k) < p {
        lo = hi;
        hi *= 2.0;
        if !hi.is_finite() {
            return f64::NAN;
        }
    }
    let mut x = 0.5 * (lo + hi);
    for _ in 0..500 {
        let f = cdf(x, k) - p;
        if f == 0.0 {
            return x;
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let density = pdf(x, k);
        let newton = if density > 0.0 {
            x - f / density
        } else {
            f64::NAN
        };
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if libm::fabs(next - x) <= EPS * x || hi - lo <= EPS * hi {
            return next;
        }
        x = next;
    }
    x
}
