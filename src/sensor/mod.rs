//! Sensors: the raw sample, the IMU trait the firmware and the model see,
//! the [`Chip`] trait (what differs between chips), the one generic
//! [`Driver`] over it, and one module per chip.

pub mod chip;
pub mod config;
pub mod detect;
pub mod driver;
pub mod error;
pub mod fifo;
pub mod icm42688;
pub mod interface;
pub mod interrupt;
pub mod lsm6dsox;
pub mod self_test;
pub mod settings;

pub use chip::{Chip, DataRate, FullScale};
pub use config::Config;
pub use detect::{AnyChip, DetectError, Undetected, CHIP_NAMES};
pub use driver::Driver;
pub use error::Error;
pub use fifo::{FifoConfig, FifoImu, FifoMode, FifoRead};
pub use interrupt::InterruptPin;
pub use self_test::{Axis, ChipLeft, ChipSelfTest, SelfTestError, SelfTestReport};
pub use settings::Settings;

/// One raw reading of both triads, in the chip's own counts (LSB).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawSample {
    /// Accelerometer x, y, z in LSB.
    pub accel: [i16; 3],
    /// Gyroscope x, y, z in LSB.
    pub gyro: [i16; 3],
    /// Die temperature in LSB (see [`ImuScale::temperature_c`]).
    pub temperature: i16,
}

/// How one triad's counts map to SI units, for the configured range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriadScale {
    /// SI units per LSB: m/s² per LSB (accelerometer) or rad/s per LSB (gyroscope).
    pub si_per_lsb: f64,
    /// The configured measurement range, ± this many SI units.
    pub full_scale: f64,
}

/// The sensitivities of a configured chip: what the model folds into K.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuScale {
    /// Accelerometer counts → m/s².
    pub accel: TriadScale,
    /// Gyroscope counts → rad/s.
    pub gyro: TriadScale,
    /// °C per temperature LSB.
    pub temperature_per_lsb: f64,
    /// °C at temperature reading 0.
    pub temperature_offset: f64,
}

impl ImuScale {
    /// The die temperature in °C of a raw temperature reading.
    pub fn temperature_c(&self, raw: i16) -> f64 {
        f64::from(raw) * self.temperature_per_lsb + self.temperature_offset
    }
}

/// What the firmware and the model see of a chip, whatever its bus.
pub trait Imu {
    /// The driver's error (bus failures, identity mismatches, ...).
    type Error;
    /// Reads the latest accelerometer, gyroscope and temperature sample in one burst.
    fn read_sample(&mut self) -> Result<RawSample, Self::Error>;
    /// The LSB → SI sensitivities of the configured ranges.
    fn scale(&self) -> ImuScale;
}
