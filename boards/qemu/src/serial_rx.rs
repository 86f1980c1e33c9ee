//! The link USART's interrupt: the host's commands, one byte per
//! interrupt, and the transmit queue's drain ([`super::serial_tx`]).

use super::pac;
use super::serial_tx::TxDrain;
use core::ops::Deref;
use triad::device::board::{LinkRx, RxError};

/// A USART's interrupt side: its receiver, and the drain of its transmit
/// queue (the firmware's transmitter queues with [`super::serial_tx::SerialTx`]).
pub struct SerialRx<U> {
    usart: U,
    tx: TxDrain,
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialRx<U> {
    /// Enables the receiver and its interrupt (RXNE, and overrun with it).
    /// Call after the transmitter is set up: it only adds bits to CR1.
    pub fn new(usart: U, tx: TxDrain) -> Self {
        usart
            .cr1()
            .modify(|_, w| w.re().set_bit().rxneie().set_bit());
        Self { usart, tx }
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> LinkRx for SerialRx<U> {
    fn read(&mut self) -> Option<Result<u8, RxError>> {
        let sr = self.usart.sr().read();
        // RM0090 §30.6.1: reading SR then DR clears RXNE and ORE together.
        if sr.ore().bit_is_set() {
            let _ = self.usart.dr().read();
            return Some(Err(RxError::Overrun));
        }
        if sr.fe().bit_is_set() || sr.nf().bit_is_set() {
            let _ = self.usart.dr().read();
            return Some(Err(RxError::Line));
        }
        if sr.rxne().bit_is_set() {
            return Some(Ok(self.usart.dr().read().dr().bits() as u8));
        }
        None
    }

    /// Every queued byte goes at once: the ring is always empty after.
    fn transmit(&mut self) -> bool {
        self.tx.drain(&self.usart);
        true
    }
}
