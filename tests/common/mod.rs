//! Shared test scaffolding, in the style of eldruin's driver crates: build a
//! driver over embedded-hal-mock from a list of register-level operations, so
//! each test states the exact bus transactions it expects, and finish it by
//! checking that every expectation was met.
#![allow(dead_code)] // each test binary uses a different part

use embedded_hal_mock::eh1::i2c::{Mock as I2cMock, Transaction as I2cTrans};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTrans};
use triad::sensor::interface::{I2cInterface, RegisterInterface, SpiInterface};

/// One register-level bus operation a test expects.
#[derive(Clone, Debug)]
pub enum Op {
    /// Write `value` to `register`.
    Write(u8, u8),
    /// Read `data.len()` bytes from `register` in one burst; the chip answers `data`.
    Read(u8, Vec<u8>),
}

/// Shorthand for [`Op::Write`].
pub fn w(register: u8, value: u8) -> Op {
    Op::Write(register, value)
}

/// Shorthand for [`Op::Read`].
pub fn r(register: u8, data: &[u8]) -> Op {
    Op::Read(register, data.to_vec())
}

/// The SPI transactions of `ops`: a write is one 2-byte transfer with bit 7
/// clear; a read is the address with bit 7 set, then the data, under one chip select.
pub fn spi_transactions(ops: &[Op]) -> Vec<SpiTrans<u8>> {
    let mut t = Vec::new();
    for op in ops {
        t.push(SpiTrans::transaction_start());
        match op {
            Op::Write(register, value) => t.push(SpiTrans::write_vec(vec![*register, *value])),
            Op::Read(register, data) => {
                t.push(SpiTrans::write_vec(vec![register | 0x80]));
                t.push(SpiTrans::read_vec(data.clone()));
            }
        }
        t.push(SpiTrans::transaction_end());
    }
    t
}

/// The I²C transactions of `ops` at `address`: a write sends register and
/// value; a read writes the register then reads with a repeated start.
pub fn i2c_transactions(address: u8, ops: &[Op]) -> Vec<I2cTrans> {
    ops.iter()
        .map(|op| match op {
            Op::Write(register, value) => I2cTrans::write(address, vec![*register, *value]),
            Op::Read(register, data) => {
                I2cTrans::write_read(address, vec![*register], data.clone())
            }
        })
        .collect()
}

/// An SPI interface over a mock expecting exactly `ops`.
pub fn spi_interface(ops: &[Op]) -> SpiInterface<SpiMock<u8>> {
    SpiInterface::new(SpiMock::new(&spi_transactions(ops)))
}

/// An I²C interface at `address` over a mock expecting exactly `ops`.
pub fn i2c_interface(address: u8, ops: &[Op]) -> I2cInterface<I2cMock> {
    I2cInterface::new(I2cMock::new(&i2c_transactions(address, ops)), address)
}

/// A mock bus that can assert it saw every expected transaction.
pub trait Done {
    /// Panics if an expected transaction did not happen.
    fn finish(&mut self);
}

impl Done for SpiMock<u8> {
    fn finish(&mut self) {
        self.done();
    }
}

impl Done for I2cMock {
    fn finish(&mut self) {
        self.done();
    }
}

/// Releases a driver's interface and checks that all expectations were met.
pub fn destroy<I>(interface: I)
where
    I: RegisterInterface,
    I::Bus: Done,
{
    interface.release().finish();
}

/// An SPI or an I²C mock interface behind one type, so a test body runs on both.
pub enum EitherBus {
    /// SPI.
    Spi(SpiInterface<SpiMock<u8>>),
    /// I²C.
    I2c(I2cInterface<I2cMock>),
}

/// The SPI and the I²C (at `address`) interfaces, both expecting exactly `ops`.
pub fn both_buses(address: u8, ops: &[Op]) -> [EitherBus; 2] {
    [
        EitherBus::Spi(spi_interface(ops)),
        EitherBus::I2c(i2c_interface(address, ops)),
    ]
}

impl EitherBus {
    /// Checks that all expectations were met.
    pub fn finish(self) {
        match self {
            EitherBus::Spi(i) => destroy(i),
            EitherBus::I2c(i) => destroy(i),
        }
    }
}

/// Both mocks' errors, as one type (the SPI mock never fails: its errors map to `Other`).
impl RegisterInterface for EitherBus {
    type Bus = EitherBus;
    type BusError = embedded_hal::i2c::ErrorKind;
    fn write_register(&mut self, register: u8, value: u8) -> Result<(), Self::BusError> {
        match self {
            EitherBus::Spi(i) => i
                .write_register(register, value)
                .map_err(|_| embedded_hal::i2c::ErrorKind::Other),
            EitherBus::I2c(i) => i.write_register(register, value),
        }
    }
    fn read_registers(&mut self, register: u8, buffer: &mut [u8]) -> Result<(), Self::BusError> {
        match self {
            EitherBus::Spi(i) => i
                .read_registers(register, buffer)
                .map_err(|_| embedded_hal::i2c::ErrorKind::Other),
            EitherBus::I2c(i) => i.read_registers(register, buffer),
        }
    }
    fn bus(&self) -> &Self {
        self
    }
    fn bus_mut(&mut self) -> &mut Self {
        self
    }
    fn release(self) -> Self {
        self
    }
}
