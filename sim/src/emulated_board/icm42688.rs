//! The emulated board's ICM-42688-P: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use crate::icm42688_model::Icm42688Model;
use triad::sensor::icm42688::{Config, I2C_ADDRESS_AD0_LOW};

/// The chip's driver, generic over the register interface (SPI or I²C).
pub use triad::sensor::icm42688::Icm42688 as Driver;

/// The chip model behind the bus.
pub type Model = Icm42688Model<super::source::Source>;

/// The model's I²C address: AP_AD0 low (DS-000347 §9.3).
pub const I2C_ADDRESS: u8 = I2C_ADDRESS_AD0_LOW;

/// The driver's default: ±16 g, ±2000 °/s, 1 kHz (one data-ready per
/// millisecond: the board's sample rate), data-ready on INT1.
pub fn sensor_config() -> Config {
    Config::default()
}

/// A powered-up chip model serving `source` (built at the sample rate).
pub fn model(source: super::source::Source) -> Model {
    Icm42688Model::new(source)
}

/// The chip's time from one data-ready to the next, ns (a whole number at 1 kHz).
pub fn next_sample_ns(_model: &Model) -> u64 {
    u64::from(sensor_config().odr.period_ns())
}
