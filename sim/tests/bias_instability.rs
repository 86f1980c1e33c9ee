//! Bias instability as a sum of Gauss–Markov terms: the analytic Allan floor
//! is within ±1 % of 0.664·B over the band, its fall outside the band is
//! what the module documents, and the simulated process has the analytic
//! Allan deviation at every τ = m·Ts, τ = Ts included (no aliasing).

use triad_sim::effects::averaged_gauss_markov::AveragedGaussMarkov;
use triad_sim::effects::bias_instability::{
    BiasInstability, BiasInstabilityParams, FLICKER_FLOOR_FACTOR,
};
use triad_sim::effects::gauss_markov::allan_variance;
use triad_sim::effects::rng::Rng;

#[test]
fn flicker_floor_factor_is_sqrt_2_ln2_over_pi() {
    assert!(
        (FLICKER_FLOOR_FACTOR - (2.0 * 2f64.ln() / core::f64::consts::PI).sqrt()).abs() < 1e-15
    );
}

fn params(tau_min: f64, tau_max: f64, terms: u8) -> BiasInstabilityParams {
    BiasInstabilityParams {
        b: 1.0,
        tau_min,
        tau_max,
        terms,
    }
}

/// The worst deviation from 0.664·B over the band, as a fraction.
fn worst(p: &BiasInstabilityParams) -> f64 {
    let (lo, hi) = p.flatness();
    (1.0 - lo).max(hi - 1.0)
}

#[test]
fn the_floor_is_within_one_percent_over_the_band() {
    // The default and the bands the tests use: a term per 0.85 decade or
    // closer is within ±0.5 % of 0.664·B from τ_min to τ_max; one per
    // decade within ±1.3 % (the module comment's figures: the ±1 % band
    // needs the closer spacing).
    let default = BiasInstabilityParams::with_default_band(1.0);
    assert!(worst(&default) < 0.01, "the ±1 % band of the default");
    for (p, bound) in [
        (default, 0.004),
        (params(10.0, 1000.0, 5), 0.005),
        (params(0.1, 1e6, 12), 0.005),
        (params(1.0, 1e4, 9), 0.005),
        (params(1.0, 100.0, 4), 0.013),
        (params(0.1, 1e6, 9), 0.013),
    ] {
        let w = worst(&p);
        println!(
            "band {} … {} s, {} terms: worst deviation {:.3} %",
            p.tau_min,
            p.tau_max,
            p.terms,
            100.0 * w
        );
        assert!(w < bound, "{p:?}: {w}");
    }
}

#[test]
fn outside_the_band_the_floor_falls_as_documented() {
    // Band 1 s … 10⁴ s, 7 terms (the figures are relative to the band's ends).
    let p = params(1.0, 1e4, 7);
    let ratio = |tau: f64| p.allan_deviation(tau) / FLICKER_FLOOR_FACTOR;
    for (tau, documented) in [
        (0.5, 0.988),
        (0.25, 0.926),
        (0.1, 0.738),
        (2e4, 0.977),
        (4e4, 0.915),
        (1e5, 0.719),
    ] {
        let r = ratio(tau);
        println!("tau {tau} s: {r:.4} of 0.664 B");
        assert!((r - documented).abs() < 0.001, "τ = {tau}: {r}");
    }
    // From τ_min/100 down, √τ: a factor 10 in τ is √10 in σ (within 1 %);
    // from 1000·τ_max up, 1/√τ.
    let fall = ratio(1e-3) / ratio(1e-4);
    assert!((fall / 10f64.sqrt() - 1.0).abs() < 0.01, "{fall}");
    let rise = ratio(1e7) / ratio(1e8);
    assert!((rise / 10f64.sqrt() - 1.0).abs() < 0.01, "{rise}");
    // Nowhere above the floor by more than the in-band ripple.
    for i in 0..=60 {
        let tau = 1e-2 * 10f64.powf(i as f64 / 10.0);
        assert!(ratio(tau) < 1.004, "τ = {tau}: {}", ratio(tau));
    }
}

#[test]
fn more_terms_flatten_the_floor() {
    let spread = |terms| worst(&params(1.0, 1e4, terms));
    assert!(spread(3) > 0.1, "3 terms over 5 decades make humps");
    assert!(spread(5) > spread(7));
    assert!(spread(7) < 0.005);
}

#[test]
fn terms_packed_too_closely_take_the_non_negative_fit() {
    // 16 terms over one decade: the least-squares variances alternate in
    // sign; the non-negative fit's are all positive and still flat.
    let p = params(1.0, 10.0, 16);
    let q = p.term_variances();
    assert!(q.iter().all(|&v| v > 0.0), "{q:?}");
    println!(
        "16 terms over 1 … 10 s: worst deviation {:.3} %",
        100.0 * worst(&p)
    );
    assert!(worst(&p) < 0.01, "{}", worst(&p));
}

/// The overlapping Allan variance of `y` at m = 1, 2, 4, … up to `octaves`.
fn oavar(y: &[f64], octaves: u32) -> Vec<f64> {
    let mut s = vec![0.0; y.len() + 1];
    for (i, v) in y.iter().enumerate() {
        s[i + 1] = s[i] + v;
    }
    (0..octaves)
        .map(|k| {
            let m = 1usize << k;
            let terms = y.len() + 1 - 2 * m;
            let sum: f64 = (0..terms)
                .map(|j| (s[j + 2 * m] - 2.0 * s[j + m] + s[j]).powi(2))
                .sum();
            sum / (2.0 * (m * m) as f64 * terms as f64)
        })
        .collect()
}

#[test]
fn an_averaged_term_faster_than_the_sample_period_does_not_alias() {
    // Tc = Ts/20: a point sample would have variance σ² (white noise of
    // density σ·√Ts); the mean over the period has the analytic Allan
    // variance 2σ²Tc/τ at τ = Ts: 0.1·σ² here.
    let (sigma, tc, ts) = (1.0, 0.05, 1.0);
    let mut rng = Rng::from_seed(3);
    let mut gm = AveragedGaussMarkov::new_stationary(sigma, tc, ts, &mut rng);
    let y: Vec<f64> = (0..1 << 16).map(|_| gm.step(&mut rng)).collect();
    let avar = oavar(&y, 1)[0];
    let theory = allan_variance(sigma * sigma, tc, ts);
    // White at this τ: relative SE of the overlapping estimate √(2/N) < 1 %; 5 % is > 5 SE.
    assert!((avar / theory - 1.0).abs() < 0.05, "{avar} vs {theory}");
    assert!(avar < 0.2 * sigma * sigma, "{avar}: aliased");
}

#[test]
fn the_simulated_floor_has_the_analytic_allan_deviation_at_every_octave() {
    // The default band (0.01 s … 10⁵ s) at 4 Hz: its fastest terms (Tc
    // from 1.7 ms) are far shorter than Ts = 0.25 s, the case that aliases
    // into white noise when terms are point samples. 64 independent records
    // of 2^17 samples (9 h each); at each octave τ = Ts … 2^9·Ts the mean of
    // their Allan variances is compared with the analytic one, within 4
    // standard errors of that mean (from the records' spread: 0.2 % at
    // τ = Ts, 4 % at 2^9·Ts). Measured: worst 1.6 % (at 128 s, inside its
    // 4.2 %), 0.2 % or less up to 32 s; 0.8 s in a debug build.
    let start = std::time::Instant::now();
    let p = BiasInstabilityParams::with_default_band(1.0);
    let (ts, runs, octaves) = (0.25, 64u64, 10u32);
    let mut sums = vec![(0.0, 0.0); octaves as usize];
    for seed in 0..runs {
        let mut rng = Rng::from_seed(100 + seed);
        let mut bi = BiasInstability::new(&p, ts, &mut rng);
        let y: Vec<f64> = (0..1 << 17).map(|_| bi.step(&mut rng)).collect();
        for (k, v) in oavar(&y, octaves).into_iter().enumerate() {
            sums[k].0 += v;
            sums[k].1 += v * v;
        }
    }
    let mut worst: f64 = 0.0;
    for (k, (s, s2)) in sums.iter().enumerate() {
        let tau = ts * (1u64 << k) as f64;
        let mean = s / runs as f64;
        let sd =
            ((s2 / runs as f64 - mean * mean).max(0.0) * runs as f64 / (runs - 1) as f64).sqrt();
        let se = sd / (runs as f64).sqrt();
        let theory = p.allan_deviation(tau).powi(2);
        let dev = mean / theory - 1.0;
        worst = worst.max(dev.abs());
        println!(
            "tau {tau:8.2} s: avar/analytic − 1 = {:+.2} % (4 SE {:.2} %)",
            100.0 * dev,
            400.0 * se / theory
        );
        assert!(
            (mean - theory).abs() <= 4.0 * se,
            "τ = {tau}: {mean} vs {theory} ± {se}"
        );
    }
    println!(
        "worst |avar/analytic − 1| {:.2} %; {:.1} s",
        100.0 * worst,
        start.elapsed().as_secs_f64()
    );
}
