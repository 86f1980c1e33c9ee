//! The published `lsm6dso` driver (crates.io 0.2, blocking, I²C only) for
//! the LSM6DSOX's predecessor, which shares its identity (0x6C), data
//! registers and scales, against triad-sim's LSM6DSOX model: identity, every
//! full-scale range, accelerometer, gyroscope and temperature data, compared
//! with the truth the model was given. The driver has no FIFO support.

use std::cell::RefCell;

use lsm6dso::{
    AccelerometerOutput, AccelerometerScale, GyroscopeFullScale, GyroscopeOutput, Lsm6dso,
};
use triad_conformance::{assert_within_lsb, Truth, STANDARD_GRAVITY};
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::model_clock::SharedBus;

const ACCEL: [(AccelerometerScale, f64, f64); 4] = [
    (AccelerometerScale::G02, 2.0, 0.061),
    (AccelerometerScale::G04, 4.0, 0.122),
    (AccelerometerScale::G08, 8.0, 0.244),
    (AccelerometerScale::G16, 16.0, 0.488),
];

const GYRO: [(GyroscopeFullScale, f64, f64); 5] = [
    (GyroscopeFullScale::Dps125, 125.0, 4.375),
    (GyroscopeFullScale::Dps250, 250.0, 8.75),
    (GyroscopeFullScale::Dps500, 500.0, 17.5),
    (GyroscopeFullScale::Dps1000, 1000.0, 35.0),
    (GyroscopeFullScale::Dps2000, 2000.0, 70.0),
];

#[test]
fn every_range_agrees_with_the_truth() {
    for (address, sa0_high) in [(0x6A, false), (0x6B, true)] {
        for (i, &(gyro_scale, gyro_fs, mdps_per_lsb)) in GYRO.iter().enumerate() {
            let (accel_scale, accel_fs, mg_per_lsb) = ACCEL[i % ACCEL.len()];
            let truth = Truth::within(accel_fs, gyro_fs);
            let model = RefCell::new(Lsm6dsoxModel::new(truth).with_sa0(sa0_high));
            let mut imu = Lsm6dso::new(SharedBus(&model), address);
            imu.check().unwrap();
            imu.set_accelerometer_scale(accel_scale).unwrap();
            imu.set_gyroscope_scale(gyro_scale).unwrap();
            imu.set_accelerometer_output(AccelerometerOutput::Rate208)
                .unwrap();
            imu.set_gyroscope_output(GyroscopeOutput::Rate208).unwrap();
            assert!(!imu.accel_data_available().unwrap());
            model.borrow_mut().advance(10_000_000);
            assert!(imu.accel_data_available().unwrap() && imu.gyro_data_available().unwrap());
            let data = imu.read_all().unwrap();
            let accel = [data.accel_x, data.accel_y, data.accel_z];
            let want = truth.accel_g();
            for axis in 0..3 {
                let got_g = f64::from(accel[axis]) / STANDARD_GRAVITY;
                assert_within_lsb("accel", got_g, want[axis], mg_per_lsb * 1e-3, 0.5);
            }
            let gyro = [data.gyro_x, data.gyro_y, data.gyro_z];
            let want = truth.gyro_dps();
            for axis in 0..3 {
                let got_dps = f64::from(gyro[axis]).to_degrees();
                assert_within_lsb("gyro", got_dps, want[axis], mdps_per_lsb * 1e-3, 0.5);
            }
            assert_within_lsb(
                "temperature",
                f64::from(data.temp),
                truth.celsius(),
                1.0 / 256.0,
                0.5,
            );
            let model = model.borrow();
            triad_conformance::assert_all_modelled(model.unmodelled());
        }
    }
}
