//! The link USART's transmitter, 8N1: the stream and the replies.

use super::pac;
use core::ops::Deref;
use triad::device::board::LinkTx;

/// A USART (any of them: they share one register layout) sending bytes.
pub struct SerialTx<U>(U);

impl<U: Deref<Target = pac::usart1::RegisterBlock>> SerialTx<U> {
    /// Enables the transmitter with BRR = `div_x16`, the board's
    /// f_PCLK / baud rounded (16× oversampling: mantissa.fraction in 12.4).
    pub fn new(usart: U, div_x16: u16) -> Self {
        // SAFETY: BRR takes any 16-bit divider.
        usart.brr().write(|w| unsafe { w.bits(div_x16) });
        usart.cr1().write(|w| w.ue().set_bit().te().set_bit());
        Self(usart)
    }
}

impl<U: Deref<Target = pac::usart1::RegisterBlock>> LinkTx for SerialTx<U> {
    /// Sends the bytes, waiting for the transmit register to empty before each.
    fn write_all(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            while self.0.sr().read().txe().bit_is_clear() {}
            self.0.dr().write(|w| w.dr().set(u16::from(byte)));
        }
    }
}
