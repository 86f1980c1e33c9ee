//! NOR flash in RAM that the fake device and the test share: programming
//! only clears bits, erasing sets a unit to 0xFF (tests/device_storage.rs
//! has the model with power cuts; here the power stays on).

use std::sync::{Arc, Mutex};

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use triad::device::CalibrationStore;
use triad::model::blob::BLOB_LEN;

const ERASE_SIZE: usize = 1024;
const CAPACITY: usize = 2 * ERASE_SIZE;

/// An access outside the flash or not aligned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Misuse;

impl NorFlashError for Misuse {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::OutOfBounds
    }
}

/// A handle on the shared memory.
#[derive(Clone)]
pub struct RamFlash {
    memory: Arc<Mutex<Vec<u8>>>,
}

impl RamFlash {
    /// Erased flash.
    pub fn new() -> Self {
        Self {
            memory: Arc::new(Mutex::new(vec![0xFF; CAPACITY])),
        }
    }

    /// The store over this flash, as the fake device lays it out.
    pub fn store(&self) -> CalibrationStore<RamFlash> {
        CalibrationStore::new(self.clone(), 0, ERASE_SIZE as u32).expect("the layout fits")
    }

    /// The blob a restarted device would load, if any.
    pub fn stored_blob(&self) -> Option<[u8; BLOB_LEN]> {
        let mut blob = [0u8; BLOB_LEN];
        let loaded = self.store().load(&mut blob).expect("RAM reads");
        loaded.record.map(|_| blob)
    }

    fn range(&self, offset: u32, len: usize) -> Result<std::ops::Range<usize>, Misuse> {
        let at = offset as usize;
        (at + len <= CAPACITY).then_some(at..at + len).ok_or(Misuse)
    }
}

impl ErrorType for RamFlash {
    type Error = Misuse;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Misuse> {
        let range = self.range(offset, bytes.len())?;
        bytes.copy_from_slice(&self.memory.lock().unwrap()[range]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        CAPACITY
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Misuse> {
        if !(from as usize).is_multiple_of(ERASE_SIZE)
            || !(to as usize).is_multiple_of(ERASE_SIZE)
            || to < from
        {
            return Err(Misuse);
        }
        let range = self.range(from, (to - from) as usize)?;
        self.memory.lock().unwrap()[range].fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Misuse> {
        if !(offset as usize).is_multiple_of(Self::WRITE_SIZE)
            || !bytes.len().is_multiple_of(Self::WRITE_SIZE)
        {
            return Err(Misuse);
        }
        let range = self.range(offset, bytes.len())?;
        let mut memory = self.memory.lock().unwrap();
        for (cell, value) in memory[range].iter_mut().zip(bytes) {
            *cell &= value;
        }
        Ok(())
    }
}
