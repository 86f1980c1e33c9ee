//! The χ² quantile against printed table values, the EDF formulas of
//! NIST SP 1065 Table 5, and the coverage of the confidence intervals.

use triad_lab::allan::chi2;
use triad_lab::allan::edf::{self, NoiseType, ONE_SIGMA};

#[test]
fn chi2_quantile_matches_table_values() {
    // (p, k, value): NIST/SEMATECH e-Handbook §1.3.6.7.4 (upper-tail table,
    // 3 decimals) and Abramowitz & Stegun Table 26.8. Tolerance: half a unit
    // of the last printed digit.
    let table: [(f64, f64, f64, f64); 10] = [
        (0.975, 1.0, 5.024, 5e-4),
        (0.025, 1.0, 0.000982, 5e-7),
        (0.95, 10.0, 18.307, 5e-4),
        (0.05, 10.0, 3.940, 5e-4),
        (0.99, 30.0, 50.892, 5e-4),
        (0.01, 30.0, 14.953, 5e-4),
        (0.90, 100.0, 118.498, 5e-4),
        (0.10, 100.0, 82.358, 5e-4),
        (0.995, 5.0, 16.750, 5e-4),
        (0.005, 5.0, 0.412, 5e-4),
    ];
    for (p, k, value, tol) in table {
        let q = chi2::quantile(p, k);
        assert!(
            (q - value).abs() <= tol,
            "chi2 quantile p={p} k={k}: {q}, table {value}"
        );
    }
}

#[test]
fn chi2_quantile_with_two_dof_is_the_exponential_one() {
    // χ²(2) is exponential with mean 2: the quantile is −2 ln(1 − p) exactly;
    // the iteration stops at 1e-15 relative, so 1e-13 is a safe bound, plus
    // the conditioning near p = 1: the CDF is known to ≈ 2ε absolute, which
    // moves x by 2ε/pdf(x) (pdf = (1 − p)/2 here).
    for p in [1e-6f64, 0.01, 0.1587, 0.5, 0.8413, 0.99, 0.999_999] {
        let exact = -2.0 * (-p).ln_1p();
        let q = chi2::quantile(p, 2.0);
        let tol = 1e-13 * exact + 4.0 * f64::EPSILON / (0.5 * (1.0 - p));
        assert!((q - exact).abs() <= tol, "p={p}: {q} vs {exact}");
    }
}

#[test]
fn chi2_quantile_inverts_the_cdf_for_fractional_dof() {
    for k in [0.3, 1.7, 3.3, 12.5, 250.0, 5000.0] {
        for p in [0.001, 0.16, 0.5, 0.84, 0.999] {
            let q = chi2::quantile(p, k);
            // The prefactor x^a e^(−x)/Γ(a) is exp of a difference of terms
            // of size ≈ a·ln a (2·10⁴ at k = 5000): its rounding is
            // ≈ 2·10⁴·ε ≈ 5·10⁻¹², hence 1e-11 (1e-13 below k = 20).
            let tol = if k > 20.0 { 1e-11 } else { 1e-13 };
            let err = (chi2::cdf(q, k) - p).abs();
            assert!(err < tol, "k={k} p={p}: |cdf(q) − p| = {err:e}");
        }
    }
    assert!(chi2::quantile(0.0, 3.0).is_nan());
    assert!(chi2::quantile(0.5, -1.0).is_nan());
}

#[test]
fn edf_formulas_give_sp1065_values() {
    // White FM, N = 1025 phase points (1024 samples), m = 1:
    // [3·1024/2 − 2·1023/1025]·4/9 = (1536 − 1.99610)·4/9 = 681.7795.
    let v = edf::edf(NoiseType::WhiteFm, 1024, 1);
    assert!((v - 681.7795).abs() < 1e-3, "{v}");
    // Random-walk FM at m = 1: (N−2)/(N−3)²·((N−1)² − 3(N−1) + 4) ≈ N − 2 for large N.
    let v = edf::edf(NoiseType::RandomWalkFm, 100_000, 1);
    assert!((v - 100_000.0).abs() < 5.0, "{v}");
    // Flicker FM, m ≥ 2: 5N²/(4m(N + 3m)).
    let n = 10_001.0;
    let v = edf::edf(NoiseType::FlickerFm, 10_000, 16);
    assert!((v - 5.0 * n * n / (64.0 * (n + 48.0))).abs() < 1e-9 * v);
    // Fewer degrees of freedom at longer τ, never below 1.
    assert!(edf::edf(NoiseType::WhiteFm, 1000, 400) >= 1.0);
    assert!(edf::edf(NoiseType::WhiteFm, 1000, 8) < edf::edf(NoiseType::WhiteFm, 1000, 4));
}

#[test]
fn noise_type_follows_the_local_slope() {
    assert_eq!(NoiseType::from_slope(-2.0), NoiseType::WhitePm);
    assert_eq!(NoiseType::from_slope(-1.0), NoiseType::WhiteFm);
    assert_eq!(NoiseType::from_slope(0.1), NoiseType::FlickerFm);
    assert_eq!(NoiseType::from_slope(1.0), NoiseType::RandomWalkFm);
    assert_eq!(NoiseType::from_slope(2.0), NoiseType::RandomWalkFm);
}

#[test]
fn a_curve_point_takes_the_noise_type_of_its_neighbours_slope() {
    // Every τ from 1 to 8 s: white noise (σ² ∝ 1/τ) up to 4 s, a random
    // walk (σ² ∝ τ) from there. At τ = 3 the slope runs from the point
    // nearest 1.5 (1 or 2: 2, nearer on a log scale) to the one nearest 6.
    let taus: Vec<f64> = (1..=8).map(f64::from).collect();
    let avars: Vec<f64> = taus
        .iter()
        .map(|&t| if t <= 4.0 { 1.0 / t } else { t / 16.0 })
        .collect();
    let at = |i: usize| edf::local_edf(&taus, &avars, i, i as u64 + 1, 1000);
    // τ = 1: one-sided, 1 → 2, white FM.
    assert_eq!(at(0).0, NoiseType::WhiteFm);
    assert_eq!(at(0).1, edf::edf_conservative(NoiseType::WhiteFm, 1000, 1));
    // τ = 2: 1 → 4, still white FM.
    assert_eq!(at(1).0, NoiseType::WhiteFm);
    // τ = 3: 2 → 6, σ² from 1/2 to 3/8: slope ln(3/4)/ln 3 ≈ −0.26, flicker.
    assert_eq!(at(2).0, NoiseType::FlickerFm);
    // τ = 8: one-sided, 4 → 8, random walk.
    assert_eq!(at(7).0, NoiseType::RandomWalkFm);
    assert_eq!(
        at(7).1,
        edf::edf_conservative(NoiseType::RandomWalkFm, 1000, 8)
    );
    // A single point or a zero variance: the slope cannot be told, white FM.
    assert_eq!(
        edf::local_edf(&[1.0], &[0.5], 0, 1, 1000).0,
        NoiseType::WhiteFm
    );
    assert_eq!(
        edf::local_edf(&taus[..2], &[0.0, 1.0], 0, 1, 1000).0,
        NoiseType::WhiteFm
    );
}

#[test]
fn interval_brackets_the_estimate_and_narrows_with_edf() {
    let (lo, hi) = edf::deviation_interval(4.0, 10.0, ONE_SIGMA);
    assert!(lo < 2.0 && 2.0 < hi);
    let (lo2, hi2) = edf::deviation_interval(4.0, 1000.0, ONE_SIGMA);
    assert!(lo < lo2 && hi2 < hi);
    // For large ν the 1σ interval of σ is ≈ σ(1 ± 1/√(2ν)).
    let half = 0.5 * (hi2 - lo2) / 2.0;
    assert!(
        (half - 1.0 / (2.0f64 * 1000.0).sqrt()).abs() < 1e-3,
        "{half}"
    );
}

#[test]
fn one_sigma_intervals_cover_the_truth_about_68_percent_of_the_time() {
    // White noise of unit variance: 400 records of 4096 samples; at m = 16
    // the white-FM EDF is ≈ 383. The fraction of intervals that cover the
    // true σ = 1/√16 should be 0.683; with 400 trials its standard error is
    // √(0.683·0.317/400) = 0.023, so 0.683 ± 0.07 (3 s.e.).
    use triad_lab::allan::direct;
    use triad_sim::effects::rng::Rng;
    let mut rng = Rng::from_seed(11);
    let (n, m, trials) = (4096usize, 16usize, 400);
    let truth = 1.0 / (m as f64).sqrt();
    let mut covered = 0;
    let mut y = vec![0.0; n];
    let mut s = vec![0.0; n + 1];
    for _ in 0..trials {
        y.iter_mut().for_each(|v| *v = rng.gaussian());
        direct::cumulative_sums(&y, 0.0, &mut s);
        let (avar, _) = direct::overlapping(&s, m).unwrap();
        let nu = edf::edf(NoiseType::WhiteFm, n as u64, m as u64);
        let (lo, hi) = edf::deviation_interval(avar, nu, ONE_SIGMA);
        if lo <= truth && truth <= hi {
            covered += 1;
        }
    }
    let frac = covered as f64 / trials as f64;
    assert!((frac - ONE_SIGMA).abs() < 0.07, "coverage {frac}");
}
