//! What a chip is to triad: one trait. A chip module implements [`Chip`] on
//! a marker type (its identity, names, bus limits, configuration types and
//! the register-level steps that differ: start-up, sample and FIFO reads;
//! its self-test is [`ChipSelfTest`](super::self_test::ChipSelfTest)); the
//! generic [`Driver`] does the rest, and
//! [`for_each_chip!`](crate::for_each_chip) lists the chips detection
//! tries. Adding a chip is its module, its chip model in the simulator, and
//! one entry in that list.

use core::fmt::Debug;

use embedded_hal::delay::DelayNs;

use super::accel_range::AccelRange;
use super::config::Config;
use super::driver::Driver;
use super::error::Error;
use super::fifo::FifoRead;
use super::interface::RegisterInterface;
use super::{ImuScale, RawSample, TriadScale};

/// `defmt::Format` when the crate logs with defmt, nothing otherwise: lets a
/// chip's configuration types be logged without a bound that only exists
/// with the feature.
#[cfg(feature = "defmt")]
pub trait Loggable: defmt::Format {}
#[cfg(feature = "defmt")]
impl<T: defmt::Format> Loggable for T {}
/// `defmt::Format` when the crate logs with defmt, nothing otherwise.
#[cfg(not(feature = "defmt"))]
pub trait Loggable {}
#[cfg(not(feature = "defmt"))]
impl<T> Loggable for T {}

/// A full-scale range setting of one triad that is the chip's own type (its
/// `GyroRange`: the chips' gyroscope ranges and codes differ; the
/// accelerometer's are the shared [`AccelRange`]).
pub trait FullScale: Copy + Debug + PartialEq + Eq + Loggable {
    /// Counts → SI units and the range in SI units, from the data sheet.
    fn scale(self) -> TriadScale;
}

/// An output data rate setting (a chip's `Odr`): its rate and its code in
/// the chip's output-data-rate fields.
pub trait DataRate: Copy + Debug + PartialEq + Eq + Loggable + 'static {
    /// Every rate the driver offers.
    const ALL: &'static [Self];

    /// The rate in Hz.
    fn hz(self) -> f64;

    /// The chip's output-data-rate field value for this rate.
    fn code(self) -> u8;

    /// The rate whose output-data-rate field value is `code`, if the driver
    /// offers it.
    fn from_code(code: u8) -> Option<Self> {
        Self::ALL.iter().copied().find(|r| r.code() == code)
    }

    /// The rate whose whole number of hertz is `hz` (833 for 833 Hz, 12
    /// for 12.5 Hz), if the chip has it.
    fn of_hz(hz: u32) -> Option<Self> {
        Self::ALL.iter().copied().find(|r| r.hz() as u32 == hz)
    }
}

/// A chip triad drives: what differs from one chip to another. Implemented
/// on a marker type; [`Driver<C, I>`](Driver) is the driver of chip `C`.
pub trait Chip: Copy + Debug + PartialEq + Eq + Loggable + Sized + 'static {
    /// The chip's name, as the link, the log and `--sensor` spell it.
    const NAME: &'static str;
    /// The value of the chip's identity register (WHO_AM_I).
    const IDENTITY: u8;
    /// The fastest SPI clock the chip takes, Hz.
    const SPI_MAX_HZ: u32;
    /// The chip's 7-bit I²C addresses, in the order detection tries them.
    const I2C_ADDRESSES: &'static [u8];
    /// The largest FIFO watermark, in the samples [`Config::fifo`] counts.
    const MAX_WATERMARK: u16;
    /// How an out-of-range watermark is named in [`Error::InvalidConfig`].
    const WATERMARK_WHAT: &'static str;
    /// Temperature sensitivity, LSB per °C.
    const TEMP_LSB_PER_C: f64;
    /// °C at temperature reading 0.
    const TEMP_OFFSET_C: f64;

    /// Gyroscope full-scale range.
    type GyroRange: FullScale;
    /// Output data rate.
    type Odr: DataRate;
    /// What the driver keeps between FIFO drains beyond the held sample
    /// (the LSM6DSOX: a time slot cut by a full output; `()` where nothing).
    type FifoState: Copy + Default + core::fmt::Debug;

    /// The accelerometer range field's value for `range` (the data sheet's
    /// register map).
    fn accel_code(range: AccelRange) -> u8;

    /// Counts → m/s² at `range`, from the data sheet's sensitivity table.
    fn accel_si_per_lsb(range: AccelRange) -> f64;

    /// The driver's default configuration.
    const DEFAULT_CONFIG: Config<Self>;
    /// The ranges and rate the chip holds after a reset (the FIFO off):
    /// what the driver reports before `init`.
    const RESET_CONFIG: Config<Self>;

    /// The counts → SI sensitivities and code ranges of `config`: by
    /// default its ranges' ([`Config::range_scale`]); a chip whose FIFO
    /// format changes them (the ICM-42688-P's 20-bit packets) says so here.
    fn scale(config: &Config<Self>) -> ImuScale {
        config.range_scale()
    }

    /// Reads the identity register without changing anything a listed chip
    /// holds (detection probes every listed chip this way).
    fn identify<I: RegisterInterface>(interface: &mut I) -> Result<u8, I::BusError>;

    /// Checks the identity, soft-resets and applies `config` (validated by
    /// the driver: watermark in range); leaves the chip sampling.
    fn start<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
        delay: &mut impl DelayNs,
        config: &Config<Self>,
    ) -> Result<(), Error<I::BusError>>;

    /// Reads the latest accelerometer, gyroscope and temperature sample in one burst.
    fn read_sample<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
    ) -> Result<RawSample, Error<I::BusError>>;

    /// Drains whole samples from the FIFO (see [`super::FifoImu::read_fifo`]).
    fn read_fifo<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
        out: &mut [RawSample],
    ) -> Result<FifoRead, Error<I::BusError>>;

    /// Empties the FIFO.
    fn reset_fifo<I: RegisterInterface>(
        driver: &mut Driver<Self, I>,
    ) -> Result<(), Error<I::BusError>>;
}
