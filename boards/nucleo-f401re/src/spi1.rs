//! SPI1 of the STM32F401 as an embedded-hal `SpiDevice`: SCK PA5 (D13), MISO
//! PA6 (D12), MOSI PA7 (D11), chip select PB6 (D10), driven by software around
//! each transaction; the pins are set up in board.rs. Mode 3; the clock
//! divider is the chip's (`SPI_BR` in boards/nucleo-f401re/<chip>.rs).

use super::{pac, SYSCLK_HZ};
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};

/// Polls of a status flag before a wait gives up with `ErrorKind::Other`: a
/// few milliseconds, far beyond one byte at the slowest divider used (1.5 µs).
const POLL_LIMIT: u32 = 100_000;

/// SPI1 as an embedded-hal `SpiDevice`: mode 3, chip select on PB6 around
/// each transaction.
pub struct Spi1Device {
    spi: pac::SPI1,
    cs: pac::GPIOB,
}

impl Spi1Device {
    /// Configures and enables SPI1 (its clock and pins are already on) with
    /// SCK = f_PCLK2 / 2^(br + 1) (RM0368 §20.5.1 CR1 BR, 3 bits; 84 MHz APB2).
    pub fn new(spi: pac::SPI1, cs: pac::GPIOB, br: u8) -> Self {
        // RM0368 §20.5.1: master, BR, CPOL = CPHA = 1, software NSS held high.
        spi.cr1().write(|w| {
            // SAFETY: BR is a 3-bit field; the mask keeps any value inside it.
            unsafe {
                w.mstr()
                    .set_bit()
                    .br()
                    .bits(br & 0b111)
                    .cpol()
                    .set_bit()
                    .cpha()
                    .set_bit()
            }
            .ssm()
            .set_bit()
            .ssi()
            .set_bit()
            .spe()
            .set_bit()
        });
        Self { spi, cs }
    }

    fn transfer_byte(&mut self, out: u8) -> Result<u8, ErrorKind> {
        if !(0..POLL_LIMIT).any(|_| self.spi.sr().read().txe().bit_is_set()) {
            return Err(ErrorKind::Other);
        }
        self.spi.dr().write(|w| w.dr().set(u16::from(out)));
        for _ in 0..POLL_LIMIT {
            let sr = self.spi.sr().read();
            if sr.ovr().bit_is_set() {
                return Err(ErrorKind::Overrun);
            }
            if sr.modf().bit_is_set() {
                return Err(ErrorKind::ModeFault);
            }
            if sr.rxne().bit_is_set() {
                return Ok(self.spi.dr().read().dr().bits() as u8);
            }
        }
        Err(ErrorKind::Other)
    }

    fn operation(&mut self, op: &mut Operation<'_, u8>) -> Result<(), ErrorKind> {
        match op {
            Operation::Read(buf) => buf
                .iter_mut()
                .try_for_each(|b| self.transfer_byte(0).map(|got| *b = got)),
            Operation::Write(buf) => buf
                .iter()
                .try_for_each(|&b| self.transfer_byte(b).map(drop)),
            Operation::Transfer(read, write) => {
                for i in 0..read.len().max(write.len()) {
                    let got = self.transfer_byte(write.get(i).copied().unwrap_or(0))?;
                    if let Some(slot) = read.get_mut(i) {
                        *slot = got;
                    }
                }
                Ok(())
            }
            Operation::TransferInPlace(buf) => buf
                .iter_mut()
                .try_for_each(|b| self.transfer_byte(*b).map(|got| *b = got)),
            Operation::DelayNs(ns) => {
                cortex_m::asm::delay(*ns / (1_000_000_000 / SYSCLK_HZ) + 1);
                Ok(())
            }
        }
    }
}

impl ErrorType for Spi1Device {
    type Error = ErrorKind;
}

impl SpiDevice for Spi1Device {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        self.cs.bsrr().write(|w| w.br6().set_bit());
        let result = operations.iter_mut().try_for_each(|op| self.operation(op));
        // Bounded like every wait: the chip select rises even on a stuck peripheral.
        let _ = (0..POLL_LIMIT).any(|_| self.spi.sr().read().bsy().bit_is_clear());
        self.cs.bsrr().write(|w| w.bs6().set_bit());
        result
    }
}
