//! A chip's driver configuration as typed values: the shared accelerometer
//! range, the chip's own gyroscope range and rate (its [`Chip`] types), the
//! interrupt pin and the FIFO. One struct for
//! every chip; each chip gives its default ([`Chip::DEFAULT_CONFIG`]).

use super::accel_range::AccelRange;
use super::chip::{Chip, DataRate, FullScale};
use super::fifo::FifoConfig;
use super::interrupt::InterruptPin;
use super::ImuScale;

/// A complete driver configuration of chip `C`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config<C: Chip> {
    /// Accelerometer range.
    pub accel_range: AccelRange,
    /// Gyroscope range.
    pub gyro_range: C::GyroRange,
    /// Accelerometer output data rate.
    pub accel_odr: C::Odr,
    /// Gyroscope output data rate. When the two rates differ the driver
    /// delivers samples at the faster one, the slower sensor's latest value
    /// held in the samples where it has none (docs/PROTOCOL.md §22).
    pub gyro_odr: C::Odr,
    /// INT1 electrical behaviour.
    pub interrupt: InterruptPin,
    /// `None`: FIFO off, INT1 signals data ready. `Some`: FIFO on
    /// (watermark 1..=[`Chip::MAX_WATERMARK`]), INT1 signals the watermark.
    pub fifo: Option<FifoConfig>,
}

impl<C: Chip> Config<C> {
    /// Samples per second the driver delivers: the faster sensor's output
    /// data rate. The firmware's sample period, and everything timed by it,
    /// comes from here.
    pub fn sample_rate_hz(&self) -> f64 {
        self.accel_odr.hz().max(self.gyro_odr.hz())
    }

    /// Both sensors at `odr`.
    pub fn with_odr(self, odr: C::Odr) -> Self {
        Self {
            accel_odr: odr,
            gyro_odr: odr,
            ..self
        }
    }

    /// The counts → SI sensitivities and code ranges of the samples the
    /// driver delivers in this configuration (what [`super::Imu::scale`]
    /// reports): the chip's [`Chip::scale`].
    pub fn scale(&self) -> ImuScale {
        C::scale(self)
    }

    /// The sensitivities of this configuration's ranges and the chip's
    /// temperature sensor: 16-bit codes at the configured full scales.
    pub fn range_scale(&self) -> ImuScale {
        ImuScale {
            accel: self.accel_range.scale::<C>(),
            gyro: self.gyro_range.scale(),
            temperature_per_lsb: 1.0 / C::TEMP_LSB_PER_C,
            temperature_offset: C::TEMP_OFFSET_C,
        }
    }
}

impl<C: Chip> Default for Config<C> {
    /// The chip's [`Chip::DEFAULT_CONFIG`].
    fn default() -> Self {
        C::DEFAULT_CONFIG
    }
}
