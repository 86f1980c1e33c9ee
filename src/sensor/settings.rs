//! What the firmware asks of whichever chip it finds: a sample rate and a
//! FIFO watermark, chip-independent. Each chip turns them into its own
//! configuration (its rate code, its FIFO registers) or refuses them with
//! the value and the reason.

use super::fifo::{FifoConfig, FifoMode};

/// Sampling settings for [`super::AnyChip::start_with`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Settings {
    /// Output data rate, Hz (a rate the chip has exactly); `None`: the
    /// driver's default.
    pub rate_hz: Option<u32>,
    /// Samples per interrupt: 1 reads each sample on data ready (FIFO off);
    /// W > 1 turns the FIFO on and interrupts on W samples waiting.
    pub watermark: u16,
}

impl Settings {
    /// The driver's default rate, one sample per interrupt.
    pub const DEFAULT: Settings = Settings {
        rate_hz: None,
        watermark: 1,
    };

    /// The FIFO configuration these settings ask for: none for W = 1; else
    /// the watermark, stopping on full so an overflow loses the newest
    /// samples and the driver counts them (the autopilots' choice).
    pub fn fifo(&self) -> Option<FifoConfig> {
        (self.watermark > 1).then_some(FifoConfig {
            watermark: self.watermark,
            mode: FifoMode::StopOnFull,
        })
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
