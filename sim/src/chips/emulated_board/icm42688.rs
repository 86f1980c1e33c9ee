//! The emulated board's ICM-42688-P: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use triad::sensor::icm42688::Icm42688Chip;

use super::source::Source;
use super::Emulated;
use crate::chips::icm42688_model::Icm42688Model;

impl Emulated for Icm42688Chip {
    /// The chip model behind the bus, at I²C address 0x68 (AP_AD0 low).
    type Model = Icm42688Model<Source>;

    /// A powered-up chip model serving `source` (built at the sample rate of
    /// the driver's default configuration: 1 kHz, one data-ready per ms).
    fn model(source: Source) -> Self::Model {
        Icm42688Model::new(source)
    }
}
