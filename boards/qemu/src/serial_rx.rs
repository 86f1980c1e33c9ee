//! The link USART's receiver: the host's commands, one byte per interrupt.

use super::pac;
use core::ops::Deref;
use triad::device::board::{LinkRx, RxError};

/// A USART's receive side (the transmitter is [`super::serial_tx::SerialTx`]).
pub struct SerialRx<U>(U);

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialRx<U> {
    /// Enables the receiver and its interrupt (RXNE, and overrun with it).
    /// Call after the transmitter is set up: it only adds bits to CR1.
    pub fn new(usart: U) -> Self {
        usart
            .cr1()
            .modify(|_, w| w.re().set_bit().rxneie().set_bit());
        Self(usart)
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> LinkRx for SerialRx<U> {
    fn read(&mut self) -> Option<Result<u8, RxError>> {
        let sr = self.0.sr().read();
        // RM0090 §30.6.1: reading SR then DR clears RXNE and ORE together.
        if sr.ore().bit_is_set() {
            let _ = self.0.dr().read();
            return Some(Err(RxError::Overrun));
        }
        if sr.fe().bit_is_set() || sr.nf().bit_is_set() {
            let _ = self.0.dr().read();
            return Some(Err(RxError::Line));
        }
        if sr.rxne().bit_is_set() {
            return Some(Ok(self.0.dr().read().dr().bits() as u8));
        }
        None
    }
}
