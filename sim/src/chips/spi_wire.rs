//! A chip model on an SPI bus whose chip select the driver drives itself
//! (embedded-hal `SpiBus` plus an `OutputPin`), as drivers written before
//! `SpiDevice` do: [`SpiWire`] is the model's side, [`WireBus`] and
//! [`WireChipSelect`] the two halves a driver takes, sharing the model.

use core::cell::RefCell;
use core::convert::Infallible;

use embedded_hal::digital::{self, OutputPin};
use embedded_hal::spi::{self, SpiBus};

/// A chip model driven byte by byte with an explicit chip select.
pub trait SpiWire {
    /// Chip select asserted (`true`, pin low) or released.
    fn select(&mut self, selected: bool);
    /// Clocks one byte: MOSI in, MISO out (0xFF, the line not driven, while deselected).
    fn exchange(&mut self, mosi: u8) -> u8;
}

/// The SPI bus half: every byte goes to the shared model.
#[derive(Debug)]
pub struct WireBus<'a, M>(pub &'a RefCell<M>);

/// The chip-select half: low selects the shared model.
#[derive(Debug)]
pub struct WireChipSelect<'a, M>(pub &'a RefCell<M>);

impl<M> spi::ErrorType for WireBus<'_, M> {
    type Error = Infallible;
}

impl<M: SpiWire> SpiBus for WireBus<'_, M> {
    fn read(&mut self, words: &mut [u8]) -> Result<(), Infallible> {
        let mut model = self.0.borrow_mut();
        words.iter_mut().for_each(|w| *w = model.exchange(0));
        Ok(())
    }

    fn write(&mut self, words: &[u8]) -> Result<(), Infallible> {
        let mut model = self.0.borrow_mut();
        words.iter().for_each(|&w| {
            model.exchange(w);
        });
        Ok(())
    }

    fn transfer(&mut self, read: &mut [u8], write: &[u8]) -> Result<(), Infallible> {
        let mut model = self.0.borrow_mut();
        for i in 0..read.len().max(write.len()) {
            let miso = model.exchange(write.get(i).copied().unwrap_or(0));
            if let Some(r) = read.get_mut(i) {
                *r = miso;
            }
        }
        Ok(())
    }

    fn transfer_in_place(&mut self, words: &mut [u8]) -> Result<(), Infallible> {
        let mut model = self.0.borrow_mut();
        words.iter_mut().for_each(|w| *w = model.exchange(*w));
        Ok(())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

impl<M> digital::ErrorType for WireChipSelect<'_, M> {
    type Error = Infallible;
}

impl<M: SpiWire> OutputPin for WireChipSelect<'_, M> {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.0.borrow_mut().select(true);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        self.0.borrow_mut().select(false);
        Ok(())
    }
}
