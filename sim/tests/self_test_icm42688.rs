//! The ICM-42688-P self-test against the chip model: the procedure writes
//! TDK InvenSense's register sequence, a unit whose response matches its
//! factory trim passes and reports that response, the ratio window and the
//! absolute limits (factory code 0) decide as published, a moving chip fails
//! on its offset, and the configuration is the same before and after
//! (sampling resumes). Dead axes and bus failures: `self_test_any_chip.rs`.

mod common;

use std::cell::RefCell;

use common::self_test::{
    assert_duration, assert_passes_and_keeps_configuration, assert_reports_emulated, assert_still,
    response_tolerance, spi_read, NoisyRest, WriteLog,
};
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::model::Triad;
use triad::sensor::icm42688::{
    AccelRange, Config, FifoConfig, FifoMode, GyroRange, Icm42688, Icm42688Chip, InterruptPin, Odr,
};
use triad::sensor::interface::SpiInterface;
use triad::sensor::self_test::{si_per_data_sheet_unit, SelfTestLimits};
use triad::sensor::{Axis, ChipSelfTest, Imu, SelfTestReport};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_sim::chips::icm42688_factory_trim::FactoryTrim;
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::model_clock::{ModelDelay, SharedBus};
use triad_sim::chips::self_test_response::SelfTestResponse;

type Model = Icm42688Model<NoisyRest>;

/// Per-sample noise: 2 mg and 0.2 °/s (about 30 and 6 times the chip's at 1 kHz
/// with its 100 Hz filter), so "equal within noise" is a real bound.
const ACCEL_SIGMA_MG: f64 = 2.0;
const GYRO_SIGMA_DPS: f64 = 0.2;
/// TDK's procedure averages 200 samples with self-test off and 200 on.
const AVERAGED: f64 = 200.0;

fn rest(seed: u64) -> NoisyRest {
    NoisyRest::with_data_sheet_noise(seed, ACCEL_SIGMA_MG, GYRO_SIGMA_DPS)
}

fn model(seed: u64) -> RefCell<Model> {
    RefCell::new(Icm42688Model::new(rest(seed)))
}

fn started<'m>(
    model: &'m RefCell<Model>,
    config: &Config,
) -> Icm42688<SpiInterface<SharedBus<'m, Model>>> {
    let mut imu = Icm42688::new_spi(SharedBus(model));
    imu.init(&mut NoopDelay::new(), config).expect("init");
    imu
}

fn run(model: &RefCell<Model>) -> SelfTestReport {
    let mut imu = started(model, &Config::default());
    imu.self_test(&mut ModelDelay::new(model))
        .expect("the self-test finishes")
}

/// The noise's 5 σ plus one LSB at the test's full scale (±4 g: 1/8.192
/// mg; ±250 °/s: 1/131 °/s).
fn tolerance(triad: Triad) -> f64 {
    match triad {
        Triad::Accel => response_tolerance(triad, ACCEL_SIGMA_MG, AVERAGED, 1.0 / 8.192),
        Triad::Gyro => response_tolerance(triad, GYRO_SIGMA_DPS, AVERAGED, 1.0 / 131.0),
    }
}

/// The factory response a code encodes, in data-sheet units at the test's
/// full scale, by TDK's equation written out here: round(2620 / 2^(3 −
/// FS_SEL) × 1.01^(code − 1)) LSB; FS_SEL 2 (±4 g, 8192 LSB/g) for the
/// accelerometer, 3 (±250 °/s, 131 LSB/(°/s)) for the gyroscope.
fn factory(triad: Triad, code: u8) -> f64 {
    let lsb_at_3 = 2620.0 * 1.01f64.powi(i32::from(code) - 1);
    match triad {
        Triad::Accel => (lsb_at_3 / 2.0).round() / 8.192,
        Triad::Gyro => lsb_at_3.round() / 131.0,
    }
}

fn with_self_test(seed: u64, trim: FactoryTrim, response: SelfTestResponse) -> RefCell<Model> {
    RefCell::new(Icm42688Model::new(rest(seed)).with_self_test(trim, response))
}

#[test]
fn a_sound_unit_passes_and_reports_the_emulated_response() {
    let model = model(1);
    let emulated = model.borrow().self_test_response();
    let report = run(&model);
    assert_reports_emulated(&report, &emulated, tolerance);
}

#[test]
fn the_limits_are_relative_to_the_factory_codes() {
    let report = run(&model(12));
    let trim = FactoryTrim::TYPICAL;
    for (triad, result, codes) in [
        (Triad::Accel, report.accel, trim.accel),
        (Triad::Gyro, report.gyro, trim.gyro),
    ] {
        for axis in Axis::ALL {
            let f = factory(triad, codes[axis.index()]);
            let limits = result.axes[axis.index()].limits;
            assert!((limits.factory.expect("a factory value") - f).abs() < 1e-9 * f);
            assert!((limits.min - 0.5 * f).abs() < 1e-9 * f);
            assert!((limits.max - 1.5 * f).abs() < 1e-9 * f);
            // Only the gyroscope's self-test-off output is bounded: 20 °/s.
            let max_offset = (triad == Triad::Gyro).then_some(20.0);
            assert_eq!(limits.max_offset, max_offset);
        }
    }
}

#[test]
fn the_ratio_to_the_factory_response_decides() {
    let trim = FactoryTrim::TYPICAL;
    // The default unit is 4 % stronger than its factory trim.
    for (factor, passes) in [
        (0.45, false),
        (0.55, true),
        (1.04, true),
        (1.45, true),
        (1.55, false),
    ] {
        let model = with_self_test(2, trim, trim.response().scaled(factor));
        let report = run(&model);
        assert_eq!(report.passed(), passes, "× {factor}: {report:?}");
        assert_eq!(
            report.failures().count(),
            if passes { 0 } else { 6 },
            "× {factor}"
        );
    }
}

#[test]
fn an_axis_without_a_factory_code_is_held_to_the_absolute_limits() {
    // Code 0 (no factory value) on accelerometer x and gyroscope y.
    let trim = FactoryTrim {
        accel: [0, 119, 122],
        gyro: [150, 0, 156],
    };
    let typical = FactoryTrim::TYPICAL.response();
    let response = |accel_x_mg: f64, gyro_y_dps: f64| {
        let mut r = typical;
        r.accel[0] = accel_x_mg * si_per_data_sheet_unit(Triad::Accel);
        r.gyro[1] = gyro_y_dps * si_per_data_sheet_unit(Triad::Gyro);
        r
    };
    // 1300 mg is above the accelerometer's 1200 mg; 50 °/s below the gyroscope's 60 °/s.
    let report = run(&with_self_test(3, trim, response(1300.0, 50.0)));
    assert_eq!(
        report.failures().collect::<Vec<_>>(),
        [(Triad::Accel, Axis::X), (Triad::Gyro, Axis::Y)]
    );
    assert_eq!(
        report.accel.axes[0].limits,
        SelfTestLimits::fixed(50.0, 1200.0)
    );
    assert_eq!(
        report.gyro.axes[1].limits,
        SelfTestLimits::fixed(60.0, f64::INFINITY).with_max_offset(20.0)
    );
    let report = run(&with_self_test(3, trim, response(1100.0, 70.0)));
    assert!(report.passed(), "{report:?}");
}

#[test]
fn a_chip_turning_faster_than_20_dps_fails_on_its_offset() {
    let mut source = rest(5);
    source.rate = [0.0, 0.0, deg_to_rad(30.0)];
    let model = RefCell::new(Icm42688Model::new(source));
    let report = run(&model);
    assert_eq!(
        report.failures().collect::<Vec<_>>(),
        [(Triad::Gyro, Axis::Z)]
    );
    let z = report.gyro.axes[2];
    assert!(z.response_ok && !z.offset_ok, "{z:?}");
    assert!((z.off - deg_to_rad(30.0)).abs() < deg_to_rad(0.1), "{z:?}");
}

fn unusual_config() -> Config {
    Config {
        accel_range: AccelRange::G8,
        gyro_range: GyroRange::Dps500,
        accel_odr: Odr::Hz200,
        gyro_odr: Odr::Hz200,
        interrupt: InterruptPin {
            active_high: false,
            push_pull: false,
            latched: true,
        },
        fifo: Some(FifoConfig {
            watermark: 50,
            mode: FifoMode::Stream,
            high_resolution: false,
        }),
    }
}

#[test]
fn the_configuration_is_the_same_after_and_sampling_resumes() {
    let model = model(6);
    let mut imu = started(&model, &unusual_config());
    assert_passes_and_keeps_configuration(&model, |delay| imu.self_test(delay));
    assert_eq!(spi_read(&model, 0x76), 0, "REG_BANK_SEL: bank 0");
    // The FIFO held self-test samples: flushed, then it fills at the configured 200 Hz.
    assert_eq!(model.borrow().fifo_len(), 0);
    model.borrow_mut().advance(10 * 5_000_000);
    assert_eq!(model.borrow().fifo_len(), 10);
    // 6 σ of one sample's noise (2 mg, 0.2 °/s).
    let sample = imu.read_new_sample().expect("a new sample");
    assert_still(
        &sample,
        &imu.scale(),
        0.012 * STANDARD_GRAVITY,
        deg_to_rad(1.2),
    );
}

#[test]
fn the_procedure_writes_tdks_sequence_then_writes_back() {
    let model = model(7);
    let mut imu = Icm42688::new_spi(WriteLog::new(&model));
    imu.init(&mut NoopDelay::new(), &Config::default())
        .expect("init");
    let init_writes = imu.bus().writes.len();
    imu.self_test(&mut ModelDelay::new(&model))
        .expect("finishes");
    let writes = &imu.bus().writes[init_writes..];
    // After the default init: PWR_MGMT0 0Fh, GYRO_CONFIG0 06h, ACCEL_CONFIG0
    // 06h, and at their reset values GYRO_CONFIG1 16h, GYRO_ACCEL_CONFIG0 11h,
    // ACCEL_CONFIG1 0Dh, SELF_TEST_CONFIG 00h.
    let expected = [
        // Gyroscope: UI filter third order (GYRO_CONFIG1 1Ah), bandwidth
        // ODR/10 (GYRO_ACCEL_CONFIG0 14h), ±250 °/s at 1 kHz (GYRO_CONFIG0 66h).
        (0x51, 0x1A),
        (0x52, 0x14),
        (0x4F, 0x66),
        // Off: gyroscope on (low noise) ... off.
        (0x4E, 0x0C),
        (0x4E, 0x00),
        // On: gyroscope on, EN_GX/GY/GZ_ST ... off, self-test off.
        (0x4E, 0x0C),
        (0x70, 0x07),
        (0x4E, 0x00),
        (0x70, 0x00),
        // Factory codes in bank 1.
        (0x76, 0x01),
        (0x76, 0x00),
        // Accelerometer: bandwidth ODR/10 (44h), third order (ACCEL_CONFIG1
        // 15h), ±4 g at 1 kHz (ACCEL_CONFIG0 46h).
        (0x52, 0x44),
        (0x53, 0x15),
        (0x50, 0x46),
        (0x4E, 0x03),
        (0x4E, 0x00),
        // On: EN_AX/AY/AZ_ST and ACCEL_ST_POWER.
        (0x4E, 0x03),
        (0x70, 0x78),
        (0x4E, 0x00),
        (0x70, 0x00),
        (0x76, 0x02),
        (0x76, 0x00),
        // Write-back: bank 0, SELF_TEST_CONFIG, the configuration, PWR_MGMT0
        // last; then FIFO_FLUSH.
        (0x76, 0x00),
        (0x70, 0x00),
        (0x4F, 0x06),
        (0x50, 0x06),
        (0x51, 0x16),
        (0x52, 0x11),
        (0x53, 0x0D),
        (0x4E, 0x0F),
        (0x4B, 0x02),
    ];
    assert_eq!(writes, expected);
}

#[test]
fn it_takes_tdks_waits_and_samples_within_the_stated_bound() {
    let model = model(8);
    let mut imu = started(&model, &Config::default());
    // Waits: gyroscope 60 + 60 + 200 ms, accelerometer 25 + 25 + 25 ms,
    // 200 ms after the write-back; four passes of 200 samples at 1 kHz, each
    // at least 199 periods from its first sample to its last.
    let least = 595.0 + 4.0 * 199.0;
    assert_duration(
        &model,
        least,
        Icm42688Chip::self_test_max_duration_ms(),
        |delay| imu.self_test(delay),
    );
}
