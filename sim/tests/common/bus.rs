//! Raw register access to a chip model over SPI (address byte, bit 7 set
//! for a read) and I²C, as any driver would do it: for tests that drive the
//! models register by register, without triad's driver.

use embedded_hal::i2c::{I2c, Operation as I2cOperation};
use embedded_hal::spi::{Operation, SpiDevice};

/// Writes `values` from register `address` on (one burst).
pub fn write<D: SpiDevice>(chip: &mut D, address: u8, values: &[u8]) {
    chip.transaction(&mut [
        Operation::Write(&[address & 0x7F]),
        Operation::Write(values),
    ])
    .unwrap();
}

/// Reads `N` bytes from register `address` on (one burst).
pub fn read<D: SpiDevice, const N: usize>(chip: &mut D, address: u8) -> [u8; N] {
    let mut out = [0u8; N];
    chip.transaction(&mut [
        Operation::Write(&[address | 0x80]),
        Operation::Read(&mut out),
    ])
    .unwrap();
    out
}

/// Reads one register.
pub fn read1<D: SpiDevice>(chip: &mut D, address: u8) -> u8 {
    read::<D, 1>(chip, address)[0]
}

/// Reads one register over I²C from the chip at `device`.
pub fn i2c_read1<D: I2c>(chip: &mut D, device: u8, address: u8) -> Result<u8, D::Error> {
    let mut b = [0u8];
    chip.transaction(
        device,
        &mut [I2cOperation::Write(&[address]), I2cOperation::Read(&mut b)],
    )?;
    Ok(b[0])
}

/// Writes one register over I²C to the chip at `device`.
pub fn i2c_write1<D: I2c>(
    chip: &mut D,
    device: u8,
    address: u8,
    value: u8,
) -> Result<(), D::Error> {
    chip.transaction(device, &mut [I2cOperation::Write(&[address, value])])
}
