//! Equivalent degrees of freedom (EDF) of the overlapping Allan variance and
//! the χ² confidence intervals they give.
//!
//! EDF: the simple approximations of Howe, Allan & Barnes (1981), tabulated in
//! NIST SP 1065 §5.3 Table 5 (also Stein 1985, and allantools' `edf_simple`),
//! one formula per power-law noise type, with N the number of phase points
//! (rate samples + 1) and m the averaging factor. They need the dominant
//! noise type at each τ; it is read from the local log-log slope μ of σ²(τ)
//! (σ² ∝ τ^μ): μ ≈ −2 white PM (quantisation Q), −1 white FM (white noise
//! N), 0 flicker FM (bias instability B), +1 random-walk FM (K). A rate ramp
//! (μ = +2) has no formula in the table; the random-walk FM one is used
//! there (the nearest type, and the more conservative: fewer EDF).
//!
//! Interval (SP 1065 eq. 45): with ν EDF, ν·s²/σ² is χ²(ν), so the
//! two-sided interval of confidence c is
//! [ν s²/χ²_{(1+c)/2}(ν), ν s²/χ²_{(1−c)/2}(ν)].

use super::chi2;

/// The 1σ confidence level erf(1/√2), the default of the reports.
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

/// Power-law noise types of the rate signal ("frequency" in SP 1065).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseType {
    /// White phase (angle) noise: quantisation, σ² ∝ τ⁻².
    WhitePm,
    /// White frequency (rate) noise: angle random walk, σ² ∝ τ⁻¹.
    WhiteFm,
    /// Flicker frequency noise: bias instability, σ² flat.
    FlickerFm,
    /// Random-walk frequency noise: rate random walk, σ² ∝ τ (also used for a ramp).
    RandomWalkFm,
}

impl NoiseType {
    /// The noise type nearest to a local log-log slope μ of σ²(τ).
    pub fn from_slope(mu: f64) -> Self {
        if mu < -1.5 {
            NoiseType::WhitePm
        } else if mu < -0.5 {
            NoiseType::WhiteFm
        } else if mu < 0.5 {
            NoiseType::FlickerFm
        } else {
            NoiseType::RandomWalkFm
        }
    }

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            NoiseType::WhitePm => "white-pm",
            NoiseType::WhiteFm => "white-fm",
            NoiseType::FlickerFm => "flicker-fm",
            NoiseType::RandomWalkFm => "random-walk-fm",
        }
    }
}

/// EDF of the overlapping Allan variance at averaging factor `m` over
/// `samples` rate samples (N = samples + 1 phase points), SP 1065 Table 5.
/// Clamped to at least 1 (the formulas can fall below it where N ≈ 2m).
pub fn edf(noise: NoiseType, samples: u64, m: u64) -> f64 {
    table5(noise, samples, m)
}

/// The EDF used for intervals when the noise type comes from a measured
/// slope: [`edf`], but never more than the white-FM value. White PM is the
/// only type whose EDF exceeds white FM's (≈ N/2 against ≈ 2N/(3m)), and a
/// steep slope at long τ is far more often a chance fall of a few-term
/// estimate than quantisation noise: trusting it would give the noisiest
/// points the narrowest intervals (and the largest weights in the fit).
pub fn edf_conservative(noise: NoiseType, samples: u64, m: u64) -> f64 {
    table5(noise, samples, m).min(table5(NoiseType::WhiteFm, samples, m))
}

/// The noise type at point `i` of a curve (τ ascending in `taus`, Allan
/// variances in `avars`) and the point's EDF: the type is the one the
/// local log-log slope of σ² names, taken from the points nearest τ/2 and
/// 2τ (one-sided at the ends; white FM where it cannot be told: a single
/// point or a zero variance), and the EDF is [`edf_conservative`] of it at
/// averaging factor `m` over `samples` rate samples.
pub fn local_edf(taus: &[f64], avars: &[f64], i: usize, m: u64, samples: u64) -> (NoiseType, f64) {
    let tau = taus[i];
    let a = nearest(taus, tau / 2.0).min(i);
    let b = nearest(taus, tau * 2.0).max(i);
    let slope = if a != b && avars[a] > 0.0 && avars[b] > 0.0 {
        libm::log(avars[b] / avars[a]) / libm::log(taus[b] / taus[a])
    } else {
        -1.0
    };
    let noise = NoiseType::from_slope(slope);
    (noise, edf_conservative(noise, samples, m))
}

/// The index of the τ in `taus` (ascending, not empty) nearest `target`
/// on a log scale.
fn nearest(taus: &[f64], target: f64) -> usize {
    let i = taus.partition_point(|&t| t < target);
    if i == 0 {
        0
    } else if i >= taus.len() {
        taus.len() - 1
    } else if libm::fabs(libm::log(taus[i] / target)) < libm::fabs(libm::log(target / taus[i - 1]))
    {
        i
    } else {
        i - 1
    }
}

fn table5(noise: NoiseType, samples: u64, m: u64) -> f64 {
    let n = samples as f64 + 1.0;
    let m = m as f64;
    let v = match noise {
        NoiseType::WhitePm => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        NoiseType::WhiteFm => {
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * (4.0 * m * m)
                / (4.0 * m * m + 5.0)
        }
        NoiseType::FlickerFm => {
            if m == 1.0 {
                2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9)
            } else {
                5.0 * n * n / (4.0 * m * (n + 3.0 * m))
            }
        }
        NoiseType::RandomWalkFm => {
            (n - 2.0) / (m * (n - 3.0) * (n - 3.0))
                * ((n - 1.0) * (n - 1.0) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
        }
    };
    if v.is_finite() {
        v.max(1.0)
    } else {
        1.0
    }
}

/// The two-sided interval [low, high] of the true variance at confidence
/// `level` (0 < level < 1) around the estimate `variance` with `edf` EDF.
pub fn variance_interval(variance: f64, edf: f64, level: f64) -> (f64, f64) {
    let upper_q = chi2::quantile(0.5 * (1.0 + level), edf);
    let lower_q = chi2::quantile(0.5 * (1.0 - level), edf);
    (edf * variance / upper_q, edf * variance / lower_q)
}

/// The interval of the deviation: the square roots of [`variance_interval`].
pub fn deviation_interval(variance: f64, edf: f64, level: f64) -> (f64, f64) {
    let (lo, hi) = variance_interval(variance, edf, level);
    (libm::sqrt(lo), libm::sqrt(hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_is_taken_on_a_log_scale() {
        let taus = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(nearest(&taus, 0.1), 0);
        assert_eq!(nearest(&taus, 100.0), 3);
        assert_eq!(nearest(&taus, 2.7), 1); // ln(4/2.7) > ln(2.7/2)
        assert_eq!(nearest(&taus, 3.0), 2); // ln(4/3) < ln(3/2)
    }
}
