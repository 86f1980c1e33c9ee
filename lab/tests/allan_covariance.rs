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
use triad_lab::allan::strided::{stride, StridedOctave};
use triad_sim::effects::bias_instability::{BiasInstability, BiasInstabilityParams};
use triad_sim::effects::rng::Rng;

const SAMPLES: usize = 4096;
const RECORDS: usize = 2000;
const PERIOD: f64 = 0.5;

/// Fully overlapping estimates up to m = FULL; above it, the strided ones
/// of `triad_lab::allan::strided` (an overlap ratio m/d of FULL, far below
/// `triad allan`'s 2^17: the O(d/m) error of the model is largest here).
const FULL: u64 = 32;

/// The octave estimates of one record: fully overlapping at every m, or
/// (`strided`) with the terms every m/FULL samples above FULL.
fn octaves(y: &[f64], strided: bool) -> Vec<f64> {
    let ring = if strided { 2 * FULL as usize } else { SAMPLES };
    let mut acc = OctaveAccumulator::new(vec![0.0; ring], 0.0).unwrap();
    let mut above: Vec<StridedOctave<Vec<f64>>> = if strided {
        factors()
            .into_iter()
            .filter(|&m| m > FULL)
            .map(|m| StridedOctave::new(m, FULL, vec![0.0; 2 * FULL as usize]).unwrap())
            .collect()
    } else {
        Vec::new()
    };
    for &v in y {
        acc.push(v);
        for o in above.iter_mut() {
            o.push(acc.samples(), acc.cumulative());
        }
    }
    acc.results()
        .chain(above.iter().filter_map(|o| o.result()))
        .map(|r| r.overlapping)
        .collect()
}

/// Every octave of a record of SAMPLES.
fn factors() -> Vec<u64> {
    (0..SAMPLES.ilog2()).map(|i| 1u64 << i).collect()
}

/// Measured and predicted covariances of the octave estimates (fully
/// overlapping, or `strided`) of records drawn by `draw`, for the model `c`.
/// Points whose mean is not within 5 % of the model's Allan variance are
/// skipped (the simulator's flicker is 1/f only over its band).
fn compare_estimates(
    name: &str,
    strided: bool,
    c: [f64; 5],
    mut draw: impl FnMut(&mut Rng, &mut [f64]),
) {
    let mut rng = Rng::from_seed(31);
    let mut y = vec![0.0; SAMPLES];
    let mut all: Vec<Vec<f64>> = Vec::with_capacity(RECORDS);
    for _ in 0..RECORDS {
        draw(&mut rng, &mut y);
        all.push(octaves(&y, strided));
    }
    let p = all[0].len();
    let m: Vec<u64> = (0..p).map(|i| 1u64 << i).collect();
    let base = if strided { FULL } else { SAMPLES as u64 };
    let d: Vec<u64> = m.iter().map(|&m| stride(m, base)).collect();
    let cov = OctaveCovariance::with_strides(SAMPLES as u64, PERIOD, &m, &d).unwrap();
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
    white(false);
}

#[test]
fn white_noise_strided() {
    white(true);
}

fn white(strided: bool) {
    // Rate samples of variance N²/τ₀.
    let n: f64 = 2.0;
    let sd = n / PERIOD.sqrt();
    compare_estimates("N", strided, [0.0, n * n, 0.0, 0.0, 0.0], |rng, y| {
        y.iter_mut().for_each(|v| *v = sd * rng.gaussian())
    });
}

#[test]
fn white_phase_noise() {
    white_phase(false);
}

#[test]
fn white_phase_noise_strided() {
    // Here the strides cost variance: a d-th of the terms carry Q.
    white_phase(true);
}

fn white_phase(strided: bool) {
    // Quantisation-like white phase: y_k = (x_{k+1} − x_k)/τ₀, x of variance Q².
    let q: f64 = 0.3;
    compare_estimates("Q", strided, [q * q, 0.0, 0.0, 0.0, 0.0], |rng, y| {
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
    walk_noise_ramp(false);
}

#[test]
fn random_walk_with_white_noise_and_a_ramp_strided() {
    walk_noise_ramp(true);
}

fn walk_noise_ramp(strided: bool) {
    // The walk averaged over each sample (as the model's continuous K is):
    // its step and its within-sample part, plus white noise and a ramp.
    let (k, n, r): (f64, f64, f64) = (0.05, 0.2, 1e-3);
    compare_estimates(
        "N+K+R",
        strided,
        [0.0, n * n, 0.0, k * k, r * r],
        |rng, y| {
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
        },
    );
}

#[test]
fn flicker_noise() {
    flicker(false);
}

#[test]
fn flicker_noise_strided() {
    flicker(true);
}

fn flicker(strided: bool) {
    // The simulator's flicker (a sum of Gauss–Markov terms) over a band
    // wider than the record's τ on both sides: 1/f to about ±2 % there.
    let params = BiasInstabilityParams {
        b: 1.0,
        tau_min: 0.1,
        tau_max: 1e5,
        terms: 14,
    };
    compare_estimates("B", strided, [0.0, 0.0, 1.0, 0.0, 0.0], |rng, y| {
        let mut process = BiasInstability::new(&params, PERIOD, rng);
        y.iter_mut().for_each(|v| *v = process.step(rng));
    });
}
