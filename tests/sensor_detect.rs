//! Finding the chip on the bus (`AnyChip`): every listed chip's register
//! model is found on SPI and at both of its I²C addresses; the probe writes
//! nothing to a chip that is not the one probed; an unknown chip or a dead
//! bus is an error that says what was read.

mod common;

use common::{r, spi_interface, w, Op};
use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::i2c::{Mock as I2cMock, Transaction as I2cTrans};
use triad::sensor::icm42688::Icm42688Chip;
use triad::sensor::interface::SpiInterface;
use triad::sensor::lsm6dsox::Lsm6dsoxChip;
use triad::sensor::{AnyChip, Chip, DetectError, Imu, CHIP_NAMES};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::motion::demo_motion::{DemoMotion, DemoSource};

struct NoDelay;
impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _: u32) {}
}

/// ICM-42688-P WHO_AM_I and REG_BANK_SEL; LSM6DSOX WHO_AM_I (the data sheets').
const ICM_WHO_AM_I: u8 = 0x75;
const ICM_BANK_SEL: u8 = 0x76;
const LSM_WHO_AM_I: u8 = 0x0F;

fn demo() -> DemoSource {
    DemoSource::new(DemoMotion::standard(1000.0))
}

#[test]
fn every_listed_chip_model_is_found_on_spi_and_started() {
    assert_eq!(CHIP_NAMES, [Icm42688Chip::NAME, Lsm6dsoxChip::NAME]);
    let icm = AnyChip::detect(SpiInterface::new(Icm42688Model::new(demo())));
    let lsm = AnyChip::detect(SpiInterface::new(Lsm6dsoxModel::new(demo())));
    let mut icm = icm.expect("ICM-42688-P found");
    let mut lsm = lsm.expect("LSM6DSOX found");
    assert_eq!((icm.name(), lsm.name()), ("icm42688", "lsm6dsox"));
    icm.start(&mut NoDelay).expect("starts");
    lsm.start(&mut NoDelay).expect("starts");
    // Each started with its driver's default configuration.
    assert_eq!(icm.sample_rate_hz(), 1000.0);
    assert_eq!(lsm.sample_rate_hz(), 833.0);
    assert_eq!(icm.scale(), Icm42688Chip::DEFAULT_CONFIG.scale());
    assert_eq!(lsm.scale(), Lsm6dsoxChip::DEFAULT_CONFIG.scale());
}

#[test]
fn every_listed_chip_is_found_at_either_i2c_address() {
    for high in [false, true] {
        let icm = Icm42688Model::new(demo()).with_ad0(high);
        assert_eq!(AnyChip::detect_i2c(icm).expect("ICM").name(), "icm42688");
        let lsm = Lsm6dsoxModel::new(demo()).with_sa0(high);
        assert_eq!(AnyChip::detect_i2c(lsm).expect("LSM").name(), "lsm6dsox");
    }
}

#[test]
fn probing_an_lsm6dsox_on_spi_only_reads() {
    // The ICM-42688-P's probe reads WHO_AM_I and, finding another value,
    // REG_BANK_SEL; neither is written unless that names a user bank 1-4.
    let ops = [
        r(ICM_WHO_AM_I, &[0x00]),
        r(ICM_BANK_SEL, &[0x00]),
        r(LSM_WHO_AM_I, &[0x6C]),
    ];
    let found = AnyChip::detect(spi_interface(&ops)).expect("found");
    assert_eq!(found.name(), "lsm6dsox");
    match found {
        AnyChip::Lsm6dsox(driver) => common::destroy(driver.into_interface()),
        other => panic!("{}", other.name()),
    }
}

#[test]
fn an_icm42688_left_in_another_bank_is_brought_back_to_bank_0() {
    // After a warm restart of the microcontroller the chip may still be in
    // the bank a previous run selected; its WHO_AM_I address then reads another register.
    let ops = [
        r(ICM_WHO_AM_I, &[0x13]),
        r(ICM_BANK_SEL, &[0x02]),
        w(ICM_BANK_SEL, 0x00),
        r(ICM_WHO_AM_I, &[0x47]),
    ];
    let found = AnyChip::detect(spi_interface(&ops)).expect("found");
    assert_eq!(found.name(), "icm42688");
    match found {
        AnyChip::Icm42688(driver) => common::destroy(driver.into_interface()),
        other => panic!("{}", other.name()),
    }
}

#[test]
fn an_unknown_chip_is_reported_with_what_each_probe_read_and_the_bus_given_back() {
    let ops: [Op; 3] = [
        r(ICM_WHO_AM_I, &[0xFF]),
        r(ICM_BANK_SEL, &[0xFF]),
        r(LSM_WHO_AM_I, &[0x6B]),
    ];
    let Err(undetected) = AnyChip::detect(spi_interface(&ops)) else {
        panic!("an unknown chip is not detected");
    };
    assert_eq!(
        undetected.reason,
        DetectError::NotFound {
            identities: [Some(0xFF), Some(0x6B)]
        }
    );
    common::destroy(undetected.bus);
}

#[test]
fn no_chip_on_i2c_reports_no_answer() {
    // Every address NACKs: nothing is there.
    let addresses: Vec<u8> = Icm42688Chip::I2C_ADDRESSES
        .iter()
        .chain(Lsm6dsoxChip::I2C_ADDRESSES)
        .copied()
        .collect();
    let expectations: Vec<I2cTrans> = addresses
        .iter()
        .zip([ICM_WHO_AM_I, ICM_WHO_AM_I, LSM_WHO_AM_I, LSM_WHO_AM_I])
        .map(|(&address, register)| {
            I2cTrans::write_read(address, vec![register], vec![0]).with_error(
                ErrorKind::NoAcknowledge(embedded_hal::i2c::NoAcknowledgeSource::Address),
            )
        })
        .collect();
    let Err(mut undetected) = AnyChip::detect_i2c(I2cMock::new(&expectations)) else {
        panic!("nothing answers");
    };
    assert_eq!(
        undetected.reason,
        DetectError::NotFound {
            identities: [None, None]
        }
    );
    undetected.bus.done();
}
