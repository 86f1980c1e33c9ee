//! Thermal calibration (`triad_lab::calib_fit::fits::{thermal_accel,
//! bias_polynomial, thermal_coverage}`) on synthetic static means with known
//! truth: a consumer unit whose (I+Σ) follows the simulator's model
//! (I+Σ)·diag(1 + s·ΔT) (a full matrix D) and whose biases are linear in
//! ΔT, at three soaks or through a ramp, in random orientations. Recovery
//! within 3σ, the honesty of the σ's over many seeds (Student-t coverage),
//! and the refusals.
#![allow(clippy::needless_range_loop)] // index form reads as the matrix formulas

use triad::model::matrix::{self, Mat3};
use triad_lab::calib_fit::fits::bias_polynomial::{self, StaticMean};
use triad_lab::calib_fit::fits::thermal_accel::{self, Terms, ThermalAccelError, ThermalAccelFit};
use triad_lab::calib_fit::fits::thermal_coverage::{self, coverage, CoverageError};
use triad_lab::calib_fit::numerics::small3::{cholesky_upper, gram};
use triad_lab::student_t;
use triad_sim::effects::rng::Rng;

const G: f64 = 9.80665;

/// The unit's truth: (I+Σ) at 25 °C, scale per °C, biases and their slopes.
struct Unit {
    m: Mat3,
    scale_per_c: [f64; 3],
    accel_bias: [f64; 3],
    accel_slope: [f64; 3],
    gyro_bias: [f64; 3],
    gyro_slope: [f64; 3],
}

const UNIT_REFERENCE_C: f64 = 25.0;

/// Consumer-mems-like: 0.5 % scales, 5 mrad misalignments, 20 mg biases,
/// ±100 ppm/°C scales, ±150 µg/°C bias slopes; gyro ±0.5 °/s and
/// ±0.006 °/s/°C.
fn unit(rng: &mut Rng) -> Unit {
    let mut u = |scale: f64| scale * (2.0 * rng.uniform() - 1.0);
    let mut unit = Unit {
        m: matrix::IDENTITY,
        scale_per_c: [0.0; 3],
        accel_bias: [0.0; 3],
        accel_slope: [0.0; 3],
        gyro_bias: [0.0; 3],
        gyro_slope: [0.0; 3],
    };
    for i in 0..3 {
        for j in 0..3 {
            unit.m[i][j] += u(0.005);
        }
        unit.scale_per_c[i] = u(1e-4);
        unit.accel_bias[i] = u(0.2);
        unit.accel_slope[i] = u(1.5e-3);
        unit.gyro_bias[i] = u(0.009);
        unit.gyro_slope[i] = u(1e-4);
    }
    unit
}

impl Unit {
    /// (I+Σ)(T) = (I+Σ)·diag(1 + s·ΔT).
    fn m_at(&self, t: f64) -> Mat3 {
        let d = t - UNIT_REFERENCE_C;
        core::array::from_fn(|i| {
            core::array::from_fn(|j| self.m[i][j] * (1.0 + self.scale_per_c[j] * d))
        })
    }

    /// (I+Σ)(T) in the fit's convention: its upper triangular factor U
    /// ((I+Σ)(T) = U·Q, Q a rotation; U⁻¹ is the Cholesky factor of
    /// (I+Σ)⁻ᵀ(I+Σ)⁻¹).
    fn upper_at(&self, t: f64) -> Mat3 {
        let inv = matrix::inverse(&self.m_at(t)).unwrap();
        matrix::inverse(&cholesky_upper(&gram(&inv)).unwrap()).unwrap()
    }

    /// D in the fit's convention at `reference_c` (central difference of U:
    /// U is linear in T to ~1e-9 of its derivative over ±35 °C, far
    /// below the fit's σ's).
    fn upper_per_c(&self, reference_c: f64) -> Mat3 {
        let (a, b) = (
            self.upper_at(reference_c + 1.0),
            self.upper_at(reference_c - 1.0),
        );
        core::array::from_fn(|i| core::array::from_fn(|j| (a[i][j] - b[i][j]) / 2.0))
    }

    fn bias_at(&self, t: f64, gyro: bool) -> [f64; 3] {
        let d = t - UNIT_REFERENCE_C;
        let (b, s) = if gyro {
            (self.gyro_bias, self.gyro_slope)
        } else {
            (self.accel_bias, self.accel_slope)
        };
        core::array::from_fn(|i| b[i] + s[i] * d)
    }
}

/// Per-sample noise (70 µg/√Hz and 0.0028 °/s/√Hz at 50 Hz) and samples
/// per segment (20 s).
const ACCEL_NOISE: f64 = 70e-6 * G * 5.0;
const GYRO_NOISE: f64 = 0.0028 * core::f64::consts::PI / 180.0 * 5.0;
const SAMPLES: f64 = 1000.0;

fn direction(rng: &mut Rng) -> [f64; 3] {
    let v = [rng.gaussian(), rng.gaussian(), rng.gaussian()];
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

/// StaticMeans at `temperatures`, cycling through 12 random orientations:
/// the accelerometer's and the gyro's means with their standard errors.
fn segments(
    unit: &Unit,
    temperatures: &[f64],
    rng: &mut Rng,
) -> (Vec<StaticMean>, Vec<StaticMean>) {
    let poses: Vec<[f64; 3]> = (0..12).map(|_| direction(rng)).collect();
    let se = |noise: f64| noise / SAMPLES.sqrt();
    let mut accel = Vec::new();
    let mut gyro = Vec::new();
    for (k, &t) in temperatures.iter().enumerate() {
        let f = poses[k % poses.len()].map(|x| x * G);
        let m = matrix::mul_vec(&unit.m_at(t), &f);
        let b = unit.bias_at(t, false);
        accel.push(StaticMean {
            temperature_c: t,
            mean: core::array::from_fn(|i| m[i] + b[i] + se(ACCEL_NOISE) * rng.gaussian()),
            standard_error: [se(ACCEL_NOISE); 3],
        });
        let bg = unit.bias_at(t, true);
        gyro.push(StaticMean {
            temperature_c: t,
            mean: core::array::from_fn(|i| bg[i] + se(GYRO_NOISE) * rng.gaussian()),
            standard_error: [se(GYRO_NOISE); 3],
        });
    }
    (accel, gyro)
}

/// A 12-position tumble at each of −10, 25 and 60 °C.
fn soaks() -> Vec<f64> {
    [-10.0, 25.0, 60.0].iter().flat_map(|&t| [t; 12]).collect()
}

/// A ramp −10 → 60 °C, a pose every 0.5 °C (141 poses).
fn ramp() -> Vec<f64> {
    (0..141).map(|k| -10.0 + 0.5 * k as f64).collect()
}

fn fit_accel(segments: &[StaticMean]) -> Result<ThermalAccelFit, ThermalAccelError> {
    let temps: Vec<f64> = segments.iter().map(|s| s.temperature_c).collect();
    let cov = coverage(&temps).expect("the temperatures support a term");
    let terms = Terms {
        reference_c: cov.reference_c,
        bias_order: cov.bias_order(),
        scale: true,
    };
    let mut means = vec![[0.0; 3]; segments.len()];
    let mut weights = vec![0.0; segments.len()];
    thermal_accel::fit(segments, G, terms, &mut means, &mut weights)
}

/// (estimate − truth)/σ of every fitted entry: (I+Σ)₀ and D (upper
/// triangle), b₀ and the bias coefficients fitted.
fn accel_z(fit: &ThermalAccelFit, unit: &Unit) -> Vec<f64> {
    let r = fit.terms.reference_c;
    let (u0, d) = (unit.upper_at(r), unit.upper_per_c(r));
    let b0 = unit.bias_at(r, false);
    let mut z = Vec::new();
    for i in 0..3 {
        for j in i..3 {
            z.push((fit.scale_misalignment[i][j] - u0[i][j]) / fit.sigma_scale_misalignment[i][j]);
            z.push(
                (fit.scale_misalignment_per_c[i][j] - d[i][j])
                    / fit.sigma_scale_misalignment_per_c[i][j],
            );
        }
        z.push((fit.bias[i] - b0[i]) / fit.sigma_bias[i]);
        for k in 0..fit.terms.bias_order {
            let truth = if k == 0 { unit.accel_slope[i] } else { 0.0 };
            z.push((fit.bias_coefficients[i][k] - truth) / fit.sigma_bias_coefficients[i][k]);
        }
    }
    z
}

fn gyro_z(fit: &bias_polynomial::BiasPolynomial, unit: &Unit) -> Vec<f64> {
    let b0 = unit.bias_at(fit.reference_c, true);
    let mut z = Vec::new();
    for i in 0..3 {
        z.push((fit.bias[i] - b0[i]) / fit.sigma_bias[i]);
        for k in 0..fit.order {
            let truth = if k == 0 { unit.gyro_slope[i] } else { 0.0 };
            z.push((fit.coefficients[i][k] - truth) / fit.sigma_coefficients[i][k]);
        }
    }
    z
}

fn fit_gyro(means: &[StaticMean]) -> bias_polynomial::BiasPolynomial {
    let temps: Vec<f64> = means.iter().map(|m| m.temperature_c).collect();
    let cov = coverage(&temps).unwrap();
    bias_polynomial::fit(means, cov.reference_c, cov.bias_order()).unwrap()
}

/// Three soaks (seed 1): a quadratic bias and D, every term within 3σ.
#[test]
fn three_soaks_recover_the_temperature_terms_within_3_sigma() {
    let mut rng = Rng::from_seed(1);
    let unit = unit(&mut rng);
    let (accel, gyro) = segments(&unit, &soaks(), &mut rng);
    let fit = fit_accel(&accel).unwrap();
    assert_eq!(fit.terms.bias_order, 2, "3 soaks: 3 levels, 70 °C");
    assert_eq!((fit.segments, fit.fitted, fit.dof), (36, 6 + 6 + 3 + 6, 15));
    let z = accel_z(&fit, &unit);
    assert!(z.iter().all(|z| z.abs() <= 3.0), "{z:?}");
    // The σ's are of the size the noise predicts: the scale at each soak is
    // known to ~SE/g·√(3/12) ≈ 4e-6, so D to ~1e-7/°C over 70 °C.
    let sd = fit.sigma_scale_misalignment_per_c;
    assert!(sd[0][0] > 2e-8 && sd[0][0] < 5e-7, "{sd:?}");
    // D is recovered, not just bounded: 100 ppm/°C within a few %.
    let d = unit.upper_per_c(fit.terms.reference_c);
    assert!((fit.scale_misalignment_per_c[2][2] - d[2][2]).abs() < 0.05 * d[2][2].abs() + 4e-7);
    let g = fit_gyro(&gyro);
    assert_eq!((g.order, g.dof), (2, 36 - 3));
    let z = gyro_z(&g, &unit);
    assert!(z.iter().all(|z| z.abs() <= 3.0), "{z:?}");
}

/// A ramp: the cubic is supported and fitted (its truth is zero).
#[test]
fn a_ramp_supports_the_cubic() {
    let mut rng = Rng::from_seed(2);
    let unit = unit(&mut rng);
    let (accel, gyro) = segments(&unit, &ramp(), &mut rng);
    let fit = fit_accel(&accel).unwrap();
    assert_eq!((fit.terms.bias_order, fit.terms.reference_c), (3, 25.0));
    assert_eq!(fit.dof, 141 - 24);
    let z = accel_z(&fit, &unit);
    assert!(z.iter().all(|z| z.abs() <= 3.5), "{z:?}");
    assert_eq!(fit_gyro(&gyro).order, 3);
}

/// Truth within ±2σ at the rate Student-t with the fit's degrees of freedom
/// predicts, ±5 points, over 60 seeds of three soaks (27 accelerometer
/// entries and 9 gyro entries a seed).
#[test]
#[cfg_attr(debug_assertions, ignore = "slow in debug: run with --release")]
fn the_sigmas_are_honest_over_many_seeds() {
    let started = std::time::Instant::now();
    let (mut a, mut g) = ([0usize; 2], [0usize; 2]);
    let (mut a_dof, mut g_dof) = (0, 0);
    for seed in 100..160 {
        let mut rng = Rng::from_seed(seed);
        let unit = unit(&mut rng);
        let (accel, gyro) = segments(&unit, &soaks(), &mut rng);
        let fit = fit_accel(&accel).unwrap();
        let z = accel_z(&fit, &unit);
        a[0] += z.iter().filter(|z| z.abs() <= 2.0).count();
        a[1] += z.len();
        a_dof = fit.dof;
        let gf = fit_gyro(&gyro);
        let z = gyro_z(&gf, &unit);
        g[0] += z.iter().filter(|z| z.abs() <= 2.0).count();
        g[1] += z.len();
        g_dof = gf.dof;
    }
    let rate = |c: [usize; 2]| 100.0 * c[0] as f64 / c[1] as f64;
    let expected = |dof: usize| 100.0 * student_t::coverage(2.0, dof as f64);
    println!(
        "accel: {:.1} % of {} within 2σ, t({a_dof}) predicts {:.1} %; gyro bias: {:.1} % of {}, t({g_dof}) {:.1} %; {:.2} s",
        rate(a),
        a[1],
        expected(a_dof),
        rate(g),
        g[1],
        expected(g_dof),
        started.elapsed().as_secs_f64()
    );
    assert!(
        (rate(a) - expected(a_dof)).abs() <= 5.0,
        "accel coverage {:.1} %",
        rate(a)
    );
    assert!(
        (rate(g) - expected(g_dof)).abs() <= 5.0,
        "gyro coverage {:.1} %",
        rate(g)
    );
}

#[test]
fn too_narrow_a_swing_and_one_side_without_poses_are_refused() {
    let mut rng = Rng::from_seed(3);
    let unit = unit(&mut rng);
    let temps: Vec<f64> = [20.0, 28.0].iter().flat_map(|&t| [t; 12]).collect();
    let (accel, _) = segments(&unit, &temps, &mut rng);
    let segment_temps: Vec<f64> = accel.iter().map(|s| s.temperature_c).collect();
    let err = coverage(&segment_temps).unwrap_err();
    assert!(
        matches!(err, CoverageError::TemperatureSwingTooSmall { .. }),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .contains("a swing of 8.0 °C: a temperature term needs at least 10 °C"),
        "{err}"
    );

    // A tumble at 25 °C and a static ramp: the warm side has one direction.
    let mut temps = vec![-10.0; 12];
    temps.extend((0..70).map(|k| 25.0 + 0.5 * k as f64));
    let (mut accel, _) = segments(&unit, &temps, &mut rng);
    let level = accel[12].mean;
    for s in accel.iter_mut().skip(12) {
        s.mean = level;
    }
    let means: Vec<[f64; 3]> = accel.iter().map(|s| s.mean).collect();
    let cov = coverage(&temps).unwrap();
    let mut scratch = vec![[0.0; 3]; means.len()];
    let found =
        thermal_coverage::orientations_either_side(&means, &temps, cov.reference_c, &mut scratch);
    assert_eq!(found, [12, 1]);
    let err = thermal_coverage::check_scale_support(found, &cov).unwrap_err();
    assert!(
        err.to_string().contains("found 12 colder and 1 warmer"),
        "{err}"
    );
}
