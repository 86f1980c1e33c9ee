//! The emulated board's chip: the model of whichever listed chip the build
//! names (`TRIAD_EMULATED_CHIP`), built from the core's one list of chips
//! (`triad::for_each_chip!`), so adding a chip model here is its module
//! under `emulated_board/` (an [`Emulated`] implementation for the chip)
//! and nothing else. It answers SPI and I²C like the chip it models.

use embedded_hal::{i2c, spi};

use super::source::Source;
use super::Emulated;
use crate::chips::model_clock::Clocked;
use triad::sensor::{Chip, DataRate};

macro_rules! define_emulated_chip {
    ($($variant:ident: $chip:ty),+ $(,)?) => {
        /// A powered-up chip model of one of the listed chips.
        #[allow(clippy::large_enum_variant)] // one of them, built once at start-up
        pub enum EmulatedChip {
            $(
                #[doc = concat!("The model of `", stringify!($chip), "`.")]
                $variant(<$chip as Emulated>::Model),
            )+
        }

        impl EmulatedChip {
            /// The output data rate, Hz, of the chip named `name` asked
            /// for `rate_hz` whole hertz (the driver's default for `None`):
            /// the rate its driver configures. `None` for a name not listed
            /// or a rate the chip does not have.
            pub fn rate_hz(name: &str, rate_hz: Option<u32>) -> Option<f64> {
                $(
                    if name == <$chip>::NAME {
                        return match rate_hz {
                            Some(hz) => Some(<$chip as Chip>::Odr::of_hz(hz)?.hz()),
                            None => Some(<$chip>::DEFAULT_CONFIG.sample_rate_hz()),
                        };
                    }
                )+
                None
            }

            /// The model of the chip named `name` (one of
            /// `triad::sensor::CHIP_NAMES`) serving `source`, which is built at
            /// that chip's rate; `None` for a name not listed.
            pub fn named(name: &str, source: impl FnOnce(f64) -> Source) -> Option<Self> {
                Self::named_at(name, None, source)
            }

            /// As [`Self::named`], the source built at `rate_hz` (the rate
            /// the firmware will configure; the driver's default for
            /// `None`). `None` also for a rate the chip does not have.
            pub fn named_at(
                name: &str,
                rate_hz: Option<u32>,
                source: impl FnOnce(f64) -> Source,
            ) -> Option<Self> {
                let rate_hz = Self::rate_hz(name, rate_hz)?;
                $(
                    if name == <$chip>::NAME {
                        return Some(Self::$variant(<$chip>::model(source(rate_hz))));
                    }
                )+
                None
            }

            /// The listed chip's name.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(_) => <$chip>::NAME,)+
                }
            }

            /// The model's time to its next data-ready (one new sample), ns;
            /// `None` while its sensors are off.
            pub fn next_sample_ns(&self) -> Option<u64> {
                match self {
                    $(Self::$variant(model) => model.ns_to_next_sample(),)+
                }
            }

            /// Runs the model's clock to its next data-ready (one new
            /// sample); nothing while its sensors are off.
            pub fn advance_one_sample(&mut self) {
                if let Some(ns) = self.next_sample_ns() {
                    match self {
                        $(Self::$variant(model) => model.advance(ns),)+
                    }
                }
            }

            /// Injects a fault into the model (see [`Fault`](crate::chips::fault::Fault)).
            pub fn inject(&mut self, fault: crate::chips::fault::Fault) {
                match self {
                    $(Self::$variant(model) => model.inject(fault),)+
                }
            }

            /// Clears the model's persistent faults and pending bus errors.
            pub fn clear_faults(&mut self) {
                match self {
                    $(Self::$variant(model) => model.clear_faults(),)+
                }
            }

            /// Puts the chip back at its power-on registers (sensors off,
            /// FIFO empty), as after its supply came back: the chip's
            /// [`Emulated::power_on_reset`], its own reset through its registers.
            pub fn power_on_reset(&mut self) {
                match self {
                    $(Self::$variant(model) => <$chip as Emulated>::power_on_reset(model),)+
                }
            }

            /// `byte` as read at `address` when the FIFO's count is
            /// impossible ([`Emulated::impossible_fifo_count`]): the count
            /// registers give a count beyond the FIFO's size, any other
            /// register its own byte.
            pub fn impossible_fifo_count(&self, address: u8, byte: u8) -> u8 {
                match self {
                    $(Self::$variant(_) => <$chip as Emulated>::impossible_fifo_count(address, byte),)+
                }
            }

            /// The samples the model has produced so far.
            pub fn samples_produced(&self) -> u64 {
                match self {
                    $(Self::$variant(model) => model.samples_produced(),)+
                }
            }
        }

        /// Time passes for the model as for the chip: a delay that
        /// advances it (`model_clock::ModelDelay`) lets a procedure that
        /// waits on the chip, such as the self-test, run on the emulated board.
        impl Clocked for EmulatedChip {
            fn advance(&mut self, ns: u64) {
                match self {
                    $(Self::$variant(model) => model.advance(ns),)+
                }
            }
        }

        impl spi::ErrorType for EmulatedChip {
            type Error = spi::ErrorKind;
        }

        impl spi::SpiDevice for EmulatedChip {
            fn transaction(
                &mut self,
                operations: &mut [spi::Operation<'_, u8>],
            ) -> Result<(), spi::ErrorKind> {
                match self {
                    $(Self::$variant(model) => model.transaction(operations),)+
                }
            }
        }

        impl i2c::ErrorType for EmulatedChip {
            type Error = i2c::ErrorKind;
        }

        impl i2c::I2c for EmulatedChip {
            fn transaction(
                &mut self,
                address: u8,
                operations: &mut [i2c::Operation<'_>],
            ) -> Result<(), i2c::ErrorKind> {
                match self {
                    $(Self::$variant(model) => model.transaction(address, operations),)+
                }
            }
        }
    };
}

triad::for_each_chip!(define_emulated_chip);
