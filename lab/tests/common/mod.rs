//! What the Allan tests share: a simulated static record and its octave
//! curve, as `triad allan` computes it.

// Each test crate that includes this module uses a part of it.
#![allow(dead_code)]

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_lab::allan::covariance::OctaveCovariance;
use triad_lab::allan::edf;
use triad_lab::allan::gls;
use triad_lab::allan::noise_terms::{CurvePoint, NoiseFit};
use triad_sim::motion::Motion;
use triad_sim::scenes::scene::Scene;
use triad_sim::scenes::simulator::Simulator;

/// The octave curve of one series: the mean of its first 4096 samples
/// subtracted (as `triad allan` does), the EDF from the local slope; and
/// each point's averaging factor m.
pub fn octave_points(y: &[f64], rate: f64) -> (Vec<CurvePoint>, Vec<u64>) {
    let first = &y[..y.len().min(4096)];
    let offset = first.iter().sum::<f64>() / first.len().max(1) as f64;
    let ring = (y.len() / 2).next_power_of_two().max(2) * 2;
    let mut acc = OctaveAccumulator::new(vec![0.0; ring], offset).unwrap();
    for &v in y {
        acc.push(v);
    }
    let n = acc.samples();
    let m: Vec<u64> = acc.results().map(|r| r.m).collect();
    let avars: Vec<f64> = acc.results().map(|r| r.overlapping).collect();
    let taus: Vec<f64> = m.iter().map(|&m| m as f64 / rate).collect();
    let points = (0..m.len())
        .map(|i| CurvePoint {
            tau: taus[i],
            avar: avars[i],
            edf: edf::local_edf(&taus, &avars, i, m[i], n).1,
        })
        .collect();
    (points, m)
}

/// The GLS fits of series' octave curves. The covariance of the octave
/// estimates depends on the record's length and rate, not on its values:
/// it is computed once per (length, rate) and kept for the next series.
#[derive(Default)]
pub struct OctaveFitter {
    covariance: Option<((usize, f64), OctaveCovariance)>,
}

impl OctaveFitter {
    /// The GLS fit of the octave curve of `y`, sampled at `rate`.
    pub fn fit(&mut self, y: &[f64], rate: f64) -> NoiseFit {
        let (points, m) = octave_points(y, rate);
        let key = (y.len(), rate);
        if self.covariance.as_ref().is_none_or(|(k, _)| *k != key) {
            let cov = OctaveCovariance::new(y.len() as u64, 1.0 / rate, &m).unwrap();
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
