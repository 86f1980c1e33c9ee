//! The LSM6DSOX model on the paths published drivers take (issue 23, items
//! 2, 5 and 6), driven register by register as any driver would, each
//! checked against DS12814: independent accelerometer and gyroscope rates
//! (registers and FIFO), the embedded-functions page as a page, and I²C
//! switched off by CTRL4_C.

mod common;

use common::bus::{i2c_read1, i2c_write1, read, read1, write};
use common::RampSource;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;

const FUNC_CFG_ACCESS: u8 = 0x01;
const FIFO_CTRL3: u8 = 0x09;
const FIFO_CTRL4: u8 = 0x0A;
const INT1_CTRL: u8 = 0x0D;
const CTRL1_XL: u8 = 0x10;
const CTRL2_G: u8 = 0x11;
const CTRL4_C: u8 = 0x13;
const STATUS_REG: u8 = 0x1E;
const FIFO_STATUS1: u8 = 0x3A;
const FIFO_DATA_OUT_TAG: u8 = 0x78;
/// ODR codes (§9 CTRL1_XL/CTRL2_G bits 7:4): 208 Hz, 416 Hz.
const ODR_208HZ: u8 = 0x5;
const ODR_416HZ: u8 = 0x6;
const MS: u64 = 1_000_000;

fn chip() -> Lsm6dsoxModel<RampSource> {
    Lsm6dsoxModel::new(RampSource::default())
}

#[test]
fn accel_and_gyro_keep_their_own_rates_in_the_status_register() {
    // §9 CTRL1_XL ODR_XL and CTRL2_G ODR_G are independent.
    let mut chip = chip();
    write(&mut chip, CTRL1_XL, &[ODR_208HZ << 4]);
    write(&mut chip, CTRL2_G, &[ODR_416HZ << 4]);
    let (mut accel_ready, mut gyro_ready) = (0, 0);
    // 100 ms in steps shorter than either period: every sample is seen.
    for _ in 0..200 {
        chip.advance(MS / 2);
        let status = read1(&mut chip, STATUS_REG);
        accel_ready += usize::from(status & 0b01 != 0);
        gyro_ready += usize::from(status & 0b10 != 0);
        // Reading the outputs clears XLDA and GDA.
        read::<_, 12>(&mut chip, 0x22);
    }
    // ⌊0.1 s × 208 Hz⌋ and ⌊0.1 s × 416 Hz⌋.
    assert_eq!((accel_ready, gyro_ready), (20, 41));
}

#[test]
fn the_fifo_batches_each_sensor_at_its_own_rate() {
    // §9 FIFO_CTRL3 BDR_XL / BDR_GY at each sensor's ODR; tagged words.
    let mut chip = chip();
    write(&mut chip, FIFO_CTRL3, &[(ODR_416HZ << 4) | ODR_208HZ]);
    write(&mut chip, FIFO_CTRL4, &[0b110]); // continuous
    write(&mut chip, CTRL1_XL, &[ODR_208HZ << 4]);
    write(&mut chip, CTRL2_G, &[ODR_416HZ << 4]);
    chip.advance(100 * MS);
    let words = usize::from(read1(&mut chip, FIFO_STATUS1));
    assert_eq!(words, 20 + 41);
    let (mut accel, mut gyro) = (0, 0);
    for _ in 0..words {
        let word = read::<_, 7>(&mut chip, FIFO_DATA_OUT_TAG);
        match word[0] >> 3 {
            0x01 => gyro += 1,
            0x02 => accel += 1,
            tag => panic!("unexpected tag {tag:#04x}"),
        }
    }
    assert_eq!((accel, gyro), (20, 41));
}

#[test]
fn the_embedded_functions_page_is_a_page() {
    // §9 FUNC_CFG_ACCESS bit 7 selects the embedded-functions registers
    // (§10), which share addresses with the main page.
    let mut chip = chip();
    write(&mut chip, INT1_CTRL, &[0x08]); // INT1_FIFO_TH
    write(&mut chip, FUNC_CFG_ACCESS, &[0x80]);
    // §10 reset values: PAGE_SEL 01h, EMB_FUNC_ODR_CFG_B 4Bh, EMB_FUNC_ODR_CFG_C 15h.
    assert_eq!(read1(&mut chip, 0x02), 0x01);
    assert_eq!(read::<_, 2>(&mut chip, 0x5F), [0x4B, 0x15]);
    write(&mut chip, INT1_CTRL, &[0x01]); // MLC_INT1 in this page
    assert_eq!(read1(&mut chip, INT1_CTRL), 0x01);
    write(&mut chip, FUNC_CFG_ACCESS, &[0x00]);
    assert_eq!(read1(&mut chip, INT1_CTRL), 0x08, "INT1_CTRL overwritten");
    assert_eq!(
        read1(&mut chip, 0x0F),
        0x6C,
        "WHO_AM_I on the main page again"
    );
    write(&mut chip, FUNC_CFG_ACCESS, &[0x80]);
    assert_eq!(read1(&mut chip, INT1_CTRL), 0x01, "MLC_INT1 kept");
}

#[test]
fn i2c_stops_answering_once_ctrl4_c_disables_it() {
    // §9 CTRL4_C bit 2 I2C_disable.
    let mut chip = chip();
    assert_eq!(i2c_read1(&mut chip, 0x6A, 0x0F), Ok(0x6C));
    i2c_write1(&mut chip, 0x6A, CTRL4_C, 0x04).unwrap();
    assert!(
        i2c_read1(&mut chip, 0x6A, 0x0F).is_err(),
        "I²C still answers"
    );
    assert_eq!(read1(&mut chip, 0x0F), 0x6C, "SPI still does");
}
