//! What the Allan tests share: a simulated static record and its octave
//! curve, as `triad allan` computes it.

// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_lab::allan::covariance::OctaveCovariance;
use triad_lab::allan::edf;
use triad_lab::allan::gls;
use triad_lab::allan::noise_terms::{CurvePoint, NoiseFit};
use triad_lab::allan::strided::{StridedOctave, BASE};
use triad_sim::motion::Motion;
use triad_sim::scenes::scene::Scene;
use triad_sim::scenes::simulator::Simulator;

/// The octave curve of one series as `triad allan` computes it: the mean
/// of its first 4096 samples subtracted, fully overlapping estimates up to
/// m = `base` and strided ones above (terms every m/base samples,
/// `triad_lab::allan::strided`; `triad allan`'s base is [`BASE`]), the EDF
/// from the local slope; each point's averaging factor m and stride.
pub fn octave_points(y: &[f64], rate: f64, base: u64) -> (Vec<CurvePoint>, Vec<u64>, Vec<u64>) {
    let first = &y[..y.len().min(4096)];
    let offset = first.iter().sum::<f64>() / first.len().max(1) as f64;
    let top = (y.len() / 2).max(1).ilog2();
    let ring = (2u64 << top).min(2 * base) as usize;
    let mut acc = OctaveAccumulator::new(vec![0.0; ring], offset).unwrap();
    let mut above: Vec<StridedOctave<Vec<f64>>> = (base.ilog2() + 1..=top)
        .map(|o| StridedOctave::new(1 << o, base, vec![0.0; 2 * base as usize]).unwrap())
        .collect();
    for &v in y {
        acc.push(v);
        for o in above.iter_mut() {
            o.push(acc.samples(), acc.cumulative());
        }
    }
    let n = acc.samples();
    let results: Vec<_> = acc
        .results()
        .map(|r| (r, 1))
        .chain(above.iter().filter_map(|o| Some((o.result()?, o.stride()))))
        .collect();
    let m: Vec<u64> = results.iter().map(|(r, _)| r.m).collect();
    let strides: Vec<u64> = results.iter().map(|(_, d)| *d).collect();
    let avars: Vec<f64> = results.iter().map(|(r, _)| r.overlapping).collect();
    let taus: Vec<f64> = m.iter().map(|&m| m as f64 / rate).collect();
    let points = (0..m.len())
        .map(|i| CurvePoint {
            tau: taus[i],
            avar: avars[i],
            edf: edf::local_edf(&taus, &avars, i, m[i], n).1,
        })
        .collect();
    (points, m, strides)
}

/// The GLS fits of series' octave curves (strided above `base`, `triad
/// allan`'s [`BASE`] by default). The covariance of the octave estimates
/// depends on the record's length and rate, not on its values: it is
/// computed once per (length, rate) and kept for the next series.
pub struct OctaveFitter {
    base: u64,
    covariance: Option<((usize, f64), OctaveCovariance)>,
}

impl Default for OctaveFitter {
    fn default() -> Self {
        Self::with_base(BASE)
    }
}

impl OctaveFitter {
    /// A fitter whose octaves above `base` are strided.
    pub fn with_base(base: u64) -> Self {
        Self {
            base,
            covariance: None,
        }
    }

    /// The GLS fit of the octave curve of `y`, sampled at `rate`.
    pub fn fit(&mut self, y: &[f64], rate: f64) -> NoiseFit {
        let (points, m, strides) = octave_points(y, rate, self.base);
        let key = (y.len(), rate);
        if self.covariance.as_ref().is_none_or(|(k, _)| *k != key) {
            let cov =
                OctaveCovariance::with_strides(y.len() as u64, 1.0 / rate, &m, &strides).unwrap();
            self.covariance = Some((key, cov));
        }
        let (_, cov) = self.covariance.as_ref().unwrap();
        gls::fit(&points, cov).unwrap()
    }
}

/// `samples` of a static `scene`, gyro (or accel) axes as three series.
pub fn axes(scene: &Scene, gyro: bool, samples: usize, seed: u64) -> [Vec<f64>; 3] {
    let mut sim = Simulator::new(scene, seed).unwrap();
    let mut axes: [Vec<f64>; 3] = Default::default();
    for a in axes.iter_mut() {
        a.reserve(samples);
    }
    for _ in 0..samples {
        let m = sim.step().measured;
        let s = if gyro {
            m.angular_rate
        } else {
            m.specific_force
        };
        for (a, v) in axes.iter_mut().zip(s) {
            a.push(v);
        }
    }
    axes
}

/// A static scene at `rate`.
pub fn static_scene(rate: f64) -> Scene {
    Scene::new(rate, Motion::Static { attitude: [0.0; 3] })
}
