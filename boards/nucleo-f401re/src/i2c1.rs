//! I²C1 of the STM32F401 as a blocking embedded-hal 1.0 `I2c` master: fast
//! mode, 400 kHz, SCL PB8 (D15), SDA PB9 (D14); the pins are set up in board.rs.
//!
//! The sequences follow RM0368 §18.3.3 (master mode): START → SB, address →
//! ADDR (or AF: not acknowledged), bytes through DR on TxE and BTF; reception
//! closed as the manual requires for 1, 2 and more bytes (ACK cleared and STOP
//! set before the last byte is clocked in). Every wait polls a bounded number
//! of times and returns an error instead of hanging on a stuck bus; after any
//! error the bus is released with STOP (and the peripheral reset if it stays
//! busy), so the next transaction starts clean.

use super::{pac, APB1_HZ};
use embedded_hal::i2c::{
    ErrorKind, ErrorType, I2c, NoAcknowledgeSource, Operation, SevenBitAddress,
};

/// SCL frequency: fast mode.
const SCL_HZ: u32 = 400_000;
/// RM0368 §18.6.8: in fast mode with DUTY = 0, T_high = CCR·T_PCLK1 and
/// T_low = 2·CCR·T_PCLK1, so f_SCL = f_PCLK1 / (3·CCR): 42 MHz / 1.2 MHz = 35
/// exactly (T_low 1.67 µs ≥ 1.3 µs, T_high 0.83 µs ≥ 0.6 µs of the I²C spec).
const CCR: u16 = (APB1_HZ / (3 * SCL_HZ)) as u16;
/// RM0368 §18.6.9: TRISE = t_r,max · f_PCLK1 + 1, with t_r,max = 300 ns in
/// fast mode: 0.3 µs · 42 MHz = 12.6 → 12, + 1 = 13.
const TRISE: u8 = (APB1_HZ / 1_000_000 * 300 / 1_000 + 1) as u8;
/// RM0368 §18.6.2: CR2 FREQ is the APB1 clock in MHz (42).
const FREQ_MHZ: u8 = (APB1_HZ / 1_000_000) as u8;

/// Polls of a status flag before a wait gives up. Each poll reads SR1 over
/// APB1 (several core cycles at 84 MHz), so this is a few milliseconds: far
/// beyond one byte at 400 kHz (22.5 µs) and any clock stretching of the
/// supported chips, short enough that a dead bus costs one missed sample
/// period instead of the firmware.
const POLL_LIMIT: u32 = 100_000;

// SR1 flags (RM0368 §18.6.6).
const SB: u16 = 1 << 0;
const ADDR: u16 = 1 << 1;
const BTF: u16 = 1 << 2;
const RXNE: u16 = 1 << 6;
const TXE: u16 = 1 << 7;
const BERR: u16 = 1 << 8;
const ARLO: u16 = 1 << 9;
const AF: u16 = 1 << 10;
const OVR: u16 = 1 << 11;
const ERRORS: u16 = BERR | ARLO | AF | OVR;

/// What the bus was waiting for when it failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The bus to be free before a START (SR2 BUSY).
    BusFree,
    /// The START condition (SR1 SB).
    Start,
    /// The address to be acknowledged (SR1 ADDR).
    Address,
    /// The data register to empty (SR1 TxE).
    Transmit,
    /// The last byte to leave the shift register (SR1 BTF).
    ByteTransferred,
    /// A received byte (SR1 RxNE or BTF).
    Receive,
    /// A read of no bytes: the STM32F4 I²C cannot address a chip for reading
    /// without clocking in at least one byte.
    EmptyRead,
    /// Nothing: the address given is not a 7-bit address (above 0x7F).
    InvalidAddress(u8),
}

/// An I²C1 failure: the embedded-hal kind, where it happened and SR1 then.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct I2cError {
    /// What went wrong (NACK of address or data, bus error, arbitration lost,
    /// overrun; `Other` for a timeout, an empty read or an invalid address).
    pub kind: ErrorKind,
    /// What the transfer was waiting for.
    pub stage: Stage,
    /// SR1 when the failure was seen (RM0368 §18.6.6).
    pub sr1: u16,
}

impl embedded_hal::i2c::Error for I2cError {
    fn kind(&self) -> ErrorKind {
        self.kind
    }
}

/// I²C1 as a bus master.
pub struct I2c1 {
    i2c: pac::I2C1,
}

impl I2c1 {
    /// Configures and enables I²C1 (its clock and pins are already on).
    pub fn new(i2c: pac::I2C1) -> Self {
        let bus = Self { i2c };
        bus.configure();
        bus
    }

    /// RM0368 §18.3.3: FREQ, CCR and TRISE are written with the peripheral
    /// disabled, then PE enables it.
    fn configure(&self) {
        let i2c = &self.i2c;
        i2c.cr1().write(|w| w.pe().clear_bit());
        // SAFETY: FREQ 42 is inside the 2..=50 MHz range RM0368 §18.6.2 allows.
        i2c.cr2().write(|w| unsafe { w.freq().bits(FREQ_MHZ) });
        // SAFETY: CCR 35 fits the 12-bit field and is ≥ 1, the fast-mode minimum (§18.6.8).
        i2c.ccr()
            .write(|w| unsafe { w.f_s().fast().duty().duty2_1().ccr().bits(CCR) });
        i2c.trise().write(|w| w.trise().set(TRISE));
        i2c.cr1().write(|w| w.pe().set_bit());
    }

    fn sr1(&self) -> u16 {
        self.i2c.sr1().read().bits()
    }

    /// Polls SR1 until one of `flags` is set; an error flag or the poll limit
    /// ends the wait with an error naming `stage`.
    fn wait(&self, flags: u16, stage: Stage) -> Result<u16, I2cError> {
        let mut sr1 = 0;
        for _ in 0..POLL_LIMIT {
            sr1 = self.sr1();
            if sr1 & ERRORS != 0 {
                return Err(self.error_from(sr1, stage));
            }
            if sr1 & flags != 0 {
                return Ok(sr1);
            }
        }
        Err(I2cError {
            kind: ErrorKind::Other,
            stage,
            sr1,
        })
    }

    /// The error that SR1's error flags say, with the flags cleared (rc_w0).
    fn error_from(&self, sr1: u16, stage: Stage) -> I2cError {
        let kind = if sr1 & AF != 0 {
            ErrorKind::NoAcknowledge(if stage == Stage::Address {
                NoAcknowledgeSource::Address
            } else {
                NoAcknowledgeSource::Data
            })
        } else if sr1 & ARLO != 0 {
            ErrorKind::ArbitrationLoss
        } else if sr1 & BERR != 0 {
            ErrorKind::Bus
        } else {
            ErrorKind::Overrun
        };
        // `modify` writes 1 to the rc_w0 flags it does not touch: only these clear.
        self.i2c.sr1().modify(|_, w| {
            w.af()
                .clear_bit()
                .arlo()
                .clear_bit()
                .berr()
                .clear_bit()
                .ovr()
                .clear_bit()
        });
        I2cError { kind, stage, sr1 }
    }

    /// START (or repeated START; `start_requested` when the end of a
    /// previous reception already asked for it) and the address byte with the
    /// direction bit; returns once ADDR is set, *before* clearing it (the read
    /// sequences set ACK/POS/STOP between the two).
    fn address(&self, address: u8, read: bool, start_requested: bool) -> Result<(), I2cError> {
        if !start_requested {
            self.i2c.cr1().modify(|_, w| w.start().set_bit());
        }
        self.wait(SB, Stage::Start)?;
        // SB clears on the SR1 read above followed by this DR write (§18.6.6).
        self.i2c
            .dr()
            .write(|w| w.dr().set((address << 1) | u8::from(read)));
        self.wait(ADDR, Stage::Address).map(drop)
    }

    /// ADDR clears on reading SR1 then SR2 (§18.6.7).
    fn clear_addr(&self) {
        let _ = self.i2c.sr1().read();
        let _ = self.i2c.sr2().read();
    }

    fn stop(&self) {
        self.i2c.cr1().modify(|_, w| w.stop().set_bit());
    }

    /// The end of a reception: STOP when the transaction ends, else the
    /// repeated START of the next operation (RM0368 §18.3.3 allows either
    /// at the same point).
    fn end_reception(&self, last: bool) {
        if last {
            self.stop();
        } else {
            self.i2c.cr1().modify(|_, w| w.start().set_bit());
        }
    }

    fn write_bytes<'a>(
        &self,
        address: u8,
        bytes: impl Iterator<Item = &'a u8>,
        start_requested: bool,
    ) -> Result<(), I2cError> {
        self.address(address, false, start_requested)?;
        self.clear_addr();
        let mut sent = 0usize;
        for &byte in bytes {
            self.wait(TXE, Stage::Transmit)?;
            self.i2c.dr().write(|w| w.dr().set(byte));
            sent += 1;
        }
        if sent == 0 {
            // An address-only write (a probe): the acknowledge was all there is.
            return Ok(());
        }
        // The last byte is out and acknowledged: a STOP or repeated START may follow.
        self.wait(BTF, Stage::ByteTransferred).map(drop)
    }

    fn read_dr(&self) -> u8 {
        self.i2c.dr().read().dr().bits()
    }

    /// Reads `len` bytes into `slots` and ends with STOP when `last`, else
    /// with the repeated START of the next operation. RM0368 §18.3.3 "Closing
    /// the communication": the last byte is received with ACK cleared. The
    /// steps the manual times against the byte on the wire (clearing ADDR,
    /// then ACK or STOP) run with interrupts masked: a few cycles.
    fn read_bytes<'a>(
        &self,
        address: u8,
        len: usize,
        mut slots: impl Iterator<Item = &'a mut u8>,
        last: bool,
        start_requested: bool,
    ) -> Result<(), I2cError> {
        let mut put = |byte: u8| {
            if let Some(slot) = slots.next() {
                *slot = byte;
            }
        };
        match len {
            0 => {
                return Err(I2cError {
                    kind: ErrorKind::Other,
                    stage: Stage::EmptyRead,
                    sr1: self.sr1(),
                })
            }
            1 => {
                // One byte: NACK it, then STOP (or the repeated START) right after ADDR.
                self.i2c.cr1().modify(|_, w| w.ack().clear_bit());
                self.address(address, true, start_requested)?;
                cortex_m::interrupt::free(|_| {
                    self.clear_addr();
                    self.end_reception(last);
                });
                self.wait(RXNE, Stage::Receive)?;
                put(self.read_dr());
            }
            2 => {
                // Two bytes: POS makes the NACK apply to the second byte.
                self.i2c
                    .cr1()
                    .modify(|_, w| w.ack().set_bit().pos().set_bit());
                self.address(address, true, start_requested)?;
                cortex_m::interrupt::free(|_| {
                    self.clear_addr();
                    self.i2c.cr1().modify(|_, w| w.ack().clear_bit());
                });
                self.wait(BTF, Stage::Receive)?;
                self.end_reception(last);
                put(self.read_dr());
                put(self.read_dr());
                self.i2c.cr1().modify(|_, w| w.pos().clear_bit());
            }
            _ => {
                self.i2c.cr1().modify(|_, w| w.ack().set_bit());
                self.address(address, true, start_requested)?;
                self.clear_addr();
                for _ in 0..len - 3 {
                    self.wait(RXNE, Stage::Receive)?;
                    put(self.read_dr());
                }
                // Byte N−2 in DR, N−1 in the shift register: NACK the last one.
                self.wait(BTF, Stage::Receive)?;
                self.i2c.cr1().modify(|_, w| w.ack().clear_bit());
                put(self.read_dr());
                self.wait(BTF, Stage::Receive)?;
                self.end_reception(last);
                put(self.read_dr());
                put(self.read_dr());
            }
        }
        Ok(())
    }

    /// After a failure: STOP frees the bus; if it stays busy (a chip holding
    /// SDA low, a glitch), a software reset (CR1 SWRST, §18.6.1) restarts the
    /// peripheral with its timing set again.
    fn recover(&self) {
        self.stop();
        let free = (0..POLL_LIMIT).any(|_| self.i2c.sr2().read().busy().bit_is_clear());
        self.i2c
            .cr1()
            .modify(|_, w| w.ack().clear_bit().pos().clear_bit());
        if !free {
            self.i2c.cr1().write(|w| w.swrst().set_bit());
            self.i2c.cr1().write(|w| w.swrst().clear_bit());
            self.configure();
        }
    }

    /// Waits for a free bus before a START (a previous STOP still on the wire).
    fn wait_bus_free(&self) -> Result<(), I2cError> {
        if (0..POLL_LIMIT).any(|_| self.i2c.sr2().read().busy().bit_is_clear()) {
            Ok(())
        } else {
            Err(I2cError {
                kind: ErrorKind::Bus,
                stage: Stage::BusFree,
                sr1: self.sr1(),
            })
        }
    }

    /// The embedded-hal transaction contract: adjacent operations of one kind
    /// are one transfer, a change of direction is a repeated START, the end a STOP.
    fn run(&self, address: u8, operations: &mut [Operation<'_>]) -> Result<(), I2cError> {
        self.wait_bus_free()?;
        let mut rest = operations;
        // A reception that is not the last asks for the next START itself.
        let mut start_requested = false;
        while !rest.is_empty() {
            let reading = matches!(rest[0], Operation::Read(_));
            let run_len = rest
                .iter()
                .take_while(|op| matches!(op, Operation::Read(_)) == reading)
                .count();
            let (group, tail) = rest.split_at_mut(run_len);
            let last = tail.is_empty();
            if reading {
                let len = group.iter().map(operation_len).sum();
                let slots = group.iter_mut().flat_map(|op| match op {
                    Operation::Read(buffer) => buffer.iter_mut(),
                    Operation::Write(_) => Default::default(),
                });
                self.read_bytes(address, len, slots, last, start_requested)?;
                start_requested = !last;
            } else {
                let bytes = group.iter().flat_map(|op| match op {
                    Operation::Write(bytes) => bytes.iter(),
                    Operation::Read(_) => Default::default(),
                });
                self.write_bytes(address, bytes, start_requested)?;
                start_requested = false;
                if last {
                    self.stop();
                }
            }
            rest = tail;
        }
        Ok(())
    }
}

fn operation_len(op: &Operation<'_>) -> usize {
    match op {
        Operation::Read(buffer) => buffer.len(),
        Operation::Write(bytes) => bytes.len(),
    }
}

impl ErrorType for I2c1 {
    type Error = I2cError;
}

impl I2c<SevenBitAddress> for I2c1 {
    fn transaction(
        &mut self,
        address: SevenBitAddress,
        operations: &mut [Operation<'_>],
    ) -> Result<(), I2cError> {
        if address > 0x7F {
            // Refused before touching the bus: nothing to recover.
            return Err(I2cError {
                kind: ErrorKind::Other,
                stage: Stage::InvalidAddress(address),
                sr1: self.sr1(),
            });
        }
        let result = self.run(address, operations);
        if result.is_err() {
            self.recover();
        }
        result
    }
}
