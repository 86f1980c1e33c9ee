//! First-order Gauss–Markov bias: exact discretisation against theory across
//! αTs from 1e-9 to 1e2, and the numerics of the coefficients from 1e-12 to 1e3.
//!
//! Statistical tolerances are 5 standard errors (SE) of the estimator, with
//! the SE derived from the sample size in each test: a correct
//! implementation fails with probability below 1e-6 per check, while a wrong
//! formula (φ vs φ², a missing expm1, a wrong drive variance) moves the
//! estimate by tens of SE. The seeds are fixed, so the tests are deterministic.

use triad_sim::effects::gauss_markov::{discretisation, GaussMarkov};
use triad_sim::effects::rng::Rng;

const SIGMA: f64 = 2.0;

/// Ensemble of M processes, each with its own generator.
fn ensemble(m: usize, alpha_ts: f64, initial: f64, seed: u64) -> Vec<(GaussMarkov, Rng)> {
    (0..m)
        .map(|i| {
            let rng = Rng::from_seed(seed.wrapping_mul(1_000_003).wrapping_add(i as u64));
            (GaussMarkov::new(SIGMA, 1.0 / alpha_ts, 1.0, initial), rng)
        })
        .collect()
}

fn advance(e: &mut [(GaussMarkov, Rng)], steps: usize) -> Vec<f64> {
    e.iter_mut()
        .map(|(gm, rng)| {
            for _ in 0..steps {
                gm.step(rng);
            }
            gm.state()
        })
        .collect()
}

#[test]
fn variance_growth_and_autocorrelation_match_theory_across_alpha_ts() {
    // From μ₀ = 0, after K steps Var(μ_K) = σ²(1 − e^(−2αTsK)); the zero-mean
    // estimator s² = Σμ²/M has SE Var·√(2/M). Then after L more steps
    // μ_{K+L} = ρ μ_K + e with ρ = e^(−αTsL), e independent of μ_K with
    // variance v_e = σ²(1 − ρ²); the regression slope β̂ = Σμ_Kμ_{K+L}/Σμ_K²
    // has SE √(v_e/Σμ_K²). K and L are chosen so αTsK ≈ 0.5 and αTsL ≈ 0.7
    // where that fits in 1000 steps; at αTs = 1e-9 the process is a random
    // walk over any feasible run, and the growth of the variance (2σ²αTsK)
    // is what tests the drive there.
    let m = 2000;
    for (n, &x) in [1e-9f64, 1e-6, 1e-3, 1e-1, 1.0, 10.0, 100.0]
        .iter()
        .enumerate()
    {
        let k = ((0.5 / x).round() as usize).clamp(1, 1000);
        let l = ((0.7 / x).round() as usize).clamp(1, 1000);
        let mut e = ensemble(m, x, 0.0, 100 + n as u64);
        let mu_k = advance(&mut e, k);
        let mu_kl = advance(&mut e, l);

        let var_k = SIGMA * SIGMA * -f64::exp_m1(-2.0 * x * k as f64);
        let s2 = mu_k.iter().map(|v| v * v).sum::<f64>() / m as f64;
        let se = var_k * (2.0 / m as f64).sqrt();
        assert!(
            (s2 - var_k).abs() < 5.0 * se,
            "αTs = {x}: Var(μ_{k}) = {s2:e}, theory {var_k:e} ± {:e}",
            5.0 * se
        );

        let rho = (-x * l as f64).exp();
        let sxx: f64 = mu_k.iter().map(|v| v * v).sum();
        let sxy: f64 = mu_k.iter().zip(&mu_kl).map(|(a, b)| a * b).sum();
        let beta = sxy / sxx;
        let v_e = SIGMA * SIGMA * -f64::exp_m1(-2.0 * x * l as f64);
        let se_beta = (v_e / sxx).sqrt();
        assert!(
            (beta - rho).abs() < 5.0 * se_beta,
            "αTs = {x}: correlation over {l} steps {beta}, theory {rho} ± {}",
            5.0 * se_beta
        );
    }
}

#[test]
fn stationary_variance_and_autocorrelation_from_one_long_run() {
    // One run of N = 200 000 samples started stationary. For an AR(1) process
    // with coefficient φ the sample variance has SE σ²·√((2/N)(1+φ²)/(1−φ²))
    // and a sample autocorrelation at lag k has SE at most
    // √((1/N)(1+φ²)/(1−φ²)) (Bartlett's formula), so both tolerances are 5 of
    // those SE. The lag k ≈ 1/(αTs) puts the theoretical σ²e^(−α|τ|) at e^(−1).
    let n = 200_000;
    for (i, &x) in [1e-2f64, 1e-1, 1.0, 10.0, 100.0].iter().enumerate() {
        let mut rng = Rng::from_seed(900 + i as u64);
        let mut gm = GaussMarkov::new_stationary(SIGMA, 1.0 / x, 1.0, &mut rng);
        let series: Vec<f64> = (0..n).map(|_| gm.step(&mut rng)).collect();
        let phi = (-x).exp();
        let inflation = (1.0 + phi * phi) / (1.0 - phi * phi);

        let mean = series.iter().sum::<f64>() / n as f64;
        let var = series.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n as f64;
        let se_var = SIGMA * SIGMA * (2.0 / n as f64 * inflation).sqrt();
        assert!(
            (var - SIGMA * SIGMA).abs() < 5.0 * se_var,
            "αTs = {x}: stationary variance {var}, theory {} ± {}",
            SIGMA * SIGMA,
            5.0 * se_var
        );

        let se_r = (inflation / n as f64).sqrt();
        for lag in [1usize, ((1.0 / x).round() as usize).max(1)] {
            let cov = series[..n - lag]
                .iter()
                .zip(&series[lag..])
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum::<f64>()
                / (n - lag) as f64;
            let r = cov / var;
            let theory = (-x * lag as f64).exp();
            assert!(
                (r - theory).abs() < 5.0 * se_r,
                "αTs = {x}: autocorrelation at lag {lag} = {r}, theory e^(−α|τ|) = {theory} ± {}",
                5.0 * se_r
            );
        }
    }
}

#[test]
fn mean_decays_as_exp_minus_alpha_t() {
    // From μ₀ = 3σ: E[μ_k] = μ₀e^(−αTs·k) and Var(μ_k) = σ²(1 − e^(−2αTs·k)),
    // so the ensemble mean of M has SE σ√(1 − e^(−2αTs·k))/√M; 5 SE bound.
    let m = 2000;
    let x = 1e-2;
    let mu0 = 3.0 * SIGMA;
    let mut e = ensemble(m, x, mu0, 7);
    let mut done = 0;
    for k in [10usize, 50, 100, 300] {
        let states = advance(&mut e, k - done);
        done = k;
        let mean = states.iter().sum::<f64>() / m as f64;
        let theory = mu0 * (-x * k as f64).exp();
        let se = SIGMA * (-f64::exp_m1(-2.0 * x * k as f64)).sqrt() / (m as f64).sqrt();
        assert!(
            (mean - theory).abs() < 5.0 * se,
            "step {k}: mean {mean}, theory {theory} ± {}",
            5.0 * se
        );
    }
}

#[test]
fn coefficients_keep_full_precision_at_alpha_ts_1e_minus_12() {
    // Taylor series: e^(−x) − 1 = −x + x²/2 − …, 1 − e^(−2x) = 2x − 2x² + …;
    // at x = 1e-12 the next terms are 1e-24 relative, so the series is exact
    // to f64 precision. 1 − exp(−2x) computed naively keeps only ~4 digits
    // (its relative error is ~1e-4 here), so a 1e-14 bound tells them apart.
    let x = 1e-12;
    let (pm1, drive) = discretisation(x);
    let pm1_series = -x + x * x / 2.0;
    let drive_series = 2.0 * x - 2.0 * x * x;
    assert!(
        ((pm1 - pm1_series) / pm1_series).abs() < 1e-14,
        "φ−1 = {pm1:e}"
    );
    assert!(
        ((drive - drive_series) / drive_series).abs() < 1e-14,
        "1−φ² = {drive:e}"
    );
    let naive = 1.0 - (-2.0 * x).exp();
    assert!(
        ((naive - drive_series) / drive_series).abs() > 1e-6,
        "the naive form should lose digits here"
    );
}

#[test]
fn coefficients_are_clean_at_alpha_ts_1e3() {
    // e^(−1000) underflows to 0: φ = 0 and the drive carries the whole
    // stationary variance; each sample is then white with variance σ².
    let (pm1, drive) = discretisation(1e3);
    assert_eq!(pm1, -1.0);
    assert_eq!(drive, 1.0);
    let gm = GaussMarkov::new(SIGMA, 1e-3, 1.0, 5.0);
    assert_eq!(gm.drive_sd(), SIGMA);
    let mut rng = Rng::from_seed(1);
    let mut gm = gm;
    let v = gm.step(&mut rng);
    assert!(v.is_finite() && v.abs() < 10.0 * SIGMA);
}
