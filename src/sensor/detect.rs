//! Finding the chip on the bus: every chip triad drives is tried by its
//! identity register, so one firmware build serves whichever of them a board
//! carries, and a board or a test never names a chip.
//!
//! [`for_each_chip!`](crate::for_each_chip) is the one list of chips: each
//! entry names a type implementing [`Chip`] (the contract), and [`AnyChip`]
//! holds the [`Driver`] of whichever one answered. Adding a chip is its
//! module (a [`Chip`] implementation), its chip model in the simulator, and
//! one entry in the list.

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;

use super::chip::Chip;
use super::config::Config;
use super::driver::Driver;
use super::error::Error;
use super::fifo::{FifoImu, FifoRead};
use super::interface::{I2cInterface, RegisterInterface};
use super::self_test::{ChipSelfTest, SelfTestError, SelfTestReport};
use super::settings::Settings;
use super::{Imu, ImuScale, RawSample};

/// Calls `$callback! { Variant: ChipType, ... }` with every chip triad
/// drives (each type implements [`Chip`]), in the order detection tries
/// them: the one list of chips. Crates that keep something per chip (the
/// simulator's chip models) build it from this.
#[macro_export]
macro_rules! for_each_chip {
    ($callback:ident) => {
        $callback! {
            Icm42688: $crate::sensor::icm42688::Icm42688Chip,
            Lsm6dsox: $crate::sensor::lsm6dsox::Lsm6dsoxChip,
        }
    };
}

/// Why no chip was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DetectError<E> {
    /// The bus failed (on SPI; an I²C address that does not answer is only
    /// "not there").
    Bus(E),
    /// No listed chip answered with its identity: what each chip's identity
    /// register read, in [`CHIP_NAMES`] order (`None`: no answer on I²C).
    NotFound {
        /// The value read at each chip's identity register.
        identities: [Option<u8>; CHIP_NAMES.len()],
    },
}

/// Detection failed: why, and the bus (an SPI interface or an I²C bus)
/// given back, so the caller may log, retry or use it otherwise.
pub struct Undetected<B, E> {
    /// Why no chip was found.
    pub reason: DetectError<E>,
    /// The bus, untouched since the probes.
    pub bus: B,
}

/// The reason only: a bus need not be `Debug`.
impl<B, E: core::fmt::Debug> core::fmt::Debug for Undetected<B, E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Undetected")
            .field("reason", &self.reason)
            .finish_non_exhaustive()
    }
}

/// The smallest of `values` (for the SPI clock every chip takes).
const fn min_of(values: &[u32]) -> u32 {
    let mut min = u32::MAX;
    let mut i = 0;
    while i < values.len() {
        if values[i] < min {
            min = values[i];
        }
        i += 1;
    }
    min
}

macro_rules! define_any_chip {
    ($($variant:ident: $chip:ty),+ $(,)?) => {
        /// Every chip's name, in the order detection tries them.
        pub const CHIP_NAMES: [&str; [$(<$chip as Chip>::NAME),+].len()] = [$(<$chip as Chip>::NAME),+];

        /// The fastest SPI clock every listed chip takes, Hz: what a board
        /// sets before it knows which chip it carries.
        pub const SPI_MAX_HZ: u32 = min_of(&[$(<$chip as Chip>::SPI_MAX_HZ),+]);

        /// The chip found on the bus, driven by its own driver.
        #[derive(Debug)]
        pub enum AnyChip<I> {
            $(
                #[doc = concat!("The `", stringify!($chip), "` driver.")]
                $variant(Driver<$chip, I>),
            )+
        }

        impl<I: RegisterInterface> AnyChip<I> {
            /// The chip on `interface` (SPI), found by reading each listed
            /// chip's identity register in turn; nothing is written to a chip
            /// until [`Self::start`].
            pub fn detect(mut interface: I) -> Result<Self, Undetected<I, I::BusError>> {
                let mut identities = [None; CHIP_NAMES.len()];
                let mut slot = identities.iter_mut();
                $(
                    let found = match <$chip>::identify(&mut interface) {
                        Ok(found) => found,
                        Err(error) => {
                            let reason = DetectError::Bus(error);
                            return Err(Undetected { reason, bus: interface });
                        }
                    };
                    if found == <$chip>::IDENTITY {
                        return Ok(Self::$variant(Driver::new(interface)));
                    }
                    if let Some(slot) = slot.next() {
                        *slot = Some(found);
                    }
                )+
                let reason = DetectError::NotFound { identities };
                Err(Undetected { reason, bus: interface })
            }

            /// The chip's name (e.g. `icm42688`).
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(_) => <$chip>::NAME,)+
                }
            }

            /// Checks the identity, resets the chip and applies its driver's
            /// default configuration (each module's `Config::default()`).
            pub fn start(&mut self, delay: &mut impl DelayNs) -> Result<(), Error<I::BusError>> {
                match self {
                    $(Self::$variant(chip) => chip.init(delay, &Config::default()),)+
                }
            }

            /// As [`Self::start`], with `settings`' rates and FIFO watermark in
            /// place of the default's ([`Settings::config`]); a rate the
            /// chip does not have is refused (`InvalidConfig`, with the
            /// rate) before any write.
            pub fn start_with(
                &mut self,
                delay: &mut impl DelayNs,
                settings: &Settings,
            ) -> Result<(), Error<I::BusError>> {
                match self {
                    $(Self::$variant(chip) => chip.init(delay, &settings.config::<$chip, _>()?),)+
                }
            }

            /// The fastest SPI clock this chip takes, Hz: what a board sets
            /// once it has found the chip (detection runs at [`SPI_MAX_HZ`]).
            pub fn spi_max_hz(&self) -> u32 {
                match self {
                    $(Self::$variant(_) => <$chip>::SPI_MAX_HZ,)+
                }
            }

            /// The output data rate of the configuration applied, Hz.
            pub fn sample_rate_hz(&self) -> f64 {
                match self {
                    $(Self::$variant(chip) => chip.config().sample_rate_hz(),)+
                }
            }

            /// Runs the chip's data-sheet self-test on both triads and
            /// reports each axis's response, limits and verdict; the chip is
            /// left configured as before (or the error says it is not). The
            /// chip must be still and sampling paused: it takes about 1.4 s
            /// on an ICM-42688-P, 0.64 s on an LSM6DSOX, at most
            /// [`Self::self_test_max_duration_ms`]. See each driver's `self_test`.
            pub fn self_test(
                &mut self,
                delay: &mut impl DelayNs,
            ) -> Result<SelfTestReport, SelfTestError<I::BusError>> {
                match self {
                    $(Self::$variant(chip) => chip.self_test(delay),)+
                }
            }

            /// The longest this chip's [`Self::self_test`] can take, ms (bus time excluded).
            pub fn self_test_max_duration_ms(&self) -> u32 {
                match self {
                    $(Self::$variant(_) => <$chip as ChipSelfTest>::self_test_max_duration_ms(),)+
                }
            }

            /// The bus (e.g. the chip model, whose clock the emulated board advances).
            pub fn bus_mut(&mut self) -> &mut I::Bus {
                match self {
                    $(Self::$variant(chip) => chip.bus_mut(),)+
                }
            }

            /// The bus, shared.
            pub fn bus(&self) -> &I::Bus {
                match self {
                    $(Self::$variant(chip) => chip.bus(),)+
                }
            }
        }

        impl<I2C: I2c> AnyChip<I2cInterface<I2C>> {
            /// The chip on the I²C bus `i2c`, found by reading the identity
            /// register at each listed chip's addresses in turn (no listed
            /// chips share an address); an address that does not answer is
            /// taken as no chip there.
            pub fn detect_i2c(mut i2c: I2C) -> Result<Self, Undetected<I2C, I2C::Error>> {
                let mut identities = [None; CHIP_NAMES.len()];
                let mut slot = identities.iter_mut();
                $(
                    let mut read = None;
                    for &address in <$chip>::I2C_ADDRESSES {
                        let mut interface = I2cInterface::new(i2c, address);
                        match <$chip>::identify(&mut interface) {
                            Ok(found) if found == <$chip>::IDENTITY => {
                                return Ok(Self::$variant(Driver::new(interface)));
                            }
                            Ok(found) => read = read.or(Some(found)),
                            Err(_) => {}
                        }
                        i2c = interface.release();
                    }
                    if let Some(slot) = slot.next() {
                        *slot = read;
                    }
                )+
                let reason = DetectError::NotFound { identities };
                Err(Undetected { reason, bus: i2c })
            }
        }

        impl<I: RegisterInterface> Imu for AnyChip<I> {
            type Error = Error<I::BusError>;

            fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
                match self {
                    $(Self::$variant(chip) => chip.read_sample(),)+
                }
            }

            fn scale(&self) -> ImuScale {
                match self {
                    $(Self::$variant(chip) => chip.scale(),)+
                }
            }
        }

        impl<I: RegisterInterface> FifoImu for AnyChip<I> {
            fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error> {
                match self {
                    $(Self::$variant(chip) => chip.read_fifo(out),)+
                }
            }

            fn reset_fifo(&mut self) -> Result<(), Self::Error> {
                match self {
                    $(Self::$variant(chip) => chip.reset_fifo(),)+
                }
            }
        }
    };
}

for_each_chip!(define_any_chip);
