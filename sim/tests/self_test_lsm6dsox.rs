//! The LSM6DSOX self-test against the chip model: the procedure writes
//! AN5272's register sequence, a unit with the emulated response passes and
//! reports that response, a response beyond DS12814's limits fails and is
//! named, and the configuration is the same before and after (sampling
//! resumes). Dead axes and bus failures: `self_test_any_chip.rs`.

mod common;

use std::cell::RefCell;

use common::self_test::{
    assert_duration, assert_passes_and_keeps_configuration, assert_reports_emulated, assert_still,
    response_tolerance, NoisyRest, WriteLog,
};
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::model::Triad;
use triad::sensor::interface::SpiInterface;
use triad::sensor::lsm6dsox::{
    AccelRange, Config, FifoConfig, FifoMode, GyroRange, InterruptPin, Lsm6dsox, Lsm6dsoxChip, Odr,
};
use triad::sensor::self_test::SelfTestLimits;
use triad::sensor::{Axis, ChipSelfTest, Imu, SelfTestReport};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};

type Model = Lsm6dsoxModel<NoisyRest>;

/// Per-sample noise: 2 mg and 0.5 °/s, far above the chip's (about 0.4 mg
/// and 0.04 °/s at these rates), so "equal within noise" is a real bound.
const ACCEL_SIGMA_MG: f64 = 2.0;
const GYRO_SIGMA_DPS: f64 = 0.5;
/// AN5272 averages five samples with self-test off and five on.
const AVERAGED: f64 = 5.0;

fn model(seed: u64) -> RefCell<Model> {
    let rest = NoisyRest::with_data_sheet_noise(seed, ACCEL_SIGMA_MG, GYRO_SIGMA_DPS);
    RefCell::new(Lsm6dsoxModel::new(rest))
}

fn started<'m>(
    model: &'m RefCell<Model>,
    config: &Config,
) -> Lsm6dsox<SpiInterface<SharedBus<'m, Model>>> {
    let mut imu = Lsm6dsox::new_spi(SharedBus(model));
    imu.init(&mut NoopDelay::new(), config).expect("init");
    imu
}

fn run(model: &RefCell<Model>, config: &Config) -> SelfTestReport {
    let mut imu = started(model, config);
    imu.self_test(&mut ModelDelay::new(model))
        .expect("the self-test finishes")
}

/// The noise's 5 σ plus one LSB at the test's full scale (±4 g: 0.122 mg;
/// ±2000 °/s: 70 mdps).
fn tolerance(triad: Triad) -> f64 {
    match triad {
        Triad::Accel => response_tolerance(triad, ACCEL_SIGMA_MG, AVERAGED, 0.122),
        Triad::Gyro => response_tolerance(triad, GYRO_SIGMA_DPS, AVERAGED, 0.070),
    }
}

#[test]
fn a_sound_unit_passes_and_reports_the_emulated_response() {
    let model = model(1);
    let emulated = model.borrow().self_test_response();
    let report = run(&model, &Config::default());
    assert_reports_emulated(&report, &emulated, tolerance);
}

#[test]
fn the_limits_are_ds12814s() {
    let report = run(&model(2), &Config::default());
    // DS12814 Table 2: LA_ST 50–1700 mg, G_ST 150–700 °/s (±2000 °/s).
    assert_eq!(
        report.accel.axes[0].limits,
        SelfTestLimits::fixed(50.0, 1700.0)
    );
    assert_eq!(
        report.gyro.axes[2].limits,
        SelfTestLimits::fixed(150.0, 700.0)
    );
}

#[test]
fn a_response_beyond_the_limits_fails() {
    use triad_sim::chips::self_test_response::SelfTestResponse;
    // 1800 mg and 100 °/s on x: above LA_ST's 1700 mg, below G_ST's 150 °/s.
    let response =
        SelfTestResponse::from_data_sheet_units([1800.0, 500.0, 500.0], [100.0, 300.0, 300.0]);
    let model = model(4);
    let model = RefCell::new(model.into_inner().with_self_test(response));
    let report = run(&model, &Config::default());
    let failures: Vec<_> = report.failures().collect();
    assert_eq!(failures, [(Triad::Accel, Axis::X), (Triad::Gyro, Axis::X)]);
}

fn unusual_config() -> Config {
    Config {
        accel_range: AccelRange::G8,
        gyro_range: GyroRange::Dps500,
        accel_odr: Odr::Hz104,
        gyro_odr: Odr::Hz104,
        interrupt: InterruptPin {
            active_high: false,
            push_pull: false,
            latched: true,
        },
        fifo: Some(FifoConfig {
            watermark: 100,
            mode: FifoMode::Stream,
            high_resolution: false,
        }),
    }
}

#[test]
fn the_configuration_is_the_same_after_and_sampling_resumes() {
    let model = model(5);
    let mut imu = started(&model, &unusual_config());
    assert_passes_and_keeps_configuration(&model, |delay| imu.self_test(delay));
    // The FIFO held self-test samples: it was emptied, and fills again at the configured rate.
    assert_eq!(model.borrow().fifo_len(), 0);
    // The tenth sample is due ⌈10 · 10¹² / rate[mHz]⌉ ns after the rates were written back.
    model
        .borrow_mut()
        .advance((10 * 1_000_000_000_000u64).div_ceil(u64::from(Odr::Hz104.millihertz())));
    assert_eq!(model.borrow().fifo_len(), 2 * 10);
    // A new sample is the still chip at the configured ranges, with no self-test in it.
    // 6 σ of one sample's noise (2 mg, 0.5 °/s).
    let sample = imu.read_new_sample().expect("a new sample");
    assert_still(
        &sample,
        &imu.scale(),
        0.012 * STANDARD_GRAVITY,
        deg_to_rad(3.0),
    );
}

#[test]
fn the_procedure_writes_an5272s_sequence_then_writes_back() {
    let model = model(6);
    let mut imu = Lsm6dsox::new_spi(WriteLog::new(&model));
    imu.init(&mut NoopDelay::new(), &Config::default())
        .expect("init");
    let init_writes = imu.bus().writes.len();
    imu.self_test(&mut ModelDelay::new(&model))
        .expect("finishes");
    let writes = &imu.bus().writes[init_writes..];
    // AN5272, accelerometer: CTRL1_XL = 38h, CTRL2_G = 00h, CTRL3_C = 44h,
    // CTRL4_C..CTRL10_C = 00h; CTRL5_C = 01h; then self-test and sensor off.
    let mut expected = vec![(0x10, 0x38), (0x11, 0x00), (0x12, 0x44)];
    expected.extend((0x13..=0x19).map(|r| (r, 0x00)));
    expected.extend([(0x14, 0x01), (0x14, 0x00), (0x10, 0x00)]);
    // Gyroscope: CTRL1_XL = 00h, CTRL2_G = 5Ch, CTRL3_C = 44h, the rest 00h;
    // CTRL5_C = 04h; then self-test and sensor off.
    expected.extend([(0x10, 0x00), (0x11, 0x5C), (0x12, 0x44)]);
    expected.extend((0x13..=0x19).map(|r| (r, 0x00)));
    expected.extend([(0x14, 0x04), (0x14, 0x00), (0x11, 0x00)]);
    assert_eq!(writes[..expected.len()], expected[..]);
    // Then the write-back of the default configuration: CTRL5_C, CTRL3_C =
    // 44h and CTRL4_C..CTRL10_C as they were (CTRL9_XL at its reset E0h, not
    // the 00h of the procedure), the rates (833 Hz, ±16 g; 833 Hz, ±2000
    // °/s), and the FIFO through bypass back to bypass.
    let restore = [
        (0x14, 0x00),
        (0x12, 0x44),
        (0x13, 0x00),
        (0x15, 0x00),
        (0x16, 0x00),
        (0x17, 0x00),
        (0x18, 0xE0),
        (0x19, 0x00),
        (0x10, 0x74),
        (0x11, 0x7C),
        (0x0A, 0x00),
        (0x0A, 0x00),
    ];
    assert_eq!(writes[expected.len()..], restore[..]);
}

#[test]
fn it_takes_the_an5272_waits_and_samples_within_the_stated_bound() {
    let model = model(7);
    let mut imu = started(&model, &Config::default());
    // Four 100 ms waits, and per pass at least four sample periods after
    // the discarded sample (the fifth new sample comes four periods after the first).
    let least = 400.0 + 2.0 * 4.0 * (1000.0 / 52.0) + 2.0 * 4.0 * (1000.0 / 208.0);
    assert_duration(
        &model,
        least,
        Lsm6dsoxChip::self_test_max_duration_ms(),
        |delay| imu.self_test(delay),
    );
}
