//! A chip model shared by a driver and the delay it waits with, so that
//! waiting lets the model's time pass: what a procedure that sleeps while
//! the chip samples (the self-test) needs off-target. The driver talks to
//! the model through [`SharedBus`]; every [`ModelDelay`] wait advances the
//! same model's clock by as long, and counts the time waited.

use core::cell::RefCell;

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::{self, I2c};
use embedded_hal::spi::{self, SpiDevice};

/// A chip model whose time moves only when told.
pub trait Clocked {
    /// Lets `ns` nanoseconds pass.
    fn advance(&mut self, ns: u64);
}

/// The driver's side: the model as an SPI device and an I²C bus, borrowed
/// for each transaction.
#[derive(Debug)]
pub struct SharedBus<'a, M>(pub &'a RefCell<M>);

/// The delay's side: each wait advances the model's clock by as long.
#[derive(Debug)]
pub struct ModelDelay<'a, M> {
    model: &'a RefCell<M>,
    elapsed_ns: u64,
}

impl<'a, M> ModelDelay<'a, M> {
    /// A delay driving `model`'s clock.
    pub fn new(model: &'a RefCell<M>) -> Self {
        Self {
            model,
            elapsed_ns: 0,
        }
    }

    /// The time waited so far, ns.
    pub fn elapsed_ns(&self) -> u64 {
        self.elapsed_ns
    }

    /// The model (e.g. to inject a fault between two waits).
    pub fn model(&self) -> &'a RefCell<M> {
        self.model
    }
}

impl<M: Clocked> DelayNs for ModelDelay<'_, M> {
    fn delay_ns(&mut self, ns: u32) {
        self.model.borrow_mut().advance(u64::from(ns));
        self.elapsed_ns += u64::from(ns);
    }
}

impl<M: spi::ErrorType> spi::ErrorType for SharedBus<'_, M> {
    type Error = M::Error;
}

impl<M: SpiDevice> SpiDevice for SharedBus<'_, M> {
    fn transaction(
        &mut self,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), Self::Error> {
        self.0.borrow_mut().transaction(operations)
    }
}

impl<M: i2c::ErrorType> i2c::ErrorType for SharedBus<'_, M> {
    type Error = M::Error;
}

impl<M: I2c> I2c for SharedBus<'_, M> {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        self.0.borrow_mut().transaction(address, operations)
    }
}
