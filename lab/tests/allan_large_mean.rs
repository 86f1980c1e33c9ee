//! A rate record whose mean is 10⁶ times its noise gives the same Allan
//! deviation as the zero-mean record: the accumulator subtracts an offset
//! (the mean of the first 4096 samples, as `triad allan` does) before it
//! integrates.

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_sim::effects::rng::Rng;

const N: usize = 1 << 20;
const SIGMA: f64 = 1e-3;

fn curve(y: &[f64], offset: f64) -> Vec<f64> {
    let mut acc = OctaveAccumulator::new(vec![0.0; N.next_power_of_two()], offset).unwrap();
    for &v in y {
        acc.push(v);
    }
    acc.results().map(|r| r.overlapping.sqrt()).collect()
}

#[test]
fn a_mean_a_million_times_the_noise_changes_no_deviation_beyond_1e_9() {
    let mut rng = Rng::from_seed(5);
    let noise: Vec<f64> = (0..N).map(|_| SIGMA * rng.gaussian()).collect();
    let bias = 1e6 * SIGMA;
    let biased: Vec<f64> = noise.iter().map(|n| bias + n).collect();
    let reference = curve(&noise, 0.0);
    let offset = biased[..4096].iter().sum::<f64>() / 4096.0;
    let shifted = curve(&biased, offset);
    assert_eq!(reference.len(), 20, "octaves m = 1 … 2^19");
    // Bound: forming bias + n rounds n by ulp(10⁶σ)/2 ≈ 1.1e-10·σ, a white
    // error 1e-10 of the noise; it changes σ²(τ) by ≈ 2·1e-10/√terms
    // relative, far below 1e-9. The accumulator adds at most a few ulps of
    // |S| (≈ √N·σ) per stored sum: also far below.
    for (i, (a, b)) in reference.iter().zip(&shifted).enumerate() {
        let rel = (a - b).abs() / a;
        assert!(rel < 1e-9, "m = 2^{i}: relative difference {rel:e}");
    }
}

#[test]
fn without_the_offset_the_same_record_loses_digits() {
    // The reason for the offset: integrating 10⁶σ per sample makes S reach
    // 10⁶σ·N ≈ 10⁹, whose ulp (1.2e-7) is 10⁻⁴ of the m = 1 difference.
    let mut rng = Rng::from_seed(5);
    let noise: Vec<f64> = (0..N).map(|_| SIGMA * rng.gaussian()).collect();
    let biased: Vec<f64> = noise.iter().map(|n| 1e6 * SIGMA + n).collect();
    let reference = curve(&noise, 0.0);
    let naive = curve(&biased, 0.0);
    let rel = (reference[0] - naive[0]).abs() / reference[0];
    assert!(rel > 1e-9, "relative difference {rel:e}");
}
