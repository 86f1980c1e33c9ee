//! `triad calib fit thermal`'s whole fit (the lab's `thermal::fit`: static
//! detection, the segments cut by temperature, the accelerometer's thermal
//! fit, the gyro's bias polynomial and its (I+Σ) against temperature from
//! the turns) on three hand-turned soaks of one unit at −10, 25 and 60 °C
//! (`hand_record::SESSION` each: 14 poses, 39 moves in all, 100 Hz), timed
//! by criterion around that fit only (the records are made outside the
//! clock; reading CSV and the report are not in it).
//!
//! `cargo bench -p triad-host --bench fit_thermal`.

use criterion::{criterion_group, criterion_main, Criterion};
use triad_lab::calib_fit::fits::thermal::{self, ThermalOptions, ThermalRecord};
use triad_lab::calib_fit::hand_record::{self, Recorded, TriadTruth, Unit};
use triad_lab::calib_fit::poses;
use triad_sim::effects::rng::Rng;

const SOAKS_C: [f64; 3] = [-10.0, 25.0, 60.0];

/// `truth` with its (I+Σ) columns scaled by 1 + `per_c`·(T − 25 °C).
fn at(truth: TriadTruth, per_c: [f64; 3], temperature: f64) -> TriadTruth {
    let d = temperature - 25.0;
    let m = truth.scale_misalignment;
    TriadTruth {
        scale_misalignment: core::array::from_fn(|i| {
            core::array::from_fn(|j| m[i][j] * (1.0 + per_c[j] * d))
        }),
        ..truth
    }
}

/// One soak's record and its temperature at every sample.
fn soak(temperature: f64, rng: &mut Rng) -> (Recorded, Vec<f64>) {
    let base = hand_record::MEMS_UNIT;
    let unit = Unit {
        accel: at(base.accel, [5e-5, -3e-5, 4e-5], temperature),
        gyro: at(base.gyro, [1e-4, -8e-5, 6e-5], temperature),
        ..base
    };
    let record = hand_record::recorded(&hand_record::SESSION, &unit, &mut || rng.uniform());
    let temperatures = vec![temperature; record.t.len()];
    (record, temperatures)
}

fn fit_thermal(c: &mut Criterion) {
    let mut rng = Rng::from_seed(4);
    let soaks: Vec<(Recorded, Vec<f64>)> = SOAKS_C.iter().map(|&t| soak(t, &mut rng)).collect();
    let records: Vec<ThermalRecord> = soaks
        .iter()
        .map(|(r, temperature)| ThermalRecord {
            t: &r.t,
            accel: &r.accel,
            gyro: &r.gyro,
            temperature,
            detector: poses::detector(hand_record::SESSION.rate_hz, 2.0),
        })
        .collect();
    let options = ThermalOptions {
        gravity: hand_record::MEMS_UNIT.gravity,
        full_scale: 2000f64.to_radians(),
        gyro_only: false,
    };
    // Refused fits, or fits without the gyro's (I+Σ)(T), would time the
    // wrong thing: check first.
    let fit = thermal::fit(&records, &options).expect("the soaks fit");
    assert!(fit.gyro_scale.is_ok(), "{:?}", fit.gyro_scale);
    let mut group = c.benchmark_group("fit_thermal");
    group.sample_size(10);
    group.bench_function("whole_3_soaks_100hz", |b| {
        b.iter(|| thermal::fit(&records, &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, fit_thermal);
criterion_main!(benches);
