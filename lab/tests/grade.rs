//! The classifier's rules on THEORY.md's tables: per parameter the best
//! grade whose cell holds the value; "between X and Y" in the tables' gaps;
//! worse than every row; the worst parameter decides the overall grade;
//! range and bandwidth list the grades they fit and rank nothing.

use triad_lab::allan::grade::{classify, place, GradeError, Placement, Verdict};
use triad_sim::grade::{AccelGrade, Grade, GyroGrade, Parameter, ACCEL_TABLE, GYRO_TABLE};

fn gyro(p: Parameter, x: f64) -> Placement {
    place(GYRO_TABLE.row(p).unwrap().cells, x)
}

fn accel(p: Parameter, x: f64) -> Placement {
    place(ACCEL_TABLE.row(p).unwrap().cells, x)
}

fn between(worse: usize, better: usize) -> Placement {
    Placement::Between { worse, better }
}

fn g(grade: GyroGrade) -> Placement {
    Placement::In(grade.index())
}

fn a(grade: AccelGrade) -> Placement {
    Placement::In(grade.index())
}

#[test]
fn each_parameter_is_placed_in_the_best_grade_holding_it() {
    use GyroGrade::*;
    assert_eq!(gyro(Parameter::Noise, 0.8), g(RateGrade));
    assert_eq!(gyro(Parameter::Noise, 0.5), g(Tactical));
    assert_eq!(gyro(Parameter::Noise, 0.05), g(Tactical));
    assert_eq!(gyro(Parameter::Noise, 0.01), g(Aviation));
    assert_eq!(gyro(Parameter::Noise, 0.0005), g(Navigation));
    assert_eq!(gyro(Parameter::BiasInstability, 50.0), g(RateGrade));
    assert_eq!(gyro(Parameter::BiasInstability, 3.0), g(Tactical));
    assert_eq!(gyro(Parameter::BiasInstability, 0.05), g(Aviation));
    assert_eq!(gyro(Parameter::BiasInstability, 0.0), g(Navigation));
    assert_eq!(gyro(Parameter::ScaleFactorInstability, 0.3), g(RateGrade));
    use AccelGrade as A;
    assert_eq!(accel(Parameter::Noise, 1000.0), a(A::Automotive));
    assert_eq!(accel(Parameter::Noise, 500.0), a(A::Tactical));
    assert_eq!(accel(Parameter::Noise, 5.0), a(A::Navigation));
    assert_eq!(accel(Parameter::BiasInstability, 20e3), a(A::Automotive));
    assert_eq!(accel(Parameter::BiasInstability, 500.0), a(A::Tactical));
    assert_eq!(accel(Parameter::BiasInstability, 30.0), a(A::Navigation));
    // Better than the best row (navigation bias instability 10–100 µg): navigation.
    assert_eq!(accel(Parameter::BiasInstability, 3.0), a(A::Navigation));
}

#[test]
fn the_tables_gaps_answer_between() {
    use GyroGrade::*;
    // THEORY.md's examples: gyro bias instability 0.1–1 °/h, accelerometer
    // noise 10–50 µg/√Hz, accelerometer bias instability 1–10 mg.
    assert_eq!(
        gyro(Parameter::BiasInstability, 0.5),
        between(Tactical.index(), Aviation.index())
    );
    assert_eq!(
        accel(Parameter::Noise, 30.0),
        between(AccelGrade::Tactical.index(), AccelGrade::Navigation.index())
    );
    assert_eq!(
        accel(Parameter::BiasInstability, 5000.0),
        between(AccelGrade::Automotive.index(), AccelGrade::Tactical.index())
    );
    // And the gap the table leaves between tactical (0.2–1 mg) and
    // navigation (10–100 µg) bias instability.
    assert_eq!(
        accel(Parameter::BiasInstability, 150.0),
        between(AccelGrade::Tactical.index(), AccelGrade::Navigation.index())
    );
    let c = classify(
        &GYRO_TABLE,
        &[(Parameter::Noise, 0.01), (Parameter::BiasInstability, 0.5)],
    )
    .unwrap();
    assert_eq!(
        c.overall.describe(&GYRO_TABLE).to_string(),
        "between tactical and aviation"
    );
    assert_eq!(
        c.decided_by().collect::<Vec<_>>(),
        [Parameter::BiasInstability]
    );
}

#[test]
fn worse_than_every_row_is_said_so() {
    assert_eq!(
        gyro(Parameter::ScaleFactorInstability, 2.0),
        Placement::Worse
    );
    assert_eq!(accel(Parameter::Noise, 8000.0), Placement::Worse);
    assert_eq!(accel(Parameter::BiasInstability, 200e3), Placement::Worse);
    let c = classify(
        &ACCEL_TABLE,
        &[
            (Parameter::Noise, 8000.0),
            (Parameter::BiasInstability, 500.0),
        ],
    )
    .unwrap();
    assert_eq!(
        c.overall.describe(&ACCEL_TABLE).to_string(),
        "worse than automotive"
    );
    assert_eq!(c.decided_by().collect::<Vec<_>>(), [Parameter::Noise]);
}

#[test]
fn the_worst_parameter_decides() {
    // Tactical ARW with a rate-grade bias instability: rate grade, decided by B.
    let c = classify(
        &GYRO_TABLE,
        &[(Parameter::Noise, 0.15), (Parameter::BiasInstability, 50.0)],
    )
    .unwrap();
    assert_eq!(c.overall, Placement::In(GyroGrade::RateGrade.index()));
    assert_eq!(
        c.decided_by().collect::<Vec<_>>(),
        [Parameter::BiasInstability]
    );
    // Both in the same grade: both decide.
    let c = classify(
        &GYRO_TABLE,
        &[(Parameter::Noise, 0.01), (Parameter::BiasInstability, 0.03)],
    )
    .unwrap();
    assert_eq!(c.overall, Placement::In(GyroGrade::Aviation.index()));
    assert_eq!(c.decided_by().count(), 2);
    // A scale-factor instability given ranks too: 0.05 % is tactical.
    let c = classify(
        &GYRO_TABLE,
        &[
            (Parameter::Noise, 0.01),
            (Parameter::BiasInstability, 0.03),
            (Parameter::ScaleFactorInstability, 0.05),
        ],
    )
    .unwrap();
    assert_eq!(c.overall, Placement::In(GyroGrade::Tactical.index()));
    assert_eq!(
        c.decided_by().collect::<Vec<_>>(),
        [Parameter::ScaleFactorInstability]
    );
}

#[test]
fn range_and_bandwidth_list_the_grades_they_fit_and_rank_nothing() {
    let c = classify(
        &GYRO_TABLE,
        &[
            (Parameter::Noise, 0.01),
            (Parameter::BiasInstability, 0.03),
            (Parameter::Range, 250.0),
            (Parameter::Bandwidth, 120.0),
        ],
    )
    .unwrap();
    // 250 °/s: rate grade (50–1000) and aviation (50–300).
    assert_eq!(
        c.of(Parameter::Range).unwrap().verdict,
        Verdict::Fits(0b0101)
    );
    // 120 Hz: rate grade (> 70), aviation (≈ 100) and navigation (100–500).
    assert_eq!(
        c.of(Parameter::Bandwidth).unwrap().verdict,
        Verdict::Fits(0b1101)
    );
    assert_eq!(c.overall, Placement::In(GyroGrade::Aviation.index()));
}

#[test]
fn bad_inputs_are_refused_with_their_value() {
    let e = classify(&GYRO_TABLE, &[(Parameter::Noise, -1.0)]).unwrap_err();
    assert_eq!(
        e,
        GradeError::BadValue {
            parameter: Parameter::Noise,
            value: -1.0
        }
    );
    assert!(e.to_string().contains("white noise = -1"), "{e}");
    assert!(matches!(
        classify(&GYRO_TABLE, &[(Parameter::Noise, f64::NAN)]),
        Err(GradeError::BadValue { .. })
    ));
    assert_eq!(
        classify(&ACCEL_TABLE, &[(Parameter::Cost, 1.0)]).unwrap_err(),
        GradeError::NoRow(Parameter::Cost)
    );
    assert_eq!(
        classify(&GYRO_TABLE, &[(Parameter::Range, 100.0)]).unwrap_err(),
        GradeError::NothingRanks
    );
    assert_eq!(
        classify(
            &GYRO_TABLE,
            &[(Parameter::Noise, 0.1), (Parameter::Noise, 0.2)]
        )
        .unwrap_err(),
        GradeError::Repeated(Parameter::Noise)
    );
}
