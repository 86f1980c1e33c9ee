//! The ICM-42688-P on the NUCLEO-F401RE (wiring in this folder's README.md).
//!
//! SPI1: mode 3 at 84 MHz / 8 = 10.5 MHz (DS-000347 §4.5 allows 24 MHz).
//! I²C1: 400 kHz fast mode (the chip allows 1 MHz) at 0x68, AP_AD0 (pin 1,
//! SDO/AD0) tied low; tie it high for 0x69 and change [`I2C_ADDRESS`]. The
//! chip's AP_CS (pin 12) selects the bus: PB6 drives it low around each SPI
//! transaction and holds it high for I²C (the chip's pin table: AP_CS high
//! leaves the serial port in I²C mode). INT1 (pin 4): push-pull, active high, pulsed data ready
//! → PB0 (A3), EXTI0.

use triad::sensor::icm42688::{config::Config, registers, Odr};

/// The chip's driver, generic over the register interface (SPI or I²C).
pub use triad::sensor::icm42688::Icm42688 as Driver;

/// The output data rate; INT1 pulses once per sample.
pub const ODR: Odr = Odr::Hz1000;
/// The data-ready (sample) rate in Hz: `ODR` in whole hertz.
pub const SAMPLE_RATE_HZ: u32 = 1_000;
/// The chip's I²C address with AP_AD0 low (DS-000347 §9.3).
#[allow(dead_code)] // read by the bus-i2c builds only
pub const I2C_ADDRESS: u8 = registers::I2C_ADDRESS_AD0_LOW;
/// SPI1 CR1 BR: f_PCLK2 / 2^(BR+1) = 84 MHz / 8 = 10.5 MHz (RM0368 §20.5.1).
#[allow(dead_code)] // read by the SPI builds only
pub const SPI_BR: u8 = 0b010;

/// ±16 g, ±2000 °/s, 1 kHz, data-ready on INT1 (push-pull, active high, pulsed).
pub fn sensor_config() -> Config {
    Config {
        odr: ODR,
        ..Config::default()
    }
}
