//! The published `lsm6ds3tr` driver (crates.io 0.2) for the LSM6DS3TR-C, an
//! earlier relative with the LSM6DSOX's data registers, control registers
//! and scales, against triad-sim's LSM6DSOX model over both buses it
//! supports: SPI (an `SpiBus` with the driver holding chip select, through
//! triad-sim's `spi_wire`) and I²C (0x6A). Every full-scale range,
//! accelerometer, gyroscope and temperature data against the truth. The
//! identity differs by design (LSM6DS3TR-C 0x6A, LSM6DSOX 0x6C): the
//! driver's `is_reachable` says no, as it should.

use std::cell::RefCell;

use lsm6ds3tr::interface::{I2cInterface, Interface, SpiInterface};
use lsm6ds3tr::{AccelScale, AccelSettings, GyroSettings, LsmSettings, LSM6DS3TR};
use triad_conformance::{assert_within_lsb, Truth};
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::model_clock::SharedBus;
use triad_sim::chips::spi_wire::{WireBus, WireChipSelect};

const ACCEL: [(AccelScale, f64, f64); 4] = [
    (AccelScale::_2G, 2.0, 0.061),
    (AccelScale::_4G, 4.0, 0.122),
    (AccelScale::_8G, 8.0, 0.244),
    (AccelScale::_16G, 16.0, 0.488),
];

/// The driver keeps its `GyroScale` type private, so its default ±250 °/s
/// is the only gyro range a user can choose: (full scale °/s, DS mdps/LSB).
const GYRO: (f64, f64) = (250.0, 8.75);

fn check<I: Interface>(imu: &mut LSM6DS3TR<I>, truth: &Truth, mg: f64, mdps: f64)
where
    I::Error: core::fmt::Debug,
{
    let accel = imu.read_accel().unwrap();
    let want = truth.accel_g();
    for (axis, got) in [accel.x, accel.y, accel.z].into_iter().enumerate() {
        assert_within_lsb("accel", f64::from(got), want[axis], mg * 1e-3, 0.5);
    }
    let gyro = imu.read_gyro().unwrap();
    let want = truth.gyro_dps();
    for (axis, got) in [gyro.x, gyro.y, gyro.z].into_iter().enumerate() {
        assert_within_lsb("gyro", f64::from(got), want[axis], mdps * 1e-3, 0.5);
    }
    let celsius = f64::from(imu.read_temp().unwrap());
    assert_within_lsb("temperature", celsius, truth.celsius(), 1.0 / 256.0, 0.5);
}

/// The driver's settings for accelerometer range `a`, 416 Hz.
fn settings(a: AccelScale) -> LsmSettings {
    LsmSettings::basic()
        .with_accel(AccelSettings::new().with_scale(a))
        .with_gyro(GyroSettings::new())
}

/// Every accelerometer range, the driver reading through `$bus` (an
/// expression of `model`, the shared chip model); `$reset`: whether the
/// driver soft-resets the chip first.
macro_rules! every_range {
    (|$model:ident| $bus:expr, $reset:expr) => {
        for &(accel_scale, accel_fs, mg) in &ACCEL {
            let (gyro_fs, mdps) = GYRO;
            let truth = Truth::within(accel_fs, gyro_fs);
            let $model = RefCell::new(Lsm6dsoxModel::new(truth));
            let mut imu = LSM6DS3TR::new($bus).with_settings(settings(accel_scale));
            assert!(
                !imu.is_reachable().unwrap(),
                "identity 0x6C is not an LSM6DS3TR-C"
            );
            if $reset {
                imu.software_reset().unwrap();
            }
            imu.init().unwrap();
            $model.borrow_mut().advance(10_000_000);
            check(&mut imu, &truth, mg, mdps);
            triad_conformance::assert_all_modelled($model.borrow().unmodelled());
        }
    };
}

#[test]
fn spi_every_range_agrees_with_the_truth() {
    every_range!(
        |model| SpiInterface::new(WireBus(&model), WireChipSelect(&model)),
        true
    );
}

#[test]
fn i2c_every_range_agrees_with_the_truth() {
    every_range!(|model| I2cInterface::new(SharedBus(&model)), false);
}
