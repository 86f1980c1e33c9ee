//! The bytes one DMA transfer reads or writes, as the HAL's `Transfer`
//! takes them (embedded-dma's buffer traits).
//!
//! Why not the HAL's own buffers (`&'static [u8]`, `&'static mut [u8]`):
//! the firmware's buffers are runs of a ring that the CPU keeps writing
//! elsewhere (the transmit ring), a ring the CPU reads while the DMA writes
//! it (the receive ring), or the caller's bytes of one SPI transfer, which
//! ends before the call returns. None is a `'static` reference owned by the
//! transfer; each is an address and a length whose user answers for it.

use core::sync::atomic::AtomicU8;

use embedded_dma::{ReadBuffer, WriteBuffer};

/// An address and a length. Plain numbers, so that what holds one stays
/// `Send` (RTIC moves the board's parts to their tasks).
#[derive(Clone, Copy)]
pub(crate) struct Region {
    address: usize,
    len: usize,
}

impl Region {
    /// No bytes: a transfer's placeholder before its first run.
    pub(crate) const EMPTY: Region = Region { address: 0, len: 0 };

    /// `bytes`, which the user keeps valid and leaves alone (neither reads
    /// what the DMA writes nor writes what it reads) until the transfer
    /// using this region has ended.
    // SPI1's DMA only (not in the I²C build).
    #[cfg_attr(feature = "bus-i2c", allow(dead_code))]
    pub(crate) fn of(bytes: &[u8]) -> Region {
        Region {
            address: bytes.as_ptr() as usize,
            len: bytes.len(),
        }
    }

    /// `len` bytes of `cells` from `start` (both within `cells`), on the
    /// same terms as [`Region::of`]; atomics, because the CPU reads or
    /// writes other cells of the same buffer meanwhile.
    pub(crate) fn cells(cells: &'static [AtomicU8], start: usize, len: usize) -> Region {
        debug_assert!(start + len <= cells.len());
        Region {
            address: cells.as_ptr() as usize + start,
            len,
        }
    }

    /// The length.
    #[cfg_attr(feature = "bus-i2c", allow(dead_code))]
    pub(crate) fn len(&self) -> usize {
        self.len
    }
}

// SAFETY: a `Region` is made only on the terms of `Region::of` and
// `Region::cells`: its `len` bytes from `address` stay valid, and the CPU
// does not write them, until the transfer reading them has ended.
unsafe impl ReadBuffer for Region {
    type Word = u8;
    unsafe fn read_buffer(&self) -> (*const u8, usize) {
        (self.address as *const u8, self.len)
    }
}

// SAFETY: as for `ReadBuffer`; the CPU does not access the bytes the
// transfer writes until it has written them (or ended).
unsafe impl WriteBuffer for Region {
    type Word = u8;
    unsafe fn write_buffer(&mut self) -> (*mut u8, usize) {
        (self.address as *mut u8, self.len)
    }
}
