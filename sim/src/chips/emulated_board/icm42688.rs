//! The emulated board's ICM-42688-P: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use triad::sensor::icm42688::Icm42688Chip;

use super::source::Source;
use super::Emulated;
use crate::chips::icm42688_model::Icm42688Model;
use crate::chips::icm42688_registers as reg;

impl Emulated for Icm42688Chip {
    /// The chip model behind the bus, at I²C address 0x68 (AP_AD0 low).
    type Model = Icm42688Model<Source>;

    /// A powered-up chip model serving `source` (built at the sample rate of
    /// the driver's default configuration: 1 kHz, one data-ready per ms).
    fn model(source: Source) -> Self::Model {
        Icm42688Model::new(source)
    }

    /// Bank 0 selected, then DEVICE_CONFIG's SOFT_RESET_CONFIG, which sets
    /// every register to its §13 reset value.
    const POWER_ON_RESET: [(u8, u8); 2] = [
        (reg::REG_BANK_SEL, 0),
        (reg::DEVICE_CONFIG, reg::SOFT_RESET_CONFIG),
    ];

    /// FIFO_COUNTH and FIFO_COUNTL (bank 0) reading 4095: records, as the
    /// driver counts them, where the FIFO holds 128.
    fn impossible_fifo_count(address: u8, byte: u8) -> u8 {
        match address {
            reg::FIFO_COUNTH => 0x0F,
            a if a == reg::FIFO_COUNTH + 1 => 0xFF,
            _ => byte,
        }
    }
}
