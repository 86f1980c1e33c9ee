//! A column's curve: the Allan variance at each τ (octaves from the
//! streaming accumulator, or every m on the record held in memory), each
//! point with the noise type its local slope names, its equivalent degrees
//! of freedom and its confidence interval.

use triad_lab::allan::direct;
use triad_lab::allan::edf::{self, NoiseType};

use super::octave_blocks::{OctaveBlocks, StridedBlocks};
use crate::plumbing::progress::{Progress, Unit};

/// One point of a column's curve.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// Averaging factor.
    pub m: u64,
    /// τ, seconds.
    pub tau: f64,
    /// Overlapping Allan variance.
    pub avar: f64,
    /// Non-overlapping Allan variance (NaN when none).
    pub avar_non_overlapping: f64,
    /// Second differences in the overlapping estimate.
    pub terms: u64,
    /// Samples between its terms: 1 fully overlapping, m/M strided (`triad_lab::allan::strided`).
    pub stride: u64,
    /// Noise type assumed for the EDF.
    pub noise: NoiseType,
    /// Equivalent degrees of freedom.
    pub edf: f64,
    /// Confidence interval of the deviation.
    pub ci: (f64, f64),
}

/// A point before its interval: the estimates alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawPoint {
    /// Averaging factor.
    pub m: u64,
    /// τ, seconds.
    pub tau: f64,
    /// Overlapping Allan variance.
    pub avar: f64,
    /// Non-overlapping Allan variance (NaN when none).
    pub avar_non_overlapping: f64,
    /// Second differences in the overlapping estimate.
    pub terms: u64,
    /// Samples between its terms (1: fully overlapping).
    pub stride: u64,
}

/// The octave points of a streamed column, m ≤ `max_m`: the fully
/// overlapping ones of `acc`, then the strided ones of `above`.
pub fn octaves(
    acc: &OctaveBlocks,
    above: &[StridedBlocks],
    rate: f64,
    max_m: u64,
) -> Vec<RawPoint> {
    let full = acc.results().map(|r| (r, 1));
    let strided = above
        .iter()
        .map_while(|o| o.result().map(|r| (r, o.stride())));
    full.chain(strided)
        .filter(|(r, _)| r.m <= max_m)
        .map(|(r, stride)| RawPoint {
            m: r.m,
            tau: r.m as f64 / rate,
            avar: r.overlapping,
            avar_non_overlapping: r.non_overlapping,
            terms: r.overlapping_terms,
            stride,
        })
        .collect()
}

/// Every m from 1 to min(N/2, max_m) on the record `y` held in memory
/// (`offset` subtracted from each sample).
pub fn every_tau(y: &[f64], offset: f64, rate: f64, max_m: u64) -> Vec<RawPoint> {
    let mut s = vec![0.0; y.len() + 1];
    direct::cumulative_sums(y, offset, &mut s);
    let top = (y.len() as u64 / 2).min(max_m);
    // Each τ costs N: the work is top·N, shown once past ~1e8.
    let progress = Progress::new(top, 100_000_000 / (y.len() as u64).max(1), Unit::Taus);
    let points = (1..=top)
        .filter_map(|m| {
            progress.update(m);
            let (avar, terms) = direct::overlapping(&s, m as usize)?;
            let non = direct::non_overlapping(&s, m as usize).map_or(f64::NAN, |x| x.0);
            Some(RawPoint {
                m,
                tau: m as f64 / rate,
                avar,
                avar_non_overlapping: non,
                terms,
                stride: 1,
            })
        })
        .collect();
    progress.finish();
    points
}

/// The local log-log slope of σ² at each point (from the points nearest τ/2
/// and 2τ, one-sided at the ends), the noise type it names, the EDF (capped
/// at white FM's, see `edf_conservative`) and the interval at `level`.
pub fn with_intervals(raw: &[RawPoint], samples: u64, level: f64) -> Vec<Point> {
    let taus: Vec<f64> = raw.iter().map(|p| p.tau).collect();
    let avars: Vec<f64> = raw.iter().map(|p| p.avar).collect();
    raw.iter()
        .enumerate()
        .map(|(i, p)| {
            let (noise, nu) = edf::local_edf(&taus, &avars, i, p.m, samples);
            Point {
                m: p.m,
                tau: p.tau,
                avar: p.avar,
                avar_non_overlapping: p.avar_non_overlapping,
                terms: p.terms,
                stride: p.stride,
                noise,
                edf: nu,
                ci: edf::deviation_interval(p.avar, nu, level),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(m: u64, avar: f64) -> RawPoint {
        RawPoint {
            m,
            tau: m as f64,
            avar,
            avar_non_overlapping: f64::NAN,
            terms: 100,
            stride: 1,
        }
    }

    #[test]
    fn the_slope_names_the_noise() {
        // σ² ∝ 1/τ: white noise; σ² ∝ τ: random walk.
        let white: Vec<RawPoint> = [1, 2, 4, 8].map(|m| raw(m, 1.0 / m as f64)).to_vec();
        let walk: Vec<RawPoint> = [1, 2, 4, 8].map(|m| raw(m, m as f64)).to_vec();
        for p in with_intervals(&white, 1000, 0.68) {
            assert_eq!(p.noise, NoiseType::from_slope(-1.0));
            assert!(p.ci.0 < p.avar.sqrt() && p.avar.sqrt() < p.ci.1);
        }
        for p in with_intervals(&walk, 1000, 0.68) {
            assert_eq!(p.noise, NoiseType::from_slope(1.0));
        }
        assert_ne!(NoiseType::from_slope(-1.0), NoiseType::from_slope(1.0));
    }

    #[test]
    fn every_tau_matches_the_definition() {
        let y: Vec<f64> = (0..64).map(|i| ((i * 37 % 11) as f64) - 5.0).collect();
        let points = every_tau(&y, 0.0, 2.0, 100);
        assert_eq!(points.len(), 32);
        for p in [&points[0], &points[4], &points[31]] {
            let m = p.m as usize;
            let avg = |j: usize| y[j..j + m].iter().sum::<f64>() / m as f64;
            let n = y.len() - 2 * m + 1;
            let s: f64 = (0..n).map(|j| (avg(j + m) - avg(j)).powi(2)).sum();
            let by_definition = s / (2.0 * n as f64);
            assert!((p.avar - by_definition).abs() <= 1e-12 * by_definition);
            assert_eq!(p.tau, p.m as f64 / 2.0);
        }
        assert_eq!(every_tau(&y, 0.0, 2.0, 3).len(), 3);
    }
}
