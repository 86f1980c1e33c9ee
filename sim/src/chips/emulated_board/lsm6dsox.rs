//! The emulated board's LSM6DSOX: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use triad::sensor::lsm6dsox::Lsm6dsoxChip;

use super::source::Source;
use super::Emulated;
use crate::chips::lsm6dsox_model::Lsm6dsoxModel;
use crate::chips::lsm6dsox_registers as reg;

impl Emulated for Lsm6dsoxChip {
    /// The chip model behind the bus, at I²C address 0x6A (SA0/SDO low).
    type Model = Lsm6dsoxModel<Source>;

    /// A powered-up chip model serving `source` (built at the sample rate of the
    /// driver's default configuration: 833 Hz in high-performance mode). The
    /// board's sample timer runs at the whole microsecond nearest the chip's
    /// 1200.48 µs period; the chip model's own clock keeps the exact period
    /// (`Lsm6dsoxModel::ns_to_next_sample`), so every data-ready brings exactly one new sample.
    fn model(source: Source) -> Self::Model {
        Lsm6dsoxModel::new(source)
    }

    /// The main page selected, then CTRL3_C's SW_RESET, which sets every
    /// register to its §8 reset value.
    const POWER_ON_RESET: [(u8, u8); 2] = [
        (reg::FUNC_CFG_ACCESS, 0),
        (reg::CTRL3_C, reg::CTRL3_C_RESET | reg::SW_RESET),
    ];

    /// FIFO_STATUS1 and FIFO_STATUS2's DIFF_FIFO bits reading 1023 words, where
    /// the FIFO holds 512; FIFO_STATUS2's flags as they are.
    fn impossible_fifo_count(address: u8, byte: u8) -> u8 {
        match address {
            reg::FIFO_STATUS1 => 0xFF,
            reg::FIFO_STATUS2 => byte | reg::DIFF_FIFO_HIGH_MASK,
            _ => byte,
        }
    }
}
