//! The transmit ring's arithmetic, apart from the registers that drive it
//! ([`crate::serial_tx`] holds the bytes and the DMA stream).
//!
//! Two counters describe a `LEN`-byte ring: `written`, the bytes ever queued
//! (advanced by the link task), and `released`, the bytes ever sent (advanced
//! when a DMA run completes). Both count up and wrap at 2ⁿ (usize); byte
//! number `i` lives at `i mod LEN`, which stays the same across the wrap
//! because `LEN` is a power of two. The bytes `released..written` are
//! pending or being sent; the others are free. The DMA sends a run of
//! consecutive memory, so a run starts at `released` and stops at `written`
//! or at the ring's end, whichever comes first.

/// What the DMA sends next: `len` bytes from ring index `start`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// Index of the first byte in the ring.
    pub start: usize,
    /// Bytes in the run, at least 1, and `start + len <= LEN`.
    pub len: usize,
}

/// Counters of a `LEN`-byte ring (see the module's comment).
pub struct TxRing<const LEN: usize>;

impl<const LEN: usize> TxRing<LEN> {
    /// The counters wrap at 2ⁿ, which only a power of two divides.
    const POWER_OF_TWO: () = assert!(LEN.is_power_of_two(), "the ring's length must be 2ⁿ");

    /// Bytes pending or being sent.
    pub const fn used(written: usize, released: usize) -> usize {
        let () = Self::POWER_OF_TWO;
        written.wrapping_sub(released)
    }

    /// Bytes that can be queued now.
    pub const fn free(written: usize, released: usize) -> usize {
        LEN - Self::used(written, released)
    }

    /// Where byte number `count` lives in the ring.
    pub const fn index(count: usize) -> usize {
        let () = Self::POWER_OF_TWO;
        count % LEN
    }

    /// The next run from `released`, or `None` when nothing is pending.
    pub const fn next_run(written: usize, released: usize) -> Option<Run> {
        let pending = Self::used(written, released);
        if pending == 0 {
            return None;
        }
        let start = Self::index(released);
        let to_end = LEN - start;
        let len = if pending < to_end { pending } else { to_end };
        Some(Run { start, len })
    }
}
