//! The link USART's transmitter, 8N1: the stream and the replies, queued by
//! the link task and sent from the USART's interrupt ([`TxDrain`]), so that
//! no task waits on the line.
//!
//! QEMU 7.2's STM32 USART sends a byte the moment DR is written and keeps
//! TXE set, and does not raise the transmit interrupt by itself: after
//! enabling TXEIE the transmitter pends the USART's interrupt, which on
//! hardware would fire anyway (pending it there is harmless).

use super::pac;
use core::ops::Deref;
use heapless::spsc::{Consumer, Producer};
use triad::device::board::LinkTx;

/// Bytes queued for the line: more than two longest packets.
pub const TX_QUEUE_LEN: usize = 1024;

/// The link task's side: queues bytes.
pub struct SerialTx<U> {
    usart: U,
    queue: Producer<'static, u8>,
}

/// The USART interrupt's side: moves queued bytes to DR.
pub struct TxDrain {
    queue: Consumer<'static, u8>,
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialTx<U> {
    /// Enables the transmitter with BRR = `div_x16`, the board's
    /// f_PCLK / baud rounded (16× oversampling: mantissa.fraction in 12.4),
    /// feeding it from `queue`.
    pub fn new(usart: U, div_x16: u16, queue: Producer<'static, u8>) -> Self {
        // SAFETY: BRR takes any 16-bit divider.
        usart.brr().write(|w| unsafe { w.bits(div_x16) });
        usart.cr1().write(|w| w.ue().set_bit().te().set_bit());
        Self { usart, queue }
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> LinkTx for SerialTx<U> {
    fn room(&self) -> usize {
        self.queue.capacity() - self.queue.len()
    }

    fn queue(&mut self, bytes: &[u8]) -> bool {
        if bytes.len() > self.room() {
            return false;
        }
        for &byte in bytes {
            // Room was checked: every byte fits.
            let _ = self.queue.enqueue(byte);
        }
        self.usart.cr1().modify(|_, w| w.txeie().set_bit());
        cortex_m::peripheral::NVIC::pend(pac::Interrupt::USART2);
        true
    }
}

impl TxDrain {
    /// The drain of `queue`.
    pub fn new(queue: Consumer<'static, u8>) -> Self {
        Self { queue }
    }

    /// Writes queued bytes while `usart` takes them; when the queue is
    /// empty, stops the transmit interrupt and returns true.
    pub fn drain(&mut self, usart: &pac::usart1::RegisterBlock) -> bool {
        while usart.sr().read().txe().bit_is_set() {
            match self.queue.dequeue() {
                Some(byte) => {
                    usart.dr().write(|w| w.dr().set(u16::from(byte)));
                }
                None => {
                    usart.cr1().modify(|_, w| w.txeie().clear_bit());
                    return true;
                }
            }
        }
        false
    }
}
