//! The LSM6DSOX on the NUCLEO-F401RE (wiring in this folder's README.md).
//!
//! SPI1: mode 3 at 84 MHz / 16 = 5.25 MHz (DS12814 §4.4.1 allows 10 MHz, so
//! the ICM-42688-P's 10.5 MHz is too fast here). I²C1: 400 kHz fast mode, the
//! chip's maximum, at 0x6A, SDO/SA0 (pin 1) tied low; tie it high for 0x6B
//! and change [`I2C_ADDRESS`]. CS (pin 12) selects the bus: PB6 drives it low
//! around each SPI transaction and holds it high for I²C (DS12814 pin
//! description: CS high enables I²C). INT1 (pin 4): push-pull, active high,
//! pulsed gyroscope data ready → PB0 (A3), EXTI0.

use triad::sensor::lsm6dsox::{config::Config, registers, Odr};

/// The chip's driver, generic over the register interface (SPI or I²C).
pub use triad::sensor::lsm6dsox::Lsm6dsox as Driver;

/// The output data rate in high-performance mode; INT1 pulses once per sample.
pub const ODR: Odr = Odr::Hz833;
/// The data-ready (sample) rate in Hz: `ODR` in whole hertz (the timestamps
/// come from the data-ready edges; this only sets the expected step).
pub const SAMPLE_RATE_HZ: u32 = 833;
/// The chip's I²C address with SDO/SA0 low (DS12814 §6.3).
#[allow(dead_code)] // read by the bus-i2c builds only
pub const I2C_ADDRESS: u8 = registers::I2C_ADDRESS_SA0_LOW;
/// SPI1 CR1 BR: f_PCLK2 / 2^(BR+1) = 84 MHz / 16 = 5.25 MHz (RM0368 §20.5.1).
#[allow(dead_code)] // read by the SPI builds only
pub const SPI_BR: u8 = 0b011;

/// ±16 g, ±2000 °/s, 833 Hz, gyroscope data-ready on INT1 (push-pull, active
/// high, pulsed).
pub fn sensor_config() -> Config {
    Config {
        odr: ODR,
        ..Config::default()
    }
}
