//! The emulated board's LSM6DSOX: the register-level chip model serving the
//! board's source (source.rs: the demo motion or a scene), behind either bus (the model answers SPI and I²C like the chip).
//!
//! The end-to-end test on the host builds this very chip, so it knows what the
//! firmware read.

use crate::lsm6dsox_model::Lsm6dsoxModel;
use triad::sensor::lsm6dsox::Config;

/// The chip model behind the bus, at I²C address 0x6A (SA0/SDO low).
pub type Model = Lsm6dsoxModel<super::source::Source>;

/// A powered-up chip model serving `source` (built at the sample rate of the
/// driver's default configuration: 833 Hz in high-performance mode). The
/// board's sample timer runs at the whole microsecond nearest the chip's
/// 1200.48 µs period; the chip model's own clock keeps the exact period
/// ([`next_sample_ns`]), so every data-ready brings exactly one new sample.
pub fn model(source: super::source::Source) -> Model {
    Lsm6dsoxModel::new(source)
}

/// The chip's time from data-ready n to data-ready n + 1, ns, where n is the
/// samples the model produced so far: ⌈(n+1)·P⌉ − ⌈n·P⌉ for the exact period
/// P = 10¹² / 833 000 ns, so the model's clock stays on the whole nanosecond
/// at or after each sample instant and each call brings one sample.
pub fn next_sample_ns(model: &Model) -> u64 {
    /// ns·mHz in one second.
    const NS_MHZ: u128 = 1_000_000_000_000;
    let rate = u128::from(Config::default().odr.millihertz());
    let n = u128::from(model.samples_produced());
    let at = |k: u128| (k * NS_MHZ).div_ceil(rate);
    // The difference is ⌈P⌉ or ⌊P⌋ (about 1.2 ms): it fits in u64.
    u64::try_from(at(n + 1) - at(n)).unwrap_or(u64::MAX)
}
