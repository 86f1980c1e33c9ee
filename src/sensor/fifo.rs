//! The chip-independent view of a sensor FIFO: drain whole packets, learn
//! about overflows and how many samples they cost.

use super::{Imu, RawSample};

/// What one FIFO drain delivered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FifoRead {
    /// Samples written to the front of the output buffer, oldest first.
    pub samples: usize,
    /// Samples still waiting in the FIFO (the output buffer was full).
    pub remaining: u16,
    /// The FIFO had overflowed: it was reset, its content discarded.
    pub overflowed: bool,
    /// Samples lost since the previous drain (dropped by the full FIFO plus
    /// those discarded by the recovery reset); 0 unless `overflowed`.
    pub lost: u32,
    /// The chip does not count the samples it drops while full, so `lost` is
    /// only those discarded by the reset: a lower bound (e.g. LSM6DSOX).
    pub lost_is_lower_bound: bool,
}

impl FifoRead {
    /// The FIFO's count read beyond its size, so the driver reset it: its
    /// content is lost, at least the watermark of `fifo` (1 without one)
    /// that raised the interrupt; flagged as an overflow (the loss is the
    /// chip's FIFO's), the count a lower bound.
    pub fn impossible_count(fifo: Option<FifoConfig>) -> Self {
        Self::overflowed(u32::from(fifo.map_or(1, |f| f.watermark)), true)
    }

    /// `samples` delivered, `remaining` still waiting in the FIFO.
    pub fn drained(samples: usize, remaining: u16) -> Self {
        Self {
            samples,
            remaining,
            ..Self::default()
        }
    }

    /// The FIFO had overflowed and was reset: `lost` samples, a lower bound
    /// when the chip does not count what it dropped while full.
    pub fn overflowed(lost: u32, lost_is_lower_bound: bool) -> Self {
        Self {
            overflowed: true,
            lost,
            lost_is_lower_bound,
            ..Self::default()
        }
    }
}

/// A chip whose FIFO the driver can drain.
pub trait FifoImu: Imu {
    /// Reads up to `out.len()` whole samples from the FIFO, oldest first.
    /// On overflow the FIFO is reset (as the autopilots do) and the loss reported.
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error>;
    /// Empties the FIFO.
    fn reset_fifo(&mut self) -> Result<(), Self::Error>;
}

/// What a chip's FIFO does when it is full.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FifoMode {
    /// New samples are dropped while the FIFO is full (keeps the oldest).
    StopOnFull,
    /// The oldest samples are overwritten while the FIFO is full.
    Stream,
}

/// FIFO configuration: the chip's interrupt pin then signals the watermark
/// instead of data ready.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FifoConfig {
    /// Interrupt when this many samples wait (each chip documents its maximum).
    pub watermark: u16,
    /// What happens when the FIFO is full.
    pub mode: FifoMode,
    /// The chip's high-resolution FIFO format where it has one (the
    /// ICM-42688-P's 20-bit packets, DS-000347 §6.1: fixed ±16 g and
    /// ±2000 °/s, 18 and 19 meaningful bits); a chip without one refuses it
    /// ([`super::Error::InvalidConfig`]).
    pub high_resolution: bool,
}
