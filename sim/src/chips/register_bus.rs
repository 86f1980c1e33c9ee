//! The bus side of a register-level chip model: decodes SPI and I²C
//! transactions into register reads and writes, counts the bytes on the wire,
//! and fails transactions on demand (fault injection). A chip model only says
//! what its registers do ([`RegisterFile`]).

use embedded_hal::i2c::{self, NoAcknowledgeSource};
use embedded_hal::spi;

/// What a chip's register file does on the bus.
pub trait RegisterFile {
    /// Reads one register, with the chip's side effects (clear on read, FIFO pop).
    fn read_register(&mut self, address: u8) -> u8;
    /// Writes one register, with the chip's side effects (reset, flush).
    fn write_register(&mut self, address: u8, value: u8);
    /// The address a burst continues at after `address` (auto-increment rule).
    fn next_address(&self, address: u8) -> u8;
}

/// Where an SPI transaction is: before the address byte, or reading/writing from an address.
#[derive(Clone, Copy, Debug)]
enum SpiState {
    Address,
    Read(u8),
    Write(u8),
}

/// The chip's bus port: SPI framing, I²C address and pointer, byte counts, bus faults.
#[derive(Clone, Debug)]
pub struct BusPort {
    i2c_address: u8,
    i2c_pointer: u8,
    /// SPI driven byte by byte (chip select held by the driver): where the
    /// selected transfer is; `None` while deselected.
    wire: Option<SpiState>,
    bytes: u64,
    failing_transactions: u32,
}

/// Bit 7 of the SPI address byte: read.
const SPI_READ: u8 = 0x80;

impl BusPort {
    /// A port answering I²C at `i2c_address` (SPI needs no address).
    pub const fn new(i2c_address: u8) -> Self {
        Self {
            i2c_address,
            i2c_pointer: 0,
            wire: None,
            bytes: 0,
            failing_transactions: 0,
        }
    }

    /// Bytes moved on the bus so far: SPI every clocked byte (address byte
    /// included); I²C every address byte (one per start or repeated start)
    /// and every data byte. Failed transactions count nothing.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Restarts the byte count.
    pub fn reset_bytes(&mut self) {
        self.bytes = 0;
    }

    /// The next `transactions` bus transactions fail (SPI: `ErrorKind::Other`;
    /// I²C: address NACK, the chip not answering).
    pub fn fail_next(&mut self, transactions: u32) {
        self.failing_transactions = transactions;
    }

    /// Transactions still set to fail.
    pub fn failing(&self) -> u32 {
        self.failing_transactions
    }

    fn take_failure(&mut self) -> bool {
        if self.failing_transactions > 0 {
            self.failing_transactions -= 1;
            true
        } else {
            false
        }
    }

    /// Runs one SPI transaction (chip select asserted throughout).
    pub fn spi<R: RegisterFile>(
        &mut self,
        regs: &mut R,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), spi::ErrorKind> {
        if self.take_failure() {
            return Err(spi::ErrorKind::Other);
        }
        let mut state = SpiState::Address;
        for op in operations.iter_mut() {
            match op {
                spi::Operation::Read(buf) => {
                    for b in buf.iter_mut() {
                        *b = self.spi_byte(regs, &mut state, 0);
                    }
                }
                spi::Operation::Write(buf) => {
                    for &b in buf.iter() {
                        self.spi_byte(regs, &mut state, b);
                    }
                }
                spi::Operation::Transfer(read, write) => {
                    for i in 0..read.len().max(write.len()) {
                        let miso =
                            self.spi_byte(regs, &mut state, write.get(i).copied().unwrap_or(0));
                        if let Some(r) = read.get_mut(i) {
                            *r = miso;
                        }
                    }
                }
                spi::Operation::TransferInPlace(buf) => {
                    for b in buf.iter_mut() {
                        *b = self.spi_byte(regs, &mut state, *b);
                    }
                }
                spi::Operation::DelayNs(_) => {}
            }
        }
        Ok(())
    }

    /// One byte clocked on SPI: MOSI in, MISO out.
    fn spi_byte<R: RegisterFile>(&mut self, regs: &mut R, state: &mut SpiState, mosi: u8) -> u8 {
        self.bytes += 1;
        match *state {
            SpiState::Address => {
                let address = mosi & !SPI_READ;
                *state = if mosi & SPI_READ != 0 {
                    SpiState::Read(address)
                } else {
                    SpiState::Write(address)
                };
                0
            }
            SpiState::Read(address) => {
                *state = SpiState::Read(regs.next_address(address));
                regs.read_register(address)
            }
            SpiState::Write(address) => {
                regs.write_register(address, mosi);
                *state = SpiState::Write(regs.next_address(address));
                0
            }
        }
    }

    /// Chip select asserted (`true`: a new transfer starts with an address
    /// byte) or released, for a driver that holds chip select itself.
    pub fn wire_select(&mut self, selected: bool) {
        self.wire = selected.then_some(SpiState::Address);
    }

    /// One byte clocked while chip select is held; `None` (MISO not driven)
    /// while deselected. Injected bus faults apply to whole transactions
    /// ([`BusPort::spi`], [`BusPort::i2c`]) only.
    pub fn wire_byte<R: RegisterFile>(&mut self, regs: &mut R, mosi: u8) -> Option<u8> {
        let mut state = self.wire?;
        let miso = self.spi_byte(regs, &mut state, mosi);
        self.wire = Some(state);
        Some(miso)
    }

    /// Runs one I²C transaction: the first byte written sets the register
    /// pointer, further written bytes go to consecutive registers, reads
    /// continue from the pointer.
    pub fn i2c<R: RegisterFile>(
        &mut self,
        regs: &mut R,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), i2c::ErrorKind> {
        if address != self.i2c_address || self.take_failure() {
            return Err(i2c::ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address));
        }
        let mut pointer_set = false;
        let mut previous_was_read = None;
        for op in operations.iter_mut() {
            match op {
                i2c::Operation::Write(bytes) => {
                    if previous_was_read != Some(false) {
                        self.bytes += 1; // start or repeated start + address
                    }
                    previous_was_read = Some(false);
                    for &b in bytes.iter() {
                        self.bytes += 1;
                        if pointer_set {
                            regs.write_register(self.i2c_pointer, b);
                            self.i2c_pointer = regs.next_address(self.i2c_pointer);
                        } else {
                            self.i2c_pointer = b;
                            pointer_set = true;
                        }
                    }
                }
                i2c::Operation::Read(buf) => {
                    if previous_was_read != Some(true) {
                        self.bytes += 1;
                    }
                    previous_was_read = Some(true);
                    for b in buf.iter_mut() {
                        self.bytes += 1;
                        *b = regs.read_register(self.i2c_pointer);
                        self.i2c_pointer = regs.next_address(self.i2c_pointer);
                    }
                }
            }
        }
        Ok(())
    }
}

/// Rounds to the nearest code (half away from zero) and saturates to
/// `min..=max`; returns the code and whether the input was beyond the range.
pub fn quantise(value_lsb: f64, min: i16, max: i16) -> (i16, bool) {
    let (code, clipped) = quantise_wide(value_lsb, i32::from(min), i32::from(max));
    // min ≤ code ≤ max, both i16: the conversion is exact.
    (code as i16, clipped)
}

/// [`quantise`] for codes wider than 16 bits (the ICM-42688-P's 20-bit FIFO data).
pub fn quantise_wide(value_lsb: f64, min: i32, max: i32) -> (i32, bool) {
    let rounded = libm::round(value_lsb);
    if rounded > f64::from(max) {
        (max, true)
    } else if rounded < f64::from(min) {
        (min, true)
    } else if rounded.is_nan() {
        // Not a number from the source: the chip would show garbage; 0 is as good and flagged.
        (0, true)
    } else {
        // min ≤ rounded ≤ max: the cast is exact.
        (rounded as i32, false)
    }
}
