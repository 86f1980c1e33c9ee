//! The transmit ring's arithmetic, apart from the registers that drive it
//! (each board's `serial_tx` holds the bytes and drains them: by DMA on the
//! NUCLEO, from the USART's interrupt on the emulated board).
//!
//! Two counters describe a `LEN`-byte ring: `written`, the bytes ever queued
//! (advanced by the transmitter), and `released`, the bytes ever sent (advanced
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

#[cfg(test)]
mod tests {
    use super::*;

    type Ring = TxRing<8>;

    #[test]
    fn runs_stop_at_the_end_of_the_ring_and_wrap() {
        assert_eq!(Ring::next_run(0, 0), None);
        assert_eq!(Ring::free(0, 0), 8);
        // 6 queued from index 5: 3 to the ring's end, then 3 from 0.
        assert_eq!(Ring::next_run(11, 5), Some(Run { start: 5, len: 3 }));
        assert_eq!(Ring::next_run(11, 8), Some(Run { start: 0, len: 3 }));
        assert_eq!(Ring::free(11, 5), 2);
        // Across the counters' own wrap.
        let written = 2usize;
        let released = usize::MAX - 1;
        assert_eq!(Ring::used(written, released), 4);
        assert_eq!(
            Ring::next_run(written, released),
            Some(Run { start: 6, len: 2 })
        );
    }
}
