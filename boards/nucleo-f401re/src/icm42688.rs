//! The ICM-42688-P on the NUCLEO-F401RE: what the board's bus set-up needs
//! to know about the chip (wiring in this folder's README.md).
//!
//! SPI1 mode 3 at 84 MHz / 8 = 10.5 MHz (DS-000347 §4.5 allows 24 MHz).
//! I²C1 400 kHz fast mode (the chip allows 1 MHz) at 0x68: AP_AD0 (pin 1)
//! tied low; tie it high and use `I2C_ADDRESS_AD0_HIGH` for 0x69. AP_CS
//! (pin 12) selects the bus: PB6 drives it low around each SPI transaction
//! and holds it high for I²C. INT1 (pin 4) → PB0 (A3), EXTI0.

pub use triad::sensor::icm42688::{Config, Icm42688 as Driver};

/// The SPI clock's divider of PCLK2 (84 MHz / 8 = 10.5 MHz).
#[cfg(not(feature = "bus-i2c"))]
pub const SPI_DIVIDER: u32 = 8;
/// The fastest SPI clock the chip takes (DS-000347 §4.5).
#[cfg(not(feature = "bus-i2c"))]
pub const SPI_MAX_HZ: u32 = 24_000_000;

/// The chip's I²C address with AP_AD0 low (DS-000347 §9.3).
#[cfg(feature = "bus-i2c")]
pub const I2C_ADDRESS: u8 = triad::sensor::icm42688::I2C_ADDRESS_AD0_LOW;

/// The driver's defaults: ±16 g, ±2000 °/s, 1 kHz, data ready on INT1
/// (push-pull, active high, pulsed).
pub fn sensor_config() -> Config {
    Config::default()
}
