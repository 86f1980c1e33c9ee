//! The emulated board's LSM6DSOX: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use triad::sensor::lsm6dsox::Lsm6dsoxChip;

use super::source::Source;
use super::Emulated;
use crate::chips::lsm6dsox_model::Lsm6dsoxModel;

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
}
