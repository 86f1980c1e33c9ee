//! `triad calib fit imu`'s whole fit (static detection, the accelerometer,
//! the moves' checks and the gyro's integration fit) on a 10-minute 400 Hz
//! hand-pose record (109 poses of 4 s, turns of 1.5 s: 240 000 samples),
//! timed by criterion around `fit_imu::fit_record` only (the record is made
//! outside the clock; reading CSV is not in it).
//!
//! `cargo bench -p triad-host --bench fit_imu`; `cargo xtask bench` runs it
//! and writes its time into docs/BENCHMARKS.md.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use triad_host::calib::fit_csv::{self, Record};
use triad_host::calib::fit_imu;
use triad_lab::calib_fit::hand_record::{self, Axes, Script};
use triad_sim::effects::rng::Rng;

/// Samples per second of the benchmark's record.
pub const RATE_HZ: f64 = 400.0;

fn record() -> (Record, Record) {
    let unit = hand_record::MEMS_UNIT;
    let script = Script {
        rate_hz: RATE_HZ,
        poses: 109,
        static_s: 4.0,
        turn_s: 1.5,
        angle_deg: (60.0, 150.0),
        axes: Axes::Any,
        drift: None,
    };
    let mut rng = Rng::from_seed(9);
    let mut samples = Vec::new();
    hand_record::generate(&script, &unit, &mut || rng.uniform(), |s| {
        samples.push((s.t, s.accel, s.gyro))
    });
    fit_csv::imu_records(Path::new("bench-hand-400hz.csv"), samples)
}

fn fit_imu(c: &mut Criterion) {
    let (accel, gyro) = record();
    let full_scale = 2000f64.to_radians();
    // Refused fits would time the refusal: check it fits first.
    fit_imu::fit_record(&accel, &gyro, 9.80665, 2.0, full_scale).expect("the record fits");
    let mut group = c.benchmark_group("fit_imu");
    group.sample_size(10);
    group.bench_function("hand_10min_400hz", |b| {
        b.iter(|| fit_imu::fit_record(&accel, &gyro, 9.80665, 2.0, full_scale).unwrap())
    });
    group.finish();
}

criterion_group!(benches, fit_imu);
criterion_main!(benches);
