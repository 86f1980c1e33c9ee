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
use core::ops::Deref;
use core::sync::atomic::{AtomicU8, AtomicUsize, Ordering};
use triad::device::board::LinkTx;
use triad::device::tx_ring::TxRing;

/// Bytes queued for the line: four longest packets.
pub const TX_QUEUE_LEN: usize = 1024;

type Ring = TxRing<TX_QUEUE_LEN>;

/// The bytes queued. Atomics so that the transmitter's stores and the
/// interrupt's loads need no `unsafe`: the transmitter stores only into free
/// bytes, the interrupt loads only pending ones.
static BUFFER: [AtomicU8; TX_QUEUE_LEN] = [const { AtomicU8::new(0) }; TX_QUEUE_LEN];

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
        for (slot, &byte) in BUFFER[start..].iter().zip(to_end) {
            slot.store(byte, Ordering::Relaxed);
        }
        for (slot, &byte) in BUFFER.iter().zip(from_start) {
            slot.store(byte, Ordering::Relaxed);
        }
        // Release: the bytes are in before the interrupt can see them.
        WRITTEN.store(written.wrapping_add(bytes.len()), Ordering::Release);
        self.usart.cr1().modify(|_, w| w.txeie().set_bit());
        cortex_m::peripheral::NVIC::pend(pac::Interrupt::USART2);
        true
    }
}

impl TxDrain {
    /// Writes the queued bytes to `usart` (QEMU's takes each at once: no
    /// TXE to wait for); then stops the transmit interrupt and returns
    /// true (the ring is empty).
    pub fn drain(&mut self, usart: &pac::usart1::RegisterBlock) -> bool {
        let written = WRITTEN.load(Ordering::Acquire);
        let mut released = RELEASED.load(Ordering::Relaxed);
        while let Some(run) = Ring::next_run(written, released) {
            for slot in &BUFFER[run.start..run.start + run.len] {
                let byte = slot.load(Ordering::Relaxed);
                usart.dr().write(|w| w.dr().set(u16::from(byte)));
                released = released.wrapping_add(1);
            }
        }
        RELEASED.store(released, Ordering::Release);
        usart.cr1().modify(|_, w| w.txeie().clear_bit());
        // Bytes queued since `written` was read pend this interrupt again.
        true
    }
}
