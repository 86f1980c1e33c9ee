//! The covariance of the octave Allan-variance estimates
//! (`triad_lab::allan::covariance`) against the one measured over many
//! simulated records of each noise type.
//!
//! Tolerances: over R records the sample standard deviation of an estimate
//! whose distribution is χ²-like with ν EDF has a relative standard error
//! ≈ √((2 + 12/ν)/(4R)) (kurtosis 3 + 12/ν), ≤ 4 % for ν ≥ 1 and R = 2000;
//! each standard deviation must be within 4 standard errors (16 %) and each
//! correlation within 0.1 of the prediction (standard error ≤ √(1/R)·(1+ρ²)…
//! ≈ 0.03 for the strongly non-Gaussian top octaves).

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_lab::allan::covariance::OctaveCovariance;
use triad_lab::allan::noise_terms::model_avar;
use triad_sim::effects::bias_instability::{BiasInstability, BiasInstabilityParams};
use triad_sim::effects::rng::Rng;

const SAMPLES: usize = 4096;
const RECORDS: usize = 2000;
const PERIOD: f64 = 0.5;

/// The octave estimates of one record.
fn octaves(y: &[f64]) -> Vec<f64> {
    let mut acc = OctaveAccumulator::new(vec![0.0; SAMPLES], 0.0).unwrap();
    for &v in y {
        acc.push(v);
    }
    acc.results().map(|r| r.overlapping).collect()
}

/// Measured and predicted covariances of the octave estimates of records
/// drawn by `draw`, for the model `c`.
/// Points whose mean is not within 5 % of the model's Allan variance are
/// skipped (the simulator's flicker is 1/f only over its band).
fn compare(name: &str, c: [f64; 5], mut draw: impl FnMut(&mut Rng, &mut [f64])) {
    let mut rng = Rng::from_seed(31);
    let mut y = vec![0.0; SAMPLES];
    let mut all: Vec<Vec<f64>> = Vec::with_capacity(RECORDS);
    for _ in 0..RECORDS {
        draw(&mut rng, &mut y);
        all.push(octaves(&y));
    }
    let p = all[0].len();
    let m: Vec<u64> = (0..p).map(|i| 1u64 << i).collect();
    let cov = OctaveCovariance::new(SAMPLES as u64, PERIOD, &m).unwrap();
    let mut v = vec![0.0; p * p];
    assert!(cov.matrix(&c, &mut v));
    let mean: Vec<f64> = (0..p)
        .map(|i| all.iter().map(|r| r[i]).sum::<f64>() / RECORDS as f64)
        .collect();
    let measured = |i: usize, j: usize| {
        all.iter()
            .map(|r| (r[i] - mean[i]) * (r[j] - mean[j]))
            .sum::<f64>()
            / (RECORDS - 1) as f64
    };
    let model = |i: usize| model_avar(&c, m[i] as f64 * PERIOD);
    let kept: Vec<usize> = (0..p)
        .filter(|&i| (mean[i] / model(i) - 1.0).abs() < 0.05)
        .collect();
    assert!(
        kept.len() >= 5,
        "{name}: only {} points follow the model",
        kept.len()
    );
    for (x, &i) in kept.iter().enumerate() {
        let (sd, predicted) = (measured(i, i).sqrt(), v[i * p + i].sqrt());
        println!(
            "{name} m {}: mean {:.4e}, sd measured {sd:.4e}, predicted {predicted:.4e}",
            m[i], mean[i]
        );
        assert!(
            (sd / predicted - 1.0).abs() < 0.16,
            "{name} m {}: sd {sd:e} vs {predicted:e}",
            m[i]
        );
        for &j in &kept[x + 1..] {
            let r_meas = measured(i, j) / (measured(i, i) * measured(j, j)).sqrt();
            let r_pred = v[i * p + j] / (v[i * p + i] * v[j * p + j]).sqrt();
            assert!(
                (r_meas - r_pred).abs() < 0.1,
                "{name} m {},{}: correlation {r_meas:.3} vs {r_pred:.3}",
                m[i],
                m[j]
            );
        }
    }
}

#[test]
fn white_noise() {
    // Rate samples of variance N²/τ₀.
    let n: f64 = 2.0;
    let sd = n / PERIOD.sqrt();
    compare("N", [0.0, n * n, 0.0, 0.0, 0.0], |rng, y| {
        y.iter_mut().for_each(|v| *v = sd * rng.gaussian())
    });
}

#[test]
fn white_phase_noise() {
    // Quantisation-like white phase: y_k = (x_{k+1} − x_k)/τ₀, x of variance Q².
    let q: f64 = 0.3;
    compare("Q", [q * q, 0.0, 0.0, 0.0, 0.0], |rng, y| {
        let mut x = q * rng.gaussian();
        for v in y.iter_mut() {
            let next = q * rng.gaussian();
            *v = (next - x) / PERIOD;
            x = next;
        }
    });
}

#[test]
fn random_walk_with_white_noise_and_a_ramp() {
    // The walk averaged over each sample (as the model's continuous K is):
    // its step and its within-sample part, plus white noise and a ramp.
    let (k, n, r): (f64, f64, f64) = (0.05, 0.2, 1e-3);
    compare("N+K+R", [0.0, n * n, 0.0, k * k, r * r], |rng, y| {
        let mut b = 0.0;
        for (i, v) in y.iter_mut().enumerate() {
            let step = k * PERIOD.sqrt() * rng.gaussian();
            // Mean of a Brownian bridge-free increment over the sample: half the step
            // plus an independent part of variance K²τ₀/12.
            let within = k * (PERIOD / 12.0).sqrt() * rng.gaussian();
            *v = b
                + 0.5 * step
                + within
                + n / PERIOD.sqrt() * rng.gaussian()
                + r * PERIOD * i as f64;
            b += step;
        }
    });
}

#[test]
fn flicker_noise() {
    // The simulator's flicker (a sum of Gauss–Markov terms) over a band
    // wider than the record's τ on both sides: 1/f to about ±2 % there.
    let params = BiasInstabilityParams {
        b: 1.0,
        tau_min: 0.1,
        tau_max: 1e5,
        terms: 14,
    };
    compare("B", [0.0, 0.0, 1.0, 0.0, 0.0], |rng, y| {
        let mut process = BiasInstability::new(&params, PERIOD, rng);
        y.iter_mut().for_each(|v| *v = process.step(rng));
    });
}
