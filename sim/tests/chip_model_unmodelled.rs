//! What the chip models do not model is reported, never aliased: reserved
//! addresses, unmodelled banks and pages and settings show in the model's
//! unmodelled log; triad's own driver, through start-up, data and FIFO,
//! touches none of it.

mod common;

use common::bus::{read1, write};
use common::RampSource;
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::sensor::icm42688::config::{Config as IcmConfig, FifoMode as IcmFifoMode};
use triad::sensor::icm42688::{FifoConfig as IcmFifo, Icm42688};
use triad::sensor::lsm6dsox::config::{Config as LsmConfig, FifoMode as LsmFifoMode};
use triad::sensor::lsm6dsox::{FifoConfig as LsmFifo, Lsm6dsox};
use triad::sensor::{FifoImu, Imu, RawSample};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;

#[test]
fn icm42688_reports_reserved_addresses_and_banks_3_and_4() {
    let mut chip = Icm42688Model::new(RampSource::default());
    assert!(chip.unmodelled().is_empty());
    write(&mut chip, 0x12, &[0x55]); // reserved in bank 0
    assert_eq!(
        read1(&mut chip, 0x12),
        0,
        "a reserved address stores nothing"
    );
    assert_eq!(chip.peek(0x12), 0);
    write(&mut chip, 0x76, &[4]);
    write(&mut chip, 0x4A, &[0x10]); // bank 4 ACCEL_WOM_X_THR
    write(&mut chip, 0x76, &[0]);
    assert_eq!(chip.peek(0x4A), 0, "not aliased onto bank 0");
    let log: Vec<_> = chip
        .unmodelled()
        .accesses()
        .map(|a| (a.page, a.address, a.written))
        .collect();
    assert_eq!(
        log,
        [
            (0, 0x12, Some(0x55)),
            (0, 0x12, None),
            (4, 0x4A, Some(0x10))
        ]
    );
    assert_eq!(chip.unmodelled().count(), 3);
}

#[test]
fn lsm6dsox_reports_the_sensor_hub_page_and_embedded_functions_it_does_not_run() {
    let mut chip = Lsm6dsoxModel::new(RampSource::default());
    write(&mut chip, 0x01, &[0x40]); // sensor-hub page
    write(&mut chip, 0x14, &[0x04]); // MASTER_CONFIG there
    write(&mut chip, 0x01, &[0x80]); // embedded functions
    write(&mut chip, 0x04, &[0x08]); // EMB_FUNC_EN_A PEDO_EN
    write(&mut chip, 0x01, &[0x00]);
    assert_eq!(chip.peek(0x14), 0x00, "CTRL5_C untouched");
    assert_eq!(chip.peek(0x04), 0x00, "S4S_TPH_L untouched");
    assert_eq!(chip.peek_embedded(0x04), 0x08, "the enable is kept");
    let log: Vec<_> = chip
        .unmodelled()
        .accesses()
        .map(|a| (a.page, a.address))
        .collect();
    assert_eq!(log, [(2, 0x14), (1, 0x04)]);
}

#[test]
fn triads_own_drivers_touch_nothing_unmodelled() {
    let mut icm = Icm42688::new_spi(Icm42688Model::new(RampSource::default()));
    let config = IcmConfig {
        fifo: Some(IcmFifo {
            watermark: 8,
            mode: IcmFifoMode::Stream,
            high_resolution: false,
        }),
        ..IcmConfig::default()
    };
    icm.init(&mut NoopDelay::new(), &config).unwrap();
    icm.bus_mut().advance(10_000_000);
    icm.read_sample().unwrap();
    let mut out = [RawSample::default(); 16];
    icm.read_fifo(&mut out).unwrap();
    let log = icm.bus().unmodelled();
    assert!(log.is_empty(), "{:?}", log.accesses().collect::<Vec<_>>());

    let mut lsm = Lsm6dsox::new_spi(Lsm6dsoxModel::new(RampSource::default()));
    let config = LsmConfig {
        fifo: Some(LsmFifo {
            watermark: 8,
            mode: LsmFifoMode::Stream,
            high_resolution: false,
        }),
        ..LsmConfig::default()
    };
    lsm.init(&mut NoopDelay::new(), &config).unwrap();
    lsm.bus_mut().advance(10_000_000);
    lsm.read_sample().unwrap();
    lsm.read_fifo(&mut out).unwrap();
    let log = lsm.bus().unmodelled();
    assert!(log.is_empty(), "{:?}", log.accesses().collect::<Vec<_>>());
}
