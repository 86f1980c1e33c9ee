//! The bus interface: turns SPI (`SpiDevice`) and I²C (`I2c`) into the same
//! register reads and writes, so a chip driver is written once for both buses.
//!
//! Both supported chips use the same SPI framing (ICM-42688-P DS-000347 §9.5,
//! LSM6DSOX DS12814 §6.1): the first byte is the register address with bit 7
//! set for a read, cleared for a write; further bytes auto-increment the
//! address. Over I²C the register address is written first, then the data is
//! written after it or read with a repeated start.

use embedded_hal::i2c::I2c;
use embedded_hal::spi::{Operation, SpiDevice};

/// Bit 7 of the SPI address byte selects a read (1) or a write (0).
pub const SPI_READ: u8 = 0x80;

/// Register-level access to a chip, whatever the bus.
pub trait RegisterInterface {
    /// The bus the interface drives (an `SpiDevice` or an `I2c`).
    type Bus;
    /// The bus's error type.
    type BusError;

    /// Writes one register.
    fn write_register(&mut self, register: u8, value: u8) -> Result<(), Self::BusError>;

    /// Reads `buffer.len()` bytes starting at `register` in one bus transaction
    /// (auto-increment, or a fixed address such as a FIFO data port).
    fn read_registers(&mut self, register: u8, buffer: &mut [u8]) -> Result<(), Self::BusError>;

    /// The bus, e.g. to inspect a chip model behind it.
    fn bus(&self) -> &Self::Bus;

    /// The bus, mutably: the emulated board advances the chip model's clock through it.
    fn bus_mut(&mut self) -> &mut Self::Bus;

    /// Gives the bus back.
    fn release(self) -> Self::Bus;
}

/// A chip on an SPI bus, behind its own chip select.
#[derive(Debug)]
pub struct SpiInterface<SPI> {
    spi: SPI,
}

impl<SPI> SpiInterface<SPI> {
    /// Wraps an `SpiDevice` (which owns the chip select).
    pub fn new(spi: SPI) -> Self {
        Self { spi }
    }
}

impl<SPI: SpiDevice> RegisterInterface for SpiInterface<SPI> {
    type Bus = SPI;
    type BusError = SPI::Error;

    fn write_register(&mut self, register: u8, value: u8) -> Result<(), SPI::Error> {
        self.spi.write(&[register & !SPI_READ, value])
    }

    fn read_registers(&mut self, register: u8, buffer: &mut [u8]) -> Result<(), SPI::Error> {
        self.spi.transaction(&mut [
            Operation::Write(&[register | SPI_READ]),
            Operation::Read(buffer),
        ])
    }

    fn bus(&self) -> &SPI {
        &self.spi
    }

    fn bus_mut(&mut self) -> &mut SPI {
        &mut self.spi
    }

    fn release(self) -> SPI {
        self.spi
    }
}

/// A chip on an I²C bus at a 7-bit address (set by the chip's address pin).
#[derive(Debug)]
pub struct I2cInterface<I2C> {
    i2c: I2C,
    address: u8,
}

impl<I2C> I2cInterface<I2C> {
    /// Wraps an `I2c` bus and the chip's 7-bit address.
    pub fn new(i2c: I2C, address: u8) -> Self {
        Self { i2c, address }
    }

    /// The chip's 7-bit address.
    pub fn address(&self) -> u8 {
        self.address
    }
}

impl<I2C: I2c> RegisterInterface for I2cInterface<I2C> {
    type Bus = I2C;
    type BusError = I2C::Error;

    fn write_register(&mut self, register: u8, value: u8) -> Result<(), I2C::Error> {
        self.i2c.write(self.address, &[register, value])
    }

    fn read_registers(&mut self, register: u8, buffer: &mut [u8]) -> Result<(), I2C::Error> {
        self.i2c.write_read(self.address, &[register], buffer)
    }

    fn bus(&self) -> &I2C {
        &self.i2c
    }

    fn bus_mut(&mut self) -> &mut I2C {
        &mut self.i2c
    }

    fn release(self) -> I2C {
        self.i2c
    }
}
