//! What the firmware asks of whichever chip it finds: a sample rate (and,
//! optionally, a lower rate for one of the sensors) and a FIFO watermark,
//! chip-independent. Each chip turns them into its own configuration (its
//! rate codes, its FIFO registers) or refuses them with the value and the
//! reason.

use super::chip::{Chip, DataRate};
use super::config::Config;
use super::error::Error;
use super::fifo::{FifoConfig, FifoMode};
use crate::model::Triad;

/// Sampling settings for [`super::AnyChip::start_with`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Settings {
    /// The stream's rate, Hz: both sensors' output data rate, or the
    /// faster one's when `slower` names the other (a rate the chip has
    /// exactly); `None`: the driver's default.
    pub rate_hz: Option<u32>,
    /// One sensor at a lower output data rate than `rate_hz`, Hz: samples
    /// still come at `rate_hz`, holding this sensor's latest value between
    /// its own (docs/PROTOCOL.md §22). `None`: both at `rate_hz`.
    pub slower: Option<(Triad, u32)>,
    /// Samples per interrupt: 1 reads each sample on data ready (FIFO off);
    /// W > 1 turns the FIFO on and interrupts on W samples waiting.
    pub watermark: u16,
    /// The chip's high-resolution FIFO format (W > 1 only; the
    /// ICM-42688-P's 20-bit packets, [`FifoConfig::high_resolution`]).
    pub high_resolution: bool,
}

impl Settings {
    /// The driver's default rate, one sample per interrupt.
    pub const DEFAULT: Settings = Settings {
        rate_hz: None,
        slower: None,
        watermark: 1,
        high_resolution: false,
    };

    /// The FIFO configuration these settings ask for: none for W = 1; else
    /// the watermark, stopping on full so an overflow loses the newest
    /// samples and the driver counts them (the autopilots' choice).
    pub fn fifo(&self) -> Option<FifoConfig> {
        (self.watermark > 1).then_some(FifoConfig {
            watermark: self.watermark,
            mode: FifoMode::StopOnFull,
            high_resolution: self.high_resolution,
        })
    }
}

impl Settings {
    /// Chip `C`'s configuration for these settings: its default with the
    /// rates and the FIFO asked for. A rate the chip does not have, or a
    /// slower rate that is not below the stream's, is refused with the value.
    pub fn config<C: Chip, E>(&self) -> Result<Config<C>, Error<E>> {
        let rate =
            |hz: u32, what| C::Odr::of_hz(hz).ok_or(Error::InvalidConfig { what, value: hz });
        let mut config = Config::<C>::default();
        if let Some(hz) = self.rate_hz {
            let odr = rate(hz, "output data rate, Hz (not one of this chip's rates)")?;
            config = config.with_odr(odr);
        }
        if let Some((triad, hz)) = self.slower {
            let what = "slower sensor's output data rate, Hz (not one of this chip's rates)";
            let odr = rate(hz, what)?;
            if odr.hz() >= config.sample_rate_hz() {
                return Err(Error::InvalidConfig {
                    what: "slower sensor's output data rate, Hz (not below the stream's rate)",
                    value: hz,
                });
            }
            match triad {
                Triad::Accel => config.accel_odr = odr,
                Triad::Gyro => config.gyro_odr = odr,
            }
        }
        if self.high_resolution && self.watermark <= 1 {
            return Err(Error::InvalidConfig {
                what: "FIFO watermark with the high-resolution FIFO (it needs the FIFO: 2 or more)",
                value: u32::from(self.watermark),
            });
        }
        config.fifo = self.fifo();
        Ok(config)
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
