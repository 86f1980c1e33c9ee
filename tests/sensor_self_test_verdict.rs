//! The self-test verdict, chip-independent: fixed limits include their
//! bounds (ST: min ≤ |response| ≤ max), a factory ratio excludes them (TDK:
//! 0.5 < ratio < 1.5), the sign of a response does not matter, the
//! self-test-off output is bounded only when the limits say so, responses
//! convert to SI, and failures are named triad by triad, axis by axis.

use triad::model::Triad;
use triad::sensor::self_test::{AxisSelfTest, SelfTestLimits, TriadSelfTest};
use triad::sensor::{Axis, SelfTestReport};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

#[test]
fn fixed_limits_include_their_bounds() {
    let limits = SelfTestLimits::fixed(50.0, 1700.0);
    for (magnitude, accepted) in [
        (49.999, false),
        (50.0, true),
        (900.0, true),
        (1700.0, true),
        (1700.001, false),
    ] {
        assert_eq!(limits.accepts_response(magnitude), accepted, "{magnitude}");
    }
}

#[test]
fn a_factory_ratio_excludes_its_bounds() {
    let limits = SelfTestLimits::factory_ratio(100.0);
    assert_eq!(
        (limits.min, limits.max, limits.factory),
        (50.0, 150.0, Some(100.0))
    );
    for (magnitude, accepted) in [
        (50.0, false),
        (50.001, true),
        (149.999, true),
        (150.0, false),
    ] {
        assert_eq!(limits.accepts_response(magnitude), accepted, "{magnitude}");
    }
}

#[test]
fn the_offset_is_bounded_only_when_the_limits_say_so() {
    let unbounded = SelfTestLimits::fixed(150.0, 700.0);
    assert!(unbounded.accepts_offset(1e6));
    let bounded = unbounded.with_max_offset(20.0);
    assert!(bounded.accepts_offset(-20.0) && bounded.accepts_offset(20.0));
    assert!(!bounded.accepts_offset(20.001) && !bounded.accepts_offset(-20.001));
}

#[test]
fn an_axis_is_judged_on_its_magnitude_and_reported_in_si() {
    let limits = SelfTestLimits::fixed(150.0, 700.0);
    // A negative response of 300 °/s passes as a positive one would.
    let axis = AxisSelfTest::judge(Triad::Gyro, 10.0, -290.0, limits);
    assert!(axis.passed());
    assert_eq!(axis.response_data_sheet, -300.0);
    assert!((axis.response - deg_to_rad(-300.0)).abs() < 1e-12);
    assert!((axis.off - deg_to_rad(10.0)).abs() < 1e-12);
    // mg → m/s².
    let accel = AxisSelfTest::judge(
        Triad::Accel,
        1000.0,
        1500.0,
        SelfTestLimits::fixed(50.0, 1700.0),
    );
    assert!((accel.response - 0.5 * STANDARD_GRAVITY).abs() < 1e-12);
    assert!((accel.off - STANDARD_GRAVITY).abs() < 1e-12);
    // Too large an output at rest fails the axis though its response is fine.
    let moving = AxisSelfTest::judge(Triad::Gyro, 30.0, 330.0, limits.with_max_offset(20.0));
    assert!(moving.response_ok && !moving.offset_ok && !moving.passed());
}

#[test]
fn failures_are_named_accelerometer_first() {
    let accel_limits = [SelfTestLimits::fixed(50.0, 1700.0); 3];
    let gyro_limits = [SelfTestLimits::fixed(150.0, 700.0); 3];
    // Accelerometer z and gyroscope x respond too little.
    let accel = TriadSelfTest::judge(Triad::Accel, [0.0; 3], [500.0, 500.0, 10.0], accel_limits);
    let gyro = TriadSelfTest::judge(Triad::Gyro, [0.0; 3], [100.0, 300.0, 300.0], gyro_limits);
    let report = SelfTestReport { accel, gyro };
    assert!(!report.passed());
    assert_eq!(
        report.failures().collect::<Vec<_>>(),
        [(Triad::Accel, Axis::Z), (Triad::Gyro, Axis::X)]
    );
    assert_eq!(
        report
            .accel
            .failed_axes()
            .map(Axis::name)
            .collect::<Vec<_>>(),
        ["z"]
    );
}
