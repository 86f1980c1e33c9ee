//! What can go wrong talking to a chip: every variant carries the value that
//! was wrong, so a log line says what the chip answered.

/// A driver error, generic over the bus error `E`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// The bus transaction failed (SPI error, I²C NACK, ...).
    Bus(E),
    /// WHO_AM_I did not hold the chip's identity: wrong chip, wrong address or a dead bus.
    WrongChip {
        /// The identity the chip must report.
        expected: u8,
        /// The value read.
        found: u8,
    },
    /// After a soft reset the chip did not report that the reset completed.
    ResetNotDone {
        /// The status register read after the datasheet's wait.
        status: u8,
    },
    /// The chip had no new sample when one was due (stopped or stuck output).
    NoNewData {
        /// The status register read.
        status: u8,
    },
    /// A FIFO packet did not have the layout the driver configured.
    BadFifoPacket {
        /// The packet's header (or tag) byte.
        header: u8,
    },
    /// A configuration value outside what the chip supports.
    InvalidConfig {
        /// The parameter.
        what: &'static str,
        /// The value requested.
        value: u32,
    },
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Bus(e)
    }
}
