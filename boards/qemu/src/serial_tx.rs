//! The link USART's transmitter, 8N1: the stream and the replies, queued by
//! the firmware's transmitter into a ring ([`triad::device::tx_ring`]) and sent from the
//! USART's interrupt ([`TxDrain`]), so that no task waits on the line.
//!
//! QEMU 7.2's STM32 USART sends a byte the moment DR is written and keeps
//! TXE set, and does not raise the transmit interrupt by itself: after
//! enabling TXEIE the transmitter pends the USART's interrupt, which on
//! hardware would fire anyway (pending it there is harmless).
//!
//! So the drain never reads SR: TXE never clears here, and every SR read
//! makes QEMU call `qemu_chr_fe_accept_input`, which wakes its main loop
//! (an eventfd write, then the two threads trade the global lock). A read
//! per byte sent was most of the emulator's time at 53 kB per device
//! second (the soak's bound); the receiver's one read per interrupt is
//! what is left.

use super::pac;
use core::cell::UnsafeCell;
use core::ops::Deref;
use core::sync::atomic::{AtomicUsize, Ordering};
use triad::device::board::LinkTx;
use triad::device::tx_ring::TxRing;
use triad::protocol::MAX_WIRE_LEN;

/// Bytes queued for the line: four longest packets.
pub const TX_QUEUE_LEN: usize = 1024;

type Ring = TxRing<TX_QUEUE_LEN>;

/// The ring's bytes, then room for one longest packet past its end: a
/// packet is encoded straight into the free bytes from the write position
/// ([`SerialTx::queue_encoded`]), and what ran past the ring's end is then
/// copied to its start (a packet's tail, once per lap of the ring), where
/// copying every byte in would cost two instructions each.
struct Bytes(UnsafeCell<[u8; TX_QUEUE_LEN + MAX_WIRE_LEN]>);

// SAFETY: two parties touch the bytes, each through raw pointers or a
// reference to bytes the other does not touch: the one `SerialTx` writes
// only free bytes (outside RELEASED..WRITTEN, and the spare bytes past the
// ring's end), and the one `TxDrain` reads only pending ones
// (RELEASED..WRITTEN). WRITTEN's release store after the writes and the
// drain's acquire load before its reads order them; RELEASED's likewise
// hand bytes back.
unsafe impl Sync for Bytes {}

impl Bytes {
    fn base(&self) -> *mut u8 {
        self.0.get().cast()
    }
}

/// The bytes queued.
static BUFFER: Bytes = Bytes(UnsafeCell::new([0; TX_QUEUE_LEN + MAX_WIRE_LEN]));

/// Bytes ever queued, wrapping: stored only by [`SerialTx::queue`] (one
/// `SerialTx` exists: it owns USART2).
static WRITTEN: AtomicUsize = AtomicUsize::new(0);

/// Bytes ever sent, wrapping: stored only by [`TxDrain::drain`] (one
/// `TxDrain`, in the USART's interrupt).
static RELEASED: AtomicUsize = AtomicUsize::new(0);

/// The transmitter's side: queues bytes.
pub struct SerialTx<U> {
    usart: U,
}

/// The USART interrupt's side: moves queued bytes to DR.
pub struct TxDrain(());

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialTx<U> {
    /// Enables the transmitter with BRR = `div_x16`, the board's
    /// f_PCLK / baud rounded (16× oversampling: mantissa.fraction in 12.4).
    /// With its [`TxDrain`]: there is one of each.
    pub fn new(usart: U, div_x16: u16) -> (Self, TxDrain) {
        // SAFETY: BRR takes any 16-bit divider.
        usart.brr().write(|w| unsafe { w.bits(div_x16) });
        usart.cr1().write(|w| w.ue().set_bit().te().set_bit());
        (Self { usart }, TxDrain(()))
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> LinkTx for SerialTx<U> {
    fn room(&self) -> usize {
        Ring::free(
            WRITTEN.load(Ordering::Relaxed),
            RELEASED.load(Ordering::Acquire),
        )
    }

    fn queue(&mut self, bytes: &[u8]) -> bool {
        if bytes.len() > self.room() {
            return false;
        }
        let written = WRITTEN.load(Ordering::Relaxed);
        let start = Ring::index(written);
        // Two copies at most: to the ring's end, then from its start.
        let (to_end, from_start) = bytes.split_at(bytes.len().min(TX_QUEUE_LEN - start));
        let base = BUFFER.base();
        // SAFETY: the bytes written..written + len are free (room), at
        // start..start + to_end.len() ≤ TX_QUEUE_LEN and from the ring's start.
        unsafe {
            core::ptr::copy_nonoverlapping(to_end.as_ptr(), base.add(start), to_end.len());
            core::ptr::copy_nonoverlapping(from_start.as_ptr(), base, from_start.len());
        }
        self.queued(written, bytes.len());
        true
    }

    fn queue_encoded(&mut self, encode: impl FnOnce(&mut [u8; MAX_WIRE_LEN]) -> usize) -> bool {
        if self.room() < MAX_WIRE_LEN {
            return false;
        }
        let written = WRITTEN.load(Ordering::Relaxed);
        let start = Ring::index(written);
        let base = BUFFER.base();
        // SAFETY: start + MAX_WIRE_LEN is within the array; of those bytes,
        // the ring's are free (room) and the spare ones past its end are
        // read by no one; the reference ends before the drain may see them.
        let out = unsafe { &mut *base.add(start).cast::<[u8; MAX_WIRE_LEN]>() };
        let len = encode(out).min(MAX_WIRE_LEN);
        let past_end = (start + len).saturating_sub(TX_QUEUE_LEN);
        // SAFETY: the bytes past the ring's end go to its first `past_end`
        // bytes, free as the rest of the packet's (room ≥ MAX_WIRE_LEN ≥ len).
        unsafe { core::ptr::copy_nonoverlapping(base.add(TX_QUEUE_LEN), base, past_end) };
        self.queued(written, len);
        true
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialTx<U> {
    /// `len` bytes from `written` on are in: hands them to the interrupt.
    fn queued(&mut self, written: usize, len: usize) {
        // Release: the bytes are in before the interrupt can see them.
        WRITTEN.store(written.wrapping_add(len), Ordering::Release);
        self.usart.cr1().modify(|_, w| w.txeie().set_bit());
        cortex_m::peripheral::NVIC::pend(pac::Interrupt::USART2);
    }
}

impl TxDrain {
    /// Writes the queued bytes to `usart` (QEMU's takes each at once: no
    /// TXE to wait for), which empties the ring; then stops the transmit
    /// interrupt.
    pub fn drain(&mut self, usart: &pac::usart1::RegisterBlock) {
        let written = WRITTEN.load(Ordering::Acquire);
        let mut released = RELEASED.load(Ordering::Relaxed);
        while let Some(run) = Ring::next_run(written, released) {
            // SAFETY: the run's bytes are pending (see `Bytes`), inside the ring.
            let pending =
                unsafe { core::slice::from_raw_parts(BUFFER.base().add(run.start), run.len) };
            for &byte in pending {
                usart.dr().write(|w| w.dr().set(u16::from(byte)));
            }
            released = released.wrapping_add(run.len);
        }
        RELEASED.store(released, Ordering::Release);
        usart.cr1().modify(|_, w| w.txeie().clear_bit());
        // Bytes queued since `written` was read pend this interrupt again.
    }
}
