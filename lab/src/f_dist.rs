//! Fisher's F distribution: the ratio of two independent mean squares, as a
//! verification's residuals against a fit's.

use crate::student_t::regularized_beta;

/// P(F ≤ `f`) for F with `d1` and `d2` degrees of freedom.
pub fn cdf(f: f64, d1: f64, d2: f64) -> f64 {
    if f.is_nan() || d1 <= 0.0 || d2 <= 0.0 {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 0.0;
    }
    regularized_beta(d1 * f / (d1 * f + d2), d1 / 2.0, d2 / 2.0)
}

/// The `p` quantile of F(`d1`, `d2`), by bisection on the CDF (to 1e-12
/// relative).
pub fn quantile(p: f64, d1: f64, d2: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) || d1 <= 0.0 || d2 <= 0.0 {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while cdf(hi, d1, d2) < p {
        hi *= 2.0;
        if hi > 1e300 {
            return f64::INFINITY;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid, d1, d2) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_the_tables() {
        // F tables (99 % points): F(24, 20) = 2.8594, F(3, 10) = 6.5523,
        // F(1, 1) = 4052.18.
        assert!((quantile(0.99, 24.0, 20.0) - 2.8594).abs() < 1e-3);
        assert!((quantile(0.99, 3.0, 10.0) - 6.5523).abs() < 1e-3);
        assert!((quantile(0.99, 1.0, 1.0) / 4052.18 - 1.0).abs() < 1e-4);
        // F(1, ν) is t² with ν degrees of freedom.
        let t = 2.570_582; // t(0.975; 5)
        assert!((cdf(t * t, 1.0, 5.0) - 0.95).abs() < 1e-6);
    }
}
