//! Student's t distribution: how often ±k σ covers the truth when σ is
//! estimated with ν degrees of freedom (a fit's σ's are).
//!
//! P(|T| ≤ k) = 1 − I_x(ν/2, 1/2) with x = ν/(ν + k²), I the regularised
//! incomplete beta function, evaluated by its continued fraction (modified
//! Lentz), which converges fast for x below (a+1)/(a+b+2) and, through
//! I_x(a, b) = 1 − I_{1−x}(b, a), above it.

/// P(|T| ≤ `k`) for Student's t with `dof` degrees of freedom; NaN for
/// `dof` ≤ 0 (no σ without degrees of freedom).
pub fn coverage(k: f64, dof: f64) -> f64 {
    if dof.is_nan() || dof <= 0.0 || k.is_nan() {
        return f64::NAN;
    }
    if k <= 0.0 {
        return 0.0;
    }
    let x = dof / (dof + k * k);
    1.0 - regularized_beta(x, dof / 2.0, 0.5)
}

/// I_x(a, b), the regularised incomplete beta function, for 0 ≤ x ≤ 1.
pub fn regularized_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = libm::lgamma(a + b) - libm::lgamma(a) - libm::lgamma(b)
        + a * libm::log(x)
        + b * libm::log(1.0 - x);
    let front = libm::exp(ln_front);
    if x < (a + 1.0) / (a + b + 2.0) {
        front * continued_fraction(x, a, b) / a
    } else {
        1.0 - front * continued_fraction(1.0 - x, b, a) / b
    }
}

/// The continued fraction of I_x(a, b) (modified Lentz's method).
fn continued_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    const EPS: f64 = 1e-15;
    let mut c = 1.0;
    let mut d = 1.0 - (a + b) * x / (a + 1.0);
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=300 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        // Even step.
        let num = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
        d = 1.0 + num * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + num / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        h *= d * c;
        // Odd step.
        let num = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
        d = 1.0 + num * d;
        d = if d.abs() < TINY { TINY } else { d };
        c = 1.0 + num / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_matches_the_tables() {
        // ν = 1 is the Cauchy distribution: P(|T| ≤ k) = 2·atan(k)/π.
        for k in [0.5, 1.0, 2.0, 5.0] {
            let exact = 2.0 * libm::atan(k) / core::f64::consts::PI;
            assert!((coverage(k, 1.0) - exact).abs() < 1e-12, "k {k}");
        }
        // ν = 2: P(|T| ≤ k) = k / √(2 + k²).
        for k in [0.5, 2.0, 3.0] {
            let exact = k / libm::sqrt(2.0 + k * k);
            assert!((coverage(k, 2.0) - exact).abs() < 1e-12, "k {k}");
        }
        // Two-sided 95 % points of the t tables: t(0.975; 5) = 2.570582,
        // t(0.975; 30) = 2.042272.
        assert!((coverage(2.570_582, 5.0) - 0.95).abs() < 1e-6);
        assert!((coverage(2.042_272, 30.0) - 0.95).abs() < 1e-6);
        // Large ν tends to the normal: P(|Z| ≤ 2) = 0.954500.
        assert!((coverage(2.0, 1e6) - 0.954_500).abs() < 1e-5);
        assert!(coverage(2.0, 0.0).is_nan());
    }
}
