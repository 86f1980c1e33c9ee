//! Status flags carried by every frame.

use core::ops::{BitAnd, BitOr, BitOrAssign};

/// Status bits of a frame (a `u16` on the wire, little-endian).
///
/// The clip flags cover every sample that went into the frame (with
/// decimation, one clipped sample of the N averaged marks the frame).
/// Bits not named here are reserved: senders transmit 0, decoders keep them
/// as received ([`Flags::from_bits_retain`]) and ignore them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Flags(u16);

impl Flags {
    /// Bit 0: an accelerometer axis reached its full-scale limit, so the
    /// whole corrected triad is unreliable.
    pub const ACCEL_CLIPPED: Flags = Flags(1 << 0);
    /// Bit 1: a gyroscope axis reached its full-scale limit.
    pub const GYRO_CLIPPED: Flags = Flags(1 << 1);
    /// Bit 2: the sensor's FIFO overflowed since the previous frame: samples
    /// were lost inside the chip.
    pub const FIFO_OVERFLOW: Flags = Flags(1 << 2);
    /// Bit 3: at least one sample step began before the previous one
    /// finished since the previous frame (`overruns` > 0).
    pub const OVERRUN: Flags = Flags(1 << 3);
    /// Bit 4: the firmware dropped whole frames since the previous frame
    /// because the link was full (`dropped` > 0).
    pub const DROPPED: Flags = Flags(1 << 4);
    /// Bit 5: no valid calibration is applied; the values are the chip's
    /// readings scaled to SI units only, and `calibration_id` means nothing.
    pub const UNCALIBRATED: Flags = Flags(1 << 5);
    /// Bit 6: a raw frame: the values are the chip's counts (scaled to SI
    /// with its nominal sensitivity by `triad decode`), not corrected.
    pub const RAW: Flags = Flags(1 << 6);
    /// Bit 7: the chip ran its self-test since the previous frame: the
    /// samples it could not measure meanwhile are counted in this frame's
    /// `overruns` (with OVERRUN).
    pub const SELF_TEST: Flags = Flags(1 << 7);
    /// Bit 8: the board's flash erased or programmed since the previous
    /// frame on a board where that stalls the CPU (a single-bank flash):
    /// the samples missed meanwhile are in this frame's `overruns` (or its
    /// FIFO_OVERFLOW).
    pub const FLASH_STALL: Flags = Flags(1 << 8);
    /// Every bit this version of the protocol defines.
    pub const KNOWN: Flags = Flags(0x01FF);

    /// No flag set.
    pub const fn empty() -> Flags {
        Flags(0)
    }

    /// The flags with exactly these bits, reserved ones included.
    pub const fn from_bits_retain(bits: u16) -> Flags {
        Flags(bits)
    }

    /// The bits as sent on the wire.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// True when no bit is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// True when every bit of `other` is set in `self`.
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Both sets of bits.
    pub const fn union(self, other: Flags) -> Flags {
        Flags(self.0 | other.0)
    }

    /// Sets the bits of `other`.
    pub fn insert(&mut self, other: Flags) {
        self.0 |= other.0;
    }

    /// Clears the bits of `other`.
    pub fn remove(&mut self, other: Flags) {
        self.0 &= !other.0;
    }

    /// Sets or clears the bits of `other` as `value` says.
    pub fn set(&mut self, other: Flags, value: bool) {
        if value {
            self.insert(other);
        } else {
            self.remove(other);
        }
    }
}

impl BitOr for Flags {
    type Output = Flags;
    fn bitor(self, rhs: Flags) -> Flags {
        self.union(rhs)
    }
}

impl BitOrAssign for Flags {
    fn bitor_assign(&mut self, rhs: Flags) {
        self.insert(rhs);
    }
}

impl BitAnd for Flags {
    type Output = Flags;
    fn bitand(self, rhs: Flags) -> Flags {
        Flags(self.0 & rhs.0)
    }
}
