//! Faults a chip model can be told to show, to test that drivers and
//! firmware notice each one and recover where recovery is possible.

use triad::model::Triad;
use triad::sensor::Axis;

/// A fault injected into a chip model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// The next `transactions` bus transactions fail (SPI error, I²C NACK).
    BusError {
        /// How many transactions fail before the bus works again.
        transactions: u32,
    },
    /// WHO_AM_I reads this value instead of the chip's identity (until cleared).
    WrongWhoAmI(u8),
    /// The output stops: data registers freeze, data ready and the FIFO stop
    /// (until cleared), while the chip still answers on the bus.
    StuckOutput,
    /// The reader stalled: the FIFO receives enough samples at once to fill it
    /// and lose `lost` more.
    FifoOverflow {
        /// Samples lost beyond a full FIFO.
        lost: u16,
    },
    /// One axis's self-test excitation moves nothing (a broken actuator or a
    /// stuck proof mass): self-test on, that axis's output does not change
    /// (until cleared). Normal measurement is unaffected.
    DeadSelfTest {
        /// The accelerometer or the gyroscope.
        triad: Triad,
        /// The axis.
        axis: Axis,
    },
}
