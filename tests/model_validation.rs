//! Each bad calibration gets its own specific error, naming triad, entry and
//! value; messages are one line.

mod model_support;

use model_support::*;
use triad::model::validate::{Entry, MAX_CONDITION_NUMBER};
use triad::model::{
    Calibration, CalibrationError, Corrector, Orientation, TemperatureTerms, Triad,
    TriadCalibration,
};

const I: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn with_accel_matrix(m: [[f64; 3]; 3]) -> Calibration {
    let mut cal = Calibration::identity(1);
    cal.accel.scale_misalignment = m;
    cal
}

fn load(cal: &Calibration) -> Result<Corrector, CalibrationError> {
    Corrector::new(cal, &widest_scale(), Orientation::RotationNone)
}

fn terms() -> TemperatureTerms {
    TemperatureTerms {
        reference_c: 25.0,
        bias_coefficients: [[0.0; 3]; 3],
        scale_misalignment_per_c: [[0.0; 3]; 3],
    }
}

#[test]
fn non_finite_entries_are_named() {
    for (row, col, v) in [
        (0, 0, f64::NAN),
        (1, 2, f64::INFINITY),
        (2, 1, f64::NEG_INFINITY),
    ] {
        let mut m = I;
        m[row][col] = v;
        match load(&with_accel_matrix(m)) {
            Err(CalibrationError::NonFinite {
                triad: Triad::Accel,
                entry,
                value,
            }) => {
                assert_eq!(
                    entry,
                    Entry::ScaleMisalignment {
                        row: row as u8,
                        col: col as u8
                    }
                );
                assert!(value.is_nan() == v.is_nan() && (v.is_nan() || value == v));
            }
            other => panic!("{other:?}"),
        }
    }
    let mut cal = Calibration::identity(1);
    cal.gyro.bias[2] = f64::NAN;
    let err = load(&cal).unwrap_err();
    assert!(matches!(
        err,
        CalibrationError::NonFinite {
            triad: Triad::Gyro,
            entry: Entry::Bias { axis: 2 },
            ..
        }
    ));
    assert_eq!(err.to_string(), "gyro bias[2] = NaN: not a finite number");

    let mut t = terms();
    t.bias_coefficients[1][2] = f64::INFINITY;
    cal = Calibration::identity(1);
    cal.accel.temperature = Some(t);
    let err = load(&cal).unwrap_err();
    assert!(matches!(
        err,
        CalibrationError::NonFinite {
            entry: Entry::BiasCoefficient { axis: 1, power: 3 },
            ..
        }
    ));
    assert_eq!(
        err.to_string(),
        "accel temperature.bias_coefficients[1][2] = inf: not a finite number"
    );
}

#[test]
fn singular_matrices_are_singular() {
    for m in [
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
        [[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0; 3]; 3],
        // Rank 2: row 2 = row 0 + row 1, exactly (dyadic entries).
        [[1.0, 0.25, 0.0], [0.0, 1.0, 0.5], [1.0, 1.25, 0.5]],
    ] {
        let err = load(&with_accel_matrix(m)).unwrap_err();
        assert!(
            matches!(
                err,
                CalibrationError::Singular {
                    triad: Triad::Accel,
                    temperature_c: None,
                    ..
                }
            ),
            "{m:?}: {err}"
        );
        assert!(
            err.to_string()
                .starts_with("accel scale_misalignment: singular"),
            "{err}"
        );
    }
}

#[test]
fn nearly_singular_and_huge_matrices_are_badly_conditioned() {
    for m in [
        [[1.0, 1.0, 0.0], [1.0, 1.0 + 1e-9, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1.0]],
        [[1e300, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ] {
        match load(&with_accel_matrix(m)) {
            Err(CalibrationError::BadlyConditioned {
                triad: Triad::Accel,
                condition,
                temperature_c: None,
            }) => {
                assert!(condition > MAX_CONDITION_NUMBER, "{condition}")
            }
            other => panic!("{m:?}: {other:?}"),
        }
    }
}

#[test]
fn huge_uniform_scale_is_a_scale_error_not_an_overflow() {
    // det = 1e600 overflows f64; the check normalises first, so κ = 1 and the
    // diagonal bound reports the real problem.
    let m = [[1e200, 0.0, 0.0], [0.0, 1e200, 0.0], [0.0, 0.0, 1e200]];
    let err = load(&with_accel_matrix(m)).unwrap_err();
    assert_eq!(
        err,
        CalibrationError::ScaleOutOfRange {
            triad: Triad::Accel,
            axis: 0,
            value: 1e200,
            temperature_c: None
        }
    );
}

#[test]
fn diagonal_outside_sane_range_is_named_with_the_documented_message() {
    let mut m = I;
    m[1][1] = 1.7;
    let err = load(&with_accel_matrix(m)).unwrap_err();
    assert_eq!(
        err,
        CalibrationError::ScaleOutOfRange {
            triad: Triad::Accel,
            axis: 1,
            value: 1.7,
            temperature_c: None
        }
    );
    assert_eq!(
        err.to_string(),
        "accel scale_misalignment[1][1] = 1.7: diagonal (scale factor) outside the sane range 0.5..1.5"
    );
    m[1][1] = 0.45;
    assert!(
        matches!(load(&with_accel_matrix(m)), Err(CalibrationError::ScaleOutOfRange { value, .. }) if value == 0.45)
    );
    // A unit mistake: a gyro scale in °/s per rad/s.
    let mut cal = Calibration::identity(1);
    cal.gyro.scale_misalignment[2][2] = 57.29577951308232;
    assert!(matches!(
        load(&cal),
        Err(CalibrationError::ScaleOutOfRange {
            triad: Triad::Gyro,
            axis: 2,
            ..
        })
    ));
}

#[test]
fn large_off_diagonal_is_a_misalignment_error() {
    let mut m = I;
    m[0][2] = -0.3;
    let err = load(&with_accel_matrix(m)).unwrap_err();
    assert_eq!(
        err,
        CalibrationError::MisalignmentTooLarge {
            triad: Triad::Accel,
            row: 0,
            col: 2,
            value: -0.3,
            temperature_c: None
        }
    );
    assert_eq!(
        err.to_string(),
        "accel scale_misalignment[0][2] = -0.3: off-diagonal (misalignment) beyond ±0.1"
    );
    m[0][2] = 0.1; // on the bound: accepted
    assert!(load(&with_accel_matrix(m)).is_ok());
}

#[test]
fn bias_beyond_full_scale_is_rejected_at_the_configured_range() {
    let scale = widest_scale();
    let mut cal = Calibration::identity(1);
    cal.accel.bias[0] = scale.accel.full_scale; // exactly full scale: accepted
    assert!(load(&cal).is_ok());
    cal.accel.bias[0] = -1.01 * scale.accel.full_scale;
    assert!(matches!(
        load(&cal),
        Err(CalibrationError::BiasBeyondFullScale { triad: Triad::Accel, axis: 0, full_scale, temperature_c: None, .. })
            if full_scale == scale.accel.full_scale
    ));
    // A gyro bias of 1 rad/s is within ±2000 °/s but not within ±30 °/s.
    cal = Calibration::identity(1);
    cal.gyro.bias = [0.0, 1.0, 0.0];
    assert!(cal.validate(100.0, 35.0).is_ok());
    assert!(matches!(
        cal.validate(100.0, 0.5),
        Err(CalibrationError::BiasBeyondFullScale { axis: 1, .. })
    ));
}

#[test]
fn absurd_temperature_terms_are_rejected() {
    let with = |t: TemperatureTerms| {
        let mut cal = Calibration::identity(1);
        cal.gyro.temperature = Some(t);
        load(&cal)
    };
    let mut t = terms();
    t.reference_c = 200.0;
    assert!(
        matches!(with(t), Err(CalibrationError::ReferenceTemperatureOutOfRange { triad: Triad::Gyro, value }) if value == 200.0)
    );

    t = terms();
    t.scale_misalignment_per_c[1][0] = 0.05;
    assert!(matches!(
        with(t),
        Err(CalibrationError::TemperatureTermAbsurd {
            entry: Entry::ScaleMisalignmentPerC { row: 1, col: 0 },
            ..
        })
    ));

    // Diagonal 1.2 at 25 °C with 0.006/°C: 1.2 − 0.39 = 0.81 at −40 °C is
    // fine, 1.2 + 0.36 = 1.56 at 85 °C is not.
    t = terms();
    t.scale_misalignment_per_c[2][2] = 0.006;
    let mut cal = Calibration::identity(1);
    cal.gyro.scale_misalignment[2][2] = 1.2;
    cal.gyro.temperature = Some(t);
    let err = load(&cal).unwrap_err();
    assert!(
        matches!(err, CalibrationError::ScaleOutOfRange { axis: 2, temperature_c: Some(tc), value, .. } if tc == 85.0 && (value - 1.56).abs() < 1e-12),
        "{err:?}"
    );
    assert!(err.to_string().contains("at 85 °C"), "{err}");

    // A bias cubic that is 0 at both ends of −40..85 °C (ΔT = −65 and 60 with
    // T_ref = 25) and peaks between them: b(x) = 1e−4·(x + 65)·x·(x − 60).
    // The check must find the interior extreme, here located by dense sampling.
    t = terms();
    t.bias_coefficients[0] = [-0.39, 5e-4, 1e-4];
    let at = |x: f64| 1e-4 * (x + 65.0) * x * (x - 60.0);
    let (mut peak, mut peak_x) = (0.0f64, 0.0);
    for i in 0..=1_250_000 {
        let x = -65.0 + 125.0 * f64::from(i) / 1.25e6;
        if at(x).abs() > peak.abs() {
            (peak, peak_x) = (at(x), x);
        }
    }
    assert!(at(-65.0).abs() < 1e-9 && at(60.0).abs() < 1e-9 && peak.abs() > 10.0);
    cal = Calibration::identity(1);
    cal.gyro.temperature = Some(t);
    match cal.validate(100.0, peak.abs() * 0.999) {
        Err(CalibrationError::BiasBeyondFullScale {
            triad: Triad::Gyro,
            axis: 0,
            value,
            temperature_c: Some(tc),
            ..
        }) => {
            // Sampling step 1e−4 °C: the sampled peak is within ~1e−8 of the true one.
            assert!(
                (value - peak).abs() < 1e-6 && (tc - 25.0 - peak_x).abs() < 1e-3,
                "{value} at {tc}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(cal.validate(100.0, peak.abs() * 1.01).is_ok());
}

#[test]
fn invalid_sensor_scales_are_rejected() {
    let mut scale = widest_scale();
    scale.gyro.si_per_lsb = 0.0;
    let err =
        Corrector::new(&Calibration::identity(0), &scale, Orientation::RotationNone).unwrap_err();
    assert_eq!(
        err,
        CalibrationError::InvalidScale {
            quantity: "gyro.si_per_lsb",
            value: 0.0
        }
    );
    scale = widest_scale();
    scale.accel.full_scale = f64::NAN;
    assert!(matches!(
        Corrector::new(&Calibration::identity(0), &scale, Orientation::RotationNone),
        Err(CalibrationError::InvalidScale {
            quantity: "accel.full_scale",
            ..
        })
    ));
}

#[test]
fn every_message_is_one_line() {
    let errors = [
        CalibrationError::Singular {
            triad: Triad::Gyro,
            determinant: 0.0,
            temperature_c: Some(-40.0),
        },
        CalibrationError::BadlyConditioned {
            triad: Triad::Accel,
            condition: 4e9,
            temperature_c: None,
        },
        CalibrationError::NonFiniteTemperature { value: f64::NAN },
        CalibrationError::FixedPointRange {
            quantity: "accel",
            max_output: 4e4,
        },
        CalibrationError::InvalidScale {
            quantity: "temperature_per_lsb",
            value: -1.0,
        },
    ];
    for e in errors {
        let s = e.to_string();
        assert!(!s.contains('\n') && s.len() > 20, "{s}");
    }
}

#[test]
fn random_valid_calibrations_pass() {
    let mut rng = rng(99);
    for _ in 0..1000 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        assert!(
            Corrector::new(&cal, &scale, random_orientation(&mut rng)).is_ok(),
            "{cal:?}"
        );
    }
    // And the triad type is what the public API says it is.
    let _: TriadCalibration = Calibration::identity(0).accel;
}
