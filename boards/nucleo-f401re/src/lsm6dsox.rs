//! The LSM6DSOX on the NUCLEO-F401RE: what the board's bus set-up needs to
//! know about the chip (wiring in this folder's README.md).
//!
//! SPI1 mode 3 at 84 MHz / 16 = 5.25 MHz (DS12814 §4.4.1 allows 10 MHz, so
//! the ICM-42688-P's 84 MHz / 8 = 10.5 MHz would be out of specification).
//! I²C1 400 kHz fast mode, the chip's maximum, at 0x6A: SDO/SA0 (pin 1) tied
//! low; tie it high and use `I2C_ADDRESS_SA0_HIGH` for 0x6B. CS (pin 12)
//! selects the bus: PB6 drives it low around each SPI transaction and holds
//! it high for I²C. INT1 (pin 4) → PB0 (A3), EXTI0.

pub use triad::sensor::lsm6dsox::{Config, Lsm6dsox as Driver};

/// The SPI clock's divider of PCLK2 (84 MHz / 16 = 5.25 MHz).
#[cfg(not(feature = "bus-i2c"))]
pub const SPI_DIVIDER: u32 = 16;
/// The fastest SPI clock the chip takes (DS12814 §4.4.1).
#[cfg(not(feature = "bus-i2c"))]
pub const SPI_MAX_HZ: u32 = 10_000_000;

/// The chip's I²C address with SDO/SA0 low (DS12814 §6.3).
#[cfg(feature = "bus-i2c")]
pub const I2C_ADDRESS: u8 = triad::sensor::lsm6dsox::I2C_ADDRESS_SA0_LOW;

/// The driver's defaults: ±16 g, ±2000 °/s, 833 Hz, gyroscope data ready on
/// INT1 (push-pull, active high, pulsed).
pub fn sensor_config() -> Config {
    Config::default()
}
