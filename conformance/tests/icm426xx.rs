//! The published `icm426xx` driver (crates.io 0.4, ICM-42688-P over SPI;
//! its data path is the 20-bit FIFO packet 4) against triad-sim's
//! ICM-42688-P model: start-up (soft reset, WHO_AM_I, banks 0–2 written by
//! read-modify-write), every output data rate, data, temperature and
//! timestamps from the FIFO, compared with the truth the model was given.
//!
//! The driver fixes the ranges (packet 4 is always ±16 g, ±2000 °/s) and
//! reads no data registers, so "every range" is one range here.

use std::cell::RefCell;

use icm426xx::{Config, OutputDataRate, Sample, Timestamp, ICM42688};
use triad_conformance::{assert_within_lsb, Truth};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};

/// Every rate the driver offers, with its period in ns.
const RATES: [(OutputDataRate, u64); 12] = [
    (OutputDataRate::Hz32000, 31_250),
    (OutputDataRate::Hz16000, 62_500),
    (OutputDataRate::Hz8000, 125_000),
    (OutputDataRate::Hz4000, 250_000),
    (OutputDataRate::Hz2000, 500_000),
    (OutputDataRate::Hz1000, 1_000_000),
    (OutputDataRate::Hz500, 2_000_000),
    (OutputDataRate::Hz200, 5_000_000),
    (OutputDataRate::Hz100, 10_000_000),
    (OutputDataRate::Hz50, 20_000_000),
    (OutputDataRate::Hz25, 40_000_000),
    (OutputDataRate::Hz12_5, 80_000_000),
];

/// Samples per run: below the 102 packets 4 the 2 KiB FIFO holds (the
/// driver sets stop-on-full mode and reports a full FIFO as an error).
const SAMPLES: u64 = 40;

/// The driver's wait after writing PWR_MGMT0.
const POWER_ON_WAIT_NS: u64 = 200_000;

/// DS-000347 §6.1: packet 4 holds 18-bit accelerometer data at 8192 LSB/g
/// in a 20-bit field (4 field units per LSB), ±16 g.
const ACCEL_G_PER_FIELD_UNIT: f64 = 1.0 / 32768.0;
/// DS-000347 §6.1: 19-bit gyroscope data at 131 LSB/(°/s) in the 20-bit
/// field (2 units per LSB). The driver scales by the power-of-two full
/// scale, 2000 °/s per 2^19 (262.144 units per °/s), the model by the data
/// sheet's rounded nominal 131 (262 units per °/s): they differ by 0.054 %,
/// a rounding of the nominal sensitivity, not a disagreement on the data.
const GYRO_NOMINAL_ROUNDING: f64 = 1.0 - 262.0 / 262.144;

fn run(rate: OutputDataRate, period_ns: u64, truth: Truth) -> (Vec<Sample>, Icm42688Model<Truth>) {
    let model = RefCell::new(Icm42688Model::new(truth));
    let config = Config {
        rate,
        ..Config::default()
    };
    let imu = ICM42688::new(SharedBus(&model));
    let mut imu = imu
        .initialize(ModelDelay::new(&model), config)
        .unwrap_or_else(|e| panic!("start-up at {period_ns} ns: {e:?}"));
    model.borrow_mut().advance(SAMPLES * period_ns);
    let mut samples = Vec::new();
    loop {
        match imu.read_sample() {
            Ok(Some((sample, more))) => {
                samples.push(sample);
                if !more {
                    break;
                }
            }
            Ok(None) => break,
            Err(e) => panic!("FIFO read at {period_ns} ns: {e:?}"),
        }
    }
    let _ = imu.release();
    (samples, model.into_inner())
}

#[test]
fn every_rate_delivers_each_sample_once_with_its_timestamp() {
    let truth = Truth::within(16.0, 2000.0);
    for (rate, period_ns) in RATES {
        let (samples, model) = run(rate, period_ns, truth);
        // The driver waits 200 µs after turning the sensors on (DS-000347
        // §12.9), time in which the chip samples too.
        let expected = SAMPLES + POWER_ON_WAIT_NS / period_ns;
        assert_eq!(samples.len() as u64, expected, "samples at {period_ns} ns");
        // The driver's default: TMST_DELTA_EN, TMST_RES 16 µs. The first
        // packet's delta counts from power-on; every later one is one period.
        let ticks: Vec<u16> = samples
            .iter()
            .map(|s| match s.timestamp {
                Timestamp::OdrTimestamp(t) => t,
                ref other => panic!("{other:?} at {period_ns} ns"),
            })
            .collect();
        let period_ticks = period_ns as f64 / 16_000.0;
        for &t in &ticks[1..] {
            assert!(
                (f64::from(t) - period_ticks).abs() < 1.0,
                "delta {t} ticks at a {period_ticks}-tick period"
            );
        }
        let n = (ticks.len() - 1) as f64;
        let mean = ticks[1..].iter().map(|&t| f64::from(t)).sum::<f64>() / n;
        assert!((mean - period_ticks).abs() <= 1.0 / n, "mean delta {mean}");
        triad_conformance::assert_all_modelled(model.unmodelled());
    }
}

#[test]
fn fifo_data_agree_with_the_truth() {
    for truth in [Truth::within(16.0, 2000.0), Truth::within(0.01, 1.0)] {
        let (samples, _) = run(OutputDataRate::Hz1000, 1_000_000, truth);
        for sample in &samples {
            let (ax, ay, az) = sample.accel.expect("accel in every packet");
            let (gx, gy, gz) = sample.gyro.expect("gyro in every packet");
            let g = truth.accel_g();
            for (axis, got) in [ax, ay, az].into_iter().enumerate() {
                // Half an 18-bit LSB (4 field units).
                let got_g = f64::from(got) / triad_conformance::STANDARD_GRAVITY;
                assert_within_lsb("accel", got_g, g[axis], 4.0 * ACCEL_G_PER_FIELD_UNIT, 0.5);
            }
            let dps = truth.gyro_dps();
            for (axis, got) in [gx, gy, gz].into_iter().enumerate() {
                let got_dps = f64::from(got).to_degrees();
                let rounding = GYRO_NOMINAL_ROUNDING * dps[axis].abs();
                let lsb = 1.0 / 131.0;
                assert!(
                    (got_dps - dps[axis]).abs() <= 0.5 * lsb + rounding + 1e-6 * dps[axis].abs(),
                    "gyro {axis}: driver {got_dps} °/s, truth {}",
                    dps[axis]
                );
            }
        }
    }
}

#[test]
fn temperature_is_the_data_sheets_16_bit_value_the_driver_scales_wrongly() {
    // Peer bug (PEER_BUGS.md, icm426xx 1): DS-000347 §6.1 gives packet 4's
    // temperature as 16 bits at 132.48 LSB/°C (the 2.07 LSB/°C scale is
    // packet 3's 8-bit field); the driver divides the 16-bit value by 2.07
    // and reads it unsigned. The model's side: undo the driver's scaling and
    // read the field as the data sheet says.
    let truth = Truth::within(1.0, 100.0);
    let (samples, _) = run(OutputDataRate::Hz1000, 1_000_000, truth);
    for sample in &samples {
        let field = ((f64::from(sample.temperature_celsius) - 25.0) * 2.07).round();
        let celsius = f64::from(field as u16 as i16) / 132.48 + 25.0;
        assert_within_lsb("temperature", celsius, truth.celsius(), 1.0 / 132.48, 0.5);
        assert!((f64::from(sample.temperature_celsius) - truth.celsius()).abs() > 100.0);
    }
}

#[test]
fn start_up_leaves_the_chip_as_the_driver_configured_it() {
    let model = RefCell::new(Icm42688Model::new(Truth::within(1.0, 100.0)));
    let imu = ICM42688::new(SharedBus(&model));
    let imu = imu
        .initialize(ModelDelay::new(&model), Config::default())
        .unwrap();
    let _ = imu.release();
    let model = model.into_inner();
    // Banks 1 and 2 hold the anti-alias filter it chose for 200 Hz (DELT 2,
    // DELTSQR 4, BITSHIFT 13), written by read-modify-write over the reset values.
    assert_eq!(model.peek_bank(1, 0x0C), 2);
    assert_eq!(model.peek_bank(1, 0x0D), 4);
    assert_eq!(model.peek_bank(1, 0x0E), 13 << 4);
    assert_eq!(model.peek_bank(2, 0x03), 2 << 1);
    assert_eq!(model.peek_bank(2, 0x05), 13 << 4);
    // FIFO_CONFIG: stop-on-full. FIFO_CONFIG1: HIRES, TEMP, GYRO, ACCEL, FIFO_WM_GT_TH.
    assert_eq!(
        model.peek(0x16),
        0xC0,
        "FIFO_CONFIG {:#04x}",
        model.peek(0x16)
    );
    assert_eq!(model.peek(0x5F), 0x37);
    // INTF_CONFIG0 UI_SIFS_CFG = 11: the driver switched I²C off.
    assert_eq!(
        model.peek(0x4C),
        0x33,
        "INTF_CONFIG0 {:#04x}",
        model.peek(0x4C)
    );
    let mut model = model;
    let mut b = [0u8];
    let i2c = embedded_hal::i2c::I2c::write_read(&mut model, 0x68, &[0x75], &mut b);
    assert!(i2c.is_err(), "I²C answers after the driver disabled it");
}
