//! NOR flash in RAM that can lose power at any write unit or erase: the
//! calibration store's tests and the command handler's share it.
#![allow(dead_code)]

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

pub const ERASE_SIZE: usize = 1024;
pub const WRITE_SIZE: usize = 4;
pub const CAPACITY: usize = 4 * ERASE_SIZE;
pub const BASE: u32 = ERASE_SIZE as u32;
pub const SLOT_LEN: u32 = ERASE_SIZE as u32;

/// The power went: every operation from the cut on fails.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLost;

impl NorFlashError for PowerLost {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

/// NOR flash in RAM: programming only clears bits, erasing sets a whole
/// unit to 0xFF. With a cut armed at operation k (a write unit or an erase
/// unit), operation k is left half done and every later one fails.
pub struct RamFlash {
    pub memory: Vec<u8>,
    /// With `Some(k)`: k − 1 more operations complete, the k-th is left half
    /// done, the rest fail (k = 0: nothing more happens); `None`: no cut.
    pub cut_after: Option<usize>,
    /// Operations performed (to size the sweep).
    pub operations: usize,
    /// A fixed pattern for half-done operations (varied per case).
    pub noise: u32,
}

impl RamFlash {
    pub fn new() -> Self {
        Self {
            memory: vec![0xFF; CAPACITY],
            cut_after: None,
            operations: 0,
            noise: 0x9E37_79B9,
        }
    }

    /// One operation: true if it may complete, false if the cut happens in it.
    fn step(&mut self) -> Result<bool, PowerLost> {
        self.operations += 1;
        match self.cut_after {
            Some(0) => Err(PowerLost),
            Some(ref mut left) => {
                *left -= 1;
                Ok(*left > 0)
            }
            None => Ok(true),
        }
    }

    fn noise_byte(&mut self) -> u8 {
        // xorshift32: a different half-done state at each byte.
        self.noise ^= self.noise << 13;
        self.noise ^= self.noise >> 17;
        self.noise ^= self.noise << 5;
        self.noise as u8
    }

    /// The device restarts: power is back, no cut armed.
    pub fn power_up(&mut self) {
        self.cut_after = None;
    }
}

impl ErrorType for RamFlash {
    type Error = PowerLost;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), PowerLost> {
        if self.cut_after == Some(0) {
            return Err(PowerLost);
        }
        let at = offset as usize;
        bytes.copy_from_slice(&self.memory[at..at + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        CAPACITY
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = WRITE_SIZE;
    const ERASE_SIZE: usize = ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), PowerLost> {
        assert_eq!(from as usize % ERASE_SIZE, 0, "erase aligned");
        assert_eq!(to as usize % ERASE_SIZE, 0, "erase aligned");
        for unit in (from as usize..to as usize).step_by(ERASE_SIZE) {
            let completes = self.step()?;
            for i in unit..unit + ERASE_SIZE {
                // A cut erase leaves some bytes erased, others as they were.
                if completes || self.noise_byte() & 1 == 0 {
                    self.memory[i] = 0xFF;
                }
            }
            if !completes {
                self.cut_after = Some(0);
                return Err(PowerLost);
            }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), PowerLost> {
        assert_eq!(offset as usize % WRITE_SIZE, 0, "write aligned");
        assert_eq!(bytes.len() % WRITE_SIZE, 0, "write whole units");
        for (n, unit) in bytes.chunks(WRITE_SIZE).enumerate() {
            let completes = self.step()?;
            let at = offset as usize + n * WRITE_SIZE;
            for (i, &value) in unit.iter().enumerate() {
                // Programming clears bits; a cut one clears only some of them.
                let value = if completes {
                    value
                } else {
                    value | self.noise_byte()
                };
                self.memory[at + i] &= value;
            }
            if !completes {
                self.cut_after = Some(0);
                return Err(PowerLost);
            }
        }
        Ok(())
    }
}
