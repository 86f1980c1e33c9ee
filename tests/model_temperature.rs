//! Temperature terms: a refold at T_ref equals the calibration without
//! temperature terms; elsewhere the bias follows the cubic and (I+Σ) the line.

mod model_support;

use model_support::*;
use triad::model::validate::TEMPERATURE_RANGE_C;
use triad::model::{
    Calibration, CalibrationError, Corrector, Orientation, TemperatureTerms, Triad,
};

fn realistic(seed: u64) -> (Calibration, triad::sensor::ImuScale) {
    let mut rng = rng(seed);
    let scale = widest_scale();
    let mut cal = random_calibration(&mut rng, &scale);
    // Realistic triads (within 3 %) so the drift keeps everything valid.
    for t in [&mut cal.accel, &mut cal.gyro] {
        for (i, row) in t.scale_misalignment.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = if i == j {
                    1.0 + (*x - 1.0) * 0.05
                } else {
                    *x * 0.1
                };
            }
        }
        t.bias = t.bias.map(|b| b * 0.02);
    }
    cal.accel.temperature = Some(random_temperature_terms(&mut rng, scale.accel.full_scale));
    cal.gyro.temperature = Some(random_temperature_terms(&mut rng, scale.gyro.full_scale));
    (cal, scale)
}

#[test]
fn refold_at_reference_equals_no_temperature_terms() {
    for seed in 0..20 {
        let (cal, scale) = realistic(seed);
        let mut plain_cal = cal;
        plain_cal.accel.temperature = None;
        plain_cal.gyro.temperature = None;
        let plain = Corrector::new(&plain_cal, &scale, Orientation::Roll90).unwrap();
        let mut c = Corrector::new(&cal, &scale, Orientation::Roll90).unwrap();
        // Freshly loaded: folded at T_ref. Refolding at accel's T_ref gives the
        // same accel coefficients bit for bit (ΔT = 0 adds exact zeros).
        assert_eq!(c.folded_f32(Triad::Accel), plain.folded_f32(Triad::Accel));
        assert_eq!(c.folded_f32(Triad::Gyro), plain.folded_f32(Triad::Gyro));
        c.refold(cal.accel.temperature.unwrap().reference_c)
            .unwrap();
        assert_eq!(c.folded(Triad::Accel), plain.folded(Triad::Accel));
        let mut rng = rng(seed + 100);
        for _ in 0..50 {
            let raw = random_raw(&mut rng);
            assert_eq!(c.correct(&raw).accel, plain.correct(&raw).accel);
            assert_eq!(c.reference(&raw).accel, plain.reference(&raw).accel);
        }
    }
}

#[test]
fn bias_follows_the_cubic_and_scale_the_line() {
    let terms = TemperatureTerms {
        reference_c: 25.0,
        bias_coefficients: [[1e-3, 2e-5, -3e-7], [-2e-3, 0.0, 1e-7], [0.0, 5e-5, 0.0]],
        scale_misalignment_per_c: [[2e-4, 1e-5, 0.0], [0.0, -1e-4, 0.0], [-1e-5, 0.0, 3e-4]],
    };
    let mut cal = Calibration::identity(5);
    cal.gyro.bias = [0.01, -0.02, 0.005];
    cal.gyro.temperature = Some(terms);
    let mut c = Corrector::new_si(&cal, 100.0, 35.0, Orientation::RotationNone).unwrap();
    for t in [-40.0, -10.0, 0.0, 25.0, 37.5, 60.0, 85.0] {
        c.refold(t).unwrap();
        assert_eq!(c.fold_temperature_c(), Some(t));
        let dt = t - 25.0;
        let b: Vec<f64> = (0..3)
            .map(|i| {
                let k = terms.bias_coefficients[i];
                cal.gyro.bias[i] + k[0] * dt + k[1] * dt * dt + k[2] * dt * dt * dt
            })
            .collect();
        let a: Vec<Vec<f64>> = (0..3)
            .map(|i| (0..3).map(|j| if i == j { 1.0 } else { 0.0 } + terms.scale_misalignment_per_c[i][j] * dt).collect())
            .collect();
        // Forward model at T: x = A(T)·m + b(T); correcting x must give m back.
        let m = [0.3, -0.7, 1.1];
        let x: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i][j] * m[j]).sum::<f64>() + b[i])
            .collect();
        let back = c.reference_si([0.0; 3], [x[0], x[1], x[2]], t);
        // κ ≈ 1 and |x| ≈ 1: the f64 round trip is good to a few 1e−16.
        for (got, want) in back.gyro.iter().zip(m) {
            assert!((got - want).abs() < 1e-14, "T {t}: {got} vs {want}");
        }
        // With zero input the f32 path outputs −A(T)⁻¹·b(T) ≈ −b(T) to first order; check it
        // against the reference within the f32 bound (5u·|k|, see tests/model_f32.rs).
        let fast = c.correct_si([0.0; 3], [0.0; 3], t as f32);
        let exact = c.reference_si([0.0; 3], [0.0; 3], t);
        for i in 0..3 {
            let tol = 5.00001 * f64::from(f32::EPSILON) / 2.0 * exact.gyro[i].abs();
            assert!((f64::from(fast.gyro[i]) - exact.gyro[i]).abs() <= tol);
        }
        // The accel triad has no temperature terms and stays as loaded.
        assert_eq!(
            c.correct_si([1.0, 2.0, 3.0], [0.0; 3], 0.0).accel,
            [1.0, 2.0, 3.0]
        );
    }
}

#[test]
fn refold_clamps_to_the_validated_range_and_rejects_nan() {
    let (cal, scale) = realistic(7);
    let mut c = Corrector::new(&cal, &scale, Orientation::RotationNone).unwrap();
    c.refold(TEMPERATURE_RANGE_C.1).unwrap();
    let at_max = c.clone();
    c.refold(200.0).unwrap();
    assert_eq!(c.fold_temperature_c(), Some(TEMPERATURE_RANGE_C.1));
    assert_eq!(c, at_max);
    c.refold(-273.0).unwrap();
    assert_eq!(c.fold_temperature_c(), Some(TEMPERATURE_RANGE_C.0));
    let before = c.clone();
    assert!(matches!(
        c.refold(f64::NAN),
        Err(CalibrationError::NonFiniteTemperature { .. })
    ));
    assert_eq!(
        c, before,
        "a rejected refold must not change the coefficients"
    );
}

#[test]
fn refolded_f32_and_fixed_paths_keep_their_bounds() {
    let (cal, scale) = realistic(11);
    let mut c = Corrector::new(&cal, &scale, Orientation::Pitch270).unwrap();
    let mut rng = rng(12);
    for t in [-40.0, 0.0, 50.0, 85.0] {
        c.refold(t).unwrap();
        let fixed = c.to_fixed().unwrap();
        let bound = fixed.error_bound();
        for _ in 0..200 {
            let raw = random_raw(&mut rng);
            let exact = c.reference(&raw);
            let fx = fixed.correct(&raw).to_f64();
            // + the reference's own error, 1e−12 relative to |K||raw| + |k| ≤ 2000 SI (see model_fixed.rs).
            for i in 0..3 {
                assert!((fx.accel[i] - exact.accel[i]).abs() <= bound[0] + 2e-9);
                assert!((fx.gyro[i] - exact.gyro[i]).abs() <= bound[1] + 2e-9);
            }
        }
    }
}
