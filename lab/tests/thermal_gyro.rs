//! The gyroscope's (I+Σ) against temperature (`calib_fit::fits::thermal_gyro`) on
//! synthetic hand-turned records (`calib_fit::hand_record`) of one unit at
//! three soaks, −10, 25 and 60 °C, its (I+Σ) following the simulator's
//! model (I+Σ)·diag(1 + s·ΔT) for both triads: recovery within 3σ, the
//! honesty of the σ's over many seeds, and the refusal of records that turn
//! at one temperature only.
#![allow(clippy::needless_range_loop)] // index form reads as the matrix formulas

use triad::model::matrix::{self, Mat3};
use triad_lab::calib_fit::fits::bias_polynomial::{self, BiasPolynomial, StaticMean};
use triad_lab::calib_fit::fits::rig_free::Record;
use triad_lab::calib_fit::fits::thermal_accel::{self, Terms, ThermalAccelFit};
use triad_lab::calib_fit::fits::thermal_coverage::coverage;
use triad_lab::calib_fit::fits::thermal_gyro::{self, Poses, ThermalGyroError, ThermalGyroFit};
use triad_lab::calib_fit::hand_record::{self, Script, TriadTruth, Unit};
use triad_lab::calib_fit::numerics::small3::{cholesky_upper, gram};
use triad_lab::calib_fit::static_segments::{self, Detector, Segment};
use triad_lab::student_t;
use triad_sim::effects::rng::Rng;

const G: f64 = 9.80665;
const FULL_SCALE: f64 = 2000.0 * core::f64::consts::PI / 180.0;
const SOAKS: [f64; 3] = [-10.0, 25.0, 60.0];

/// One triad of the unit: (I+Σ) and b at 25 °C, scale and bias per °C.
struct Thermal {
    m: Mat3,
    scale_per_c: [f64; 3],
    bias: [f64; 3],
    slope: [f64; 3],
    noise: f64,
}

impl Thermal {
    fn m_at(&self, t: f64) -> Mat3 {
        let d = t - 25.0;
        std::array::from_fn(|i| {
            std::array::from_fn(|j| self.m[i][j] * (1.0 + self.scale_per_c[j] * d))
        })
    }

    fn at(&self, t: f64) -> TriadTruth {
        TriadTruth {
            scale_misalignment: self.m_at(t),
            bias: std::array::from_fn(|i| self.bias[i] + self.slope[i] * (t - 25.0)),
            noise: self.noise,
        }
    }
}

/// A consumer unit: 2–3 % scales, 1 % misalignments, ±100 ppm/°C.
fn thermal(rng: &mut Rng, scale: f64, bias: f64, slope: f64, noise: f64) -> Thermal {
    let mut u = |x: f64| x * (2.0 * rng.uniform() - 1.0);
    Thermal {
        m: std::array::from_fn(|i| {
            std::array::from_fn(|j| if i == j { 1.0 + u(scale) } else { u(0.01) })
        }),
        scale_per_c: std::array::from_fn(|_| u(1e-4)),
        bias: std::array::from_fn(|_| u(bias)),
        slope: std::array::from_fn(|_| u(slope)),
        noise,
    }
}

/// The gyro's true (I+Σ)(T) in the accelerometer's corrected frame at T
/// (see lab/tests/rig_free.rs's `gyro_truth`).
fn gyro_truth(accel: &Thermal, gyro: &Thermal, t: f64) -> Mat3 {
    let inv = matrix::inverse(&accel.m_at(t)).unwrap();
    let t_u = cholesky_upper(&gram(&inv)).unwrap();
    let q_t = matrix::mul(&inv, &matrix::inverse(&t_u).unwrap());
    matrix::mul(&gyro.m_at(t), &q_t)
}

/// A hand session ([`hand_record::SESSION`]).
fn script() -> Script {
    hand_record::SESSION
}

/// One soak's record, its poses and their means.
struct Soak {
    t: Vec<f64>,
    gyro: Vec<[f64; 3]>,
    poses: Vec<Segment>,
    accel_means: Vec<[f64; 3]>,
    temperatures: Vec<f64>,
    accel: Vec<StaticMean>,
    gyro_means: Vec<StaticMean>,
}

fn soak(accel: &Thermal, gyro: &Thermal, temperature: f64, rng: &mut Rng) -> Soak {
    let unit = Unit {
        accel: accel.at(temperature),
        gyro: gyro.at(temperature),
        gravity: G,
        g_sensitivity: None,
    };
    let (mut t, mut a, mut g) = (Vec::new(), Vec::new(), Vec::new());
    hand_record::generate(&script(), &unit, &mut || rng.uniform(), |s| {
        t.push(s.t);
        a.push(s.accel);
        g.push(s.gyro);
    });
    let detector = Detector {
        block: 50,
        min_blocks: 4,
    };
    let mut poses = vec![Segment { start: 0, end: 0 }; a.len() / 50 + 1];
    let n = detector.detect(&a, &mut poses).unwrap();
    poses.truncate(n);
    let mean_of = |x: &[[f64; 3]], s: &Segment| {
        let part = &x[s.start..s.end];
        let sd = static_segments::standard_deviation(part);
        StaticMean {
            temperature_c: temperature,
            mean: static_segments::mean(part),
            standard_error: sd.map(|v| v / (part.len() as f64).sqrt()),
        }
    };
    let accel_stats: Vec<StaticMean> = poses.iter().map(|s| mean_of(&a, s)).collect();
    Soak {
        gyro_means: poses.iter().map(|s| mean_of(&g, s)).collect(),
        accel_means: accel_stats.iter().map(|m| m.mean).collect(),
        temperatures: vec![temperature; poses.len()],
        accel: accel_stats,
        t,
        gyro: g,
        poses,
    }
}

/// The accelerometer, the gyro bias, then the gyro's (I+Σ)(T).
fn fit(
    soaks: &[Soak],
) -> Result<(ThermalAccelFit, BiasPolynomial, ThermalGyroFit), ThermalGyroError> {
    let accel_means: Vec<StaticMean> = soaks.iter().flat_map(|s| s.accel.clone()).collect();
    let gyro_means: Vec<StaticMean> = soaks.iter().flat_map(|s| s.gyro_means.clone()).collect();
    let temps: Vec<f64> = accel_means.iter().map(|m| m.temperature_c).collect();
    let cov = coverage(&temps).expect("the soaks support a term");
    let terms = Terms {
        reference_c: cov.reference_c,
        bias_order: cov.bias_order(),
        scale: true,
    };
    let (mut scratch, mut weights) = (vec![[0.0; 3]; temps.len()], vec![0.0; temps.len()]);
    let accel = thermal_accel::fit(&accel_means, G, terms, &mut scratch, &mut weights)
        .expect("the accelerometer fits");
    let bias = bias_polynomial::fit(&gyro_means, cov.reference_c, cov.bias_order())
        .expect("the gyro's bias fits");
    let sets: Vec<Poses> = soaks
        .iter()
        .map(|s| Poses {
            record: Record {
                t: &s.t,
                gyro: &s.gyro,
            },
            segments: &s.poses,
            accel_means: &s.accel_means,
            temperatures: &s.temperatures,
        })
        .collect();
    let gyro = thermal_gyro::fit(&sets, &accel, &bias, FULL_SCALE)?;
    Ok((accel, bias, gyro))
}

/// A unit and its three soaks from `seed`.
fn session(seed: u64) -> (Thermal, Thermal, Vec<Soak>) {
    let mut rng = Rng::from_seed(seed);
    let accel = thermal(&mut rng, 0.02, 0.2, 1.5e-3, 0.01);
    let gyro = thermal(&mut rng, 0.03, 0.02, 1e-4, 1e-3);
    let soaks = SOAKS
        .iter()
        .map(|&t| soak(&accel, &gyro, t, &mut rng))
        .collect();
    (accel, gyro, soaks)
}

/// (estimate − truth)/σ of the 9 entries of (I+Σ)₀ then the 9 of D, with
/// each entry's degrees of freedom.
fn z_scores(fit: &ThermalGyroFit, accel: &Thermal, gyro: &Thermal) -> Vec<(f64, f64)> {
    let m0 = gyro_truth(accel, gyro, 25.0);
    let (plus, minus) = (gyro_truth(accel, gyro, 26.0), gyro_truth(accel, gyro, 24.0));
    let mut z = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            let d = (plus[i][j] - minus[i][j]) / 2.0;
            z.push((
                (fit.scale_misalignment[i][j] - m0[i][j]) / fit.sigma_scale_misalignment[i][j],
                fit.dof_entries[0][i][j],
            ));
            z.push((
                (fit.scale_misalignment_per_c[i][j] - d) / fit.sigma_scale_misalignment_per_c[i][j],
                fit.dof_entries[1][i][j],
            ));
        }
    }
    z
}

/// One unit (seed 1): every entry of (I+Σ)₀ and D within 3σ, D's diagonal
/// (±100 ppm/°C) found to a few ppm/°C.
#[test]
fn three_soaks_recover_the_gyro_scale_against_temperature_within_3_sigma() {
    let (accel, gyro, soaks) = session(1);
    let (_, _, fit) = fit(&soaks).unwrap();
    assert_eq!((fit.moves, fit.gyro_dof), (39, 2 * 39 - 18));
    assert_eq!(
        fit.turns,
        [13, 13],
        "the 25 °C soak is at the reference: neither side"
    );
    let z = z_scores(&fit, &accel, &gyro);
    assert!(z.iter().all(|(z, _)| z.abs() <= 3.0), "{z:?}");
    let sd = fit.sigma_scale_misalignment_per_c;
    assert!(sd.iter().flatten().all(|&s| s > 1e-7 && s < 1e-5), "{sd:?}");
}

/// Truth within ±2σ at the rate Student-t with each entry's degrees of
/// freedom predicts, ±5 points, over 50 seeds (900 entries).
#[test]
#[cfg_attr(debug_assertions, ignore = "slow in debug: run with --release")]
fn the_gyro_sigmas_are_honest_over_many_seeds() {
    let started = std::time::Instant::now();
    let (mut within, mut total, mut predicted, mut beyond_3) = (0usize, 0usize, 0.0, 0usize);
    for seed in 200..250 {
        let (accel, gyro, soaks) = session(seed);
        let (_, _, fit) = fit(&soaks).unwrap();
        for (z, dof) in z_scores(&fit, &accel, &gyro) {
            total += 1;
            within += usize::from(z.abs() <= 2.0);
            beyond_3 += usize::from(z.abs() > 3.0);
            predicted += student_t::coverage(2.0, dof);
        }
    }
    let rate = 100.0 * within as f64 / total as f64;
    let expected = 100.0 * predicted / total as f64;
    println!(
        "gyro (I+Σ)₀ and D: {rate:.1} % of {total} within 2σ, Student-t predicts {expected:.1} %; {beyond_3} beyond 3σ; {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!((rate - expected).abs() <= 5.0, "coverage {rate:.1} %");
}

/// Turns at one temperature only: D is not determined, and the fit says so.
#[test]
fn turns_at_one_temperature_only_are_refused() {
    let (_, _, mut soaks) = session(3);
    // Keep the −10 °C soak's turns; the others' poses are there, their turns not.
    for s in soaks.iter_mut().skip(1) {
        s.poses.truncate(1);
        s.accel_means.truncate(1);
        s.temperatures.truncate(1);
    }
    let err = fit(&soaks).unwrap_err();
    assert!(
        matches!(
            err,
            ThermalGyroError::TooFewTurnsForScale {
                colder: 13,
                warmer: 0,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("found 13 colder and 0 warmer"),
        "{err}"
    );
}
