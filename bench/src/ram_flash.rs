//! NOR flash in RAM for the command-handling rows: it behaves as NOR flash
//! (programming only clears bits, erasing sets a whole unit to 0xFF) and
//! counts what it is asked to do, so that the benchmark reports the
//! operations a command costs (and the erases that wear a sector) instead of
//! timing a flash it does not have.
//!
//! Two erase units: one per slot of the calibration store, as on the NUCLEO
//! (a 128 KiB sector per slot), each one record long so that the Cortex-M0
//! core's 16 KiB of RAM hold the flash beside the command handler's stack.
//! Byte writes, as the NUCLEO's flash (`WRITE_SIZE` 1).

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Bytes per erase unit: one store slot, one record.
pub const ERASE_SIZE: usize = triad::device::storage::RECORD_LEN;
/// Erase units: the store's two slots.
pub const UNITS: usize = 2;
/// Bytes of flash.
pub const CAPACITY: usize = UNITS * ERASE_SIZE;

/// What the flash was asked to do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlashOps {
    /// Erase units erased.
    pub erases: u32,
    /// Write calls.
    pub writes: u32,
    /// Bytes programmed.
    pub bytes_written: u32,
    /// Read calls.
    pub reads: u32,
    /// Bytes read.
    pub bytes_read: u32,
}

impl FlashOps {
    /// The operations done since `earlier` was taken.
    pub fn since(&self, earlier: &FlashOps) -> FlashOps {
        FlashOps {
            erases: self.erases - earlier.erases,
            writes: self.writes - earlier.writes,
            bytes_written: self.bytes_written - earlier.bytes_written,
            reads: self.reads - earlier.reads,
            bytes_read: self.bytes_read - earlier.bytes_read,
        }
    }

    /// These operations and `more`.
    pub fn plus(&self, more: &FlashOps) -> FlashOps {
        FlashOps {
            erases: self.erases + more.erases,
            writes: self.writes + more.writes,
            bytes_written: self.bytes_written + more.bytes_written,
            reads: self.reads + more.reads,
            bytes_read: self.bytes_read + more.bytes_read,
        }
    }
}

/// An access outside the flash or not on an erase-unit boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RamFlashError {
    /// Past the end of the flash.
    OutOfBounds,
    /// An erase not from and to unit boundaries.
    NotAligned,
}

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            RamFlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            RamFlashError::NotAligned => NorFlashErrorKind::NotAligned,
        }
    }
}

/// NOR flash in RAM, erased, counting its operations.
#[derive(Clone, Debug)]
pub struct RamFlash {
    memory: [u8; CAPACITY],
    ops: FlashOps,
    unit_erases: [u32; UNITS],
}

impl Default for RamFlash {
    fn default() -> Self {
        Self::new()
    }
}

impl RamFlash {
    /// Erased flash, nothing counted.
    pub const fn new() -> Self {
        RamFlash {
            memory: [0xFF; CAPACITY],
            ops: FlashOps {
                erases: 0,
                writes: 0,
                bytes_written: 0,
                reads: 0,
                bytes_read: 0,
            },
            unit_erases: [0; UNITS],
        }
    }

    /// The operations so far.
    pub fn ops(&self) -> FlashOps {
        self.ops
    }

    /// Erases of each unit so far (what wears it).
    pub fn unit_erases(&self) -> [u32; UNITS] {
        self.unit_erases
    }

    fn range(&self, offset: u32, len: usize) -> Result<core::ops::Range<usize>, RamFlashError> {
        let start = offset as usize;
        match start.checked_add(len) {
            Some(end) if end <= CAPACITY => Ok(start..end),
            _ => Err(RamFlashError::OutOfBounds),
        }
    }
}

impl ErrorType for RamFlash {
    type Error = RamFlashError;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), RamFlashError> {
        let range = self.range(offset, bytes.len())?;
        bytes.copy_from_slice(&self.memory[range]);
        self.ops.reads += 1;
        self.ops.bytes_read += bytes.len() as u32;
        Ok(())
    }

    fn capacity(&self) -> usize {
        CAPACITY
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 1;
    const ERASE_SIZE: usize = ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), RamFlashError> {
        if !(from as usize).is_multiple_of(ERASE_SIZE)
            || !(to as usize).is_multiple_of(ERASE_SIZE)
            || to < from
        {
            return Err(RamFlashError::NotAligned);
        }
        let range = self.range(from, (to - from) as usize)?;
        for unit in range.clone().step_by(ERASE_SIZE) {
            self.unit_erases[unit / ERASE_SIZE] += 1;
            self.ops.erases += 1;
        }
        self.memory[range].fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), RamFlashError> {
        let range = self.range(offset, bytes.len())?;
        for (cell, &value) in self.memory[range].iter_mut().zip(bytes) {
            // Programming only clears bits.
            *cell &= value;
        }
        self.ops.writes += 1;
        self.ops.bytes_written += bytes.len() as u32;
        Ok(())
    }
}
