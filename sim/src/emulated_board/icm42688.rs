//! The emulated board's ICM-42688-P: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! Plain code over `triad` only, so the end-to-end test on the host includes
//! this very file and builds the same chip the firmware read.

use crate::icm42688_model::Icm42688Model;
use triad::sensor::icm42688::{config::Config, registers, Odr};

/// The chip's driver, generic over the register interface (SPI or I²C).
pub use triad::sensor::icm42688::Icm42688 as Driver;

/// The chip model behind the bus.
pub type Model = Icm42688Model<super::source::Source>;

/// The output data rate: one data-ready per millisecond.
pub const ODR: Odr = Odr::Hz1000;
/// The data-ready (sample) rate in Hz; `ODR` in whole hertz.
pub const SAMPLE_RATE_HZ: u32 = 1_000;
/// The model's I²C address: AP_AD0 low (DS-000347 §9.3).
pub const I2C_ADDRESS: u8 = registers::I2C_ADDRESS_AD0_LOW;

/// ±16 g, ±2000 °/s, 1 kHz, data-ready on INT1.
pub fn sensor_config() -> Config {
    Config {
        odr: ODR,
        ..Config::default()
    }
}

/// A powered-up chip model serving `source` (built at the sample rate).
pub fn model(source: super::source::Source) -> Model {
    Icm42688Model::new(source)
}

/// The chip's time from one data-ready to the next, ns (a whole number at 1 kHz).
pub fn next_sample_ns(_model: &Model) -> u64 {
    u64::from(ODR.period_ns())
}
