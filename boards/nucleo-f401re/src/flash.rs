//! The calibration's flash: the STM32F401RE's own, of which only sectors 6
//! and 7 (0x0804_0000–0x0807_FFFF, 128 KiB each; RM0368, "Flash module
//! organization", STM32F401xD/E) may be written or erased. memory.x keeps
//! the program out of them.
//!
//! Offsets are from the flash's base, 0x0800_0000, as the HAL's. What the
//! HAL does here: reads (its memory-mapped view), writes (its
//! `UnlockedFlash`'s embedded-storage `NorFlash::write`, unlocked for the
//! one operation, byte programming), the unlock and lock around a write,
//! the flash's size, and which sector an offset is in (`FlashExt::sector`).
//!
//! What is done here, and why the HAL's own does not serve:
//! - The sector erase (`erase_sector`), with x32 parallelism. The HAL's
//!   `UnlockedFlash::erase` writes PSIZE = x8 in the same register write
//!   as STRT, and nothing lets a caller choose: at x8 a 128 KiB sector
//!   takes twice as long, so sampling would stop twice as long on every
//!   save (data sheet DS10086, "Flash memory programming", tERASE128KB:
//!   typ 2 s, max 4 s at x8; typ 1 s, max 2 s at x32). x32 needs VDD
//!   2.7–3.6 V (RM0368, "Program/erase parallelism"): the NUCLEO runs the
//!   MCU at 3.3 V. (Writes stay the HAL's, x8: a 528-byte record is 8.4 ms
//!   typ, next to the erase's second.)
//! - Bounds: the HAL's `NorFlash` erases every sector `from..to` touches,
//!   the program's included, and its read indexes out of range (a panic);
//!   here writes and erases stay in sectors 6 and 7 and reads in the flash,
//!   or fail with [`FlashError::OutOfBounds`].
//! - Stale error flags: the HAL reads FLASH_SR's error flags after an
//!   operation and never clears them, so one failure would fail every
//!   later operation; they are cleared before each (`clear_errors`).
//! - The data cache, which may hold what a sector held before (ST's C HAL
//!   flushes it after an erase; this HAL does not): `flush_data_cache`.
//!
//! The flash has one bank: while it erases or programs, every fetch from it
//! (the CPU's instructions, the vector table) stalls until the operation ends
//! (RM0368, "Erase and program operations"), so the firmware stops for the
//! whole of it; the DMA into SRAM goes on.

use core::sync::atomic::{AtomicU32, Ordering};
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use stm32f4xx_hal::flash::{self as hal_flash, FlashExt as _};

use crate::pac;

/// A sector of the calibration (128 KiB).
const SECTOR_LEN: u32 = 128 * 1024;
/// Sector 6's offset from the flash's base (0x0804_0000).
const SECTOR_6: u32 = 0x4_0000;
/// Where the calibration's sectors end: the end of the 512 KiB flash.
const STORAGE_END: u32 = SECTOR_6 + 2 * SECTOR_LEN;

/// Where the two calibration slots are in [`Flash`]: sector 6, then
/// sector 7, one slot each.
pub const STORAGE_SLOTS: (u32, u32) = (SECTOR_6, SECTOR_LEN);

/// Erases and writes so far, wrapping: each stalls the CPU
/// ([`crate::Board`]'s `flash_stalls`).
static STALLS: AtomicU32 = AtomicU32::new(0);

/// Erases and writes so far (wrapping), each of which stalled the CPU.
pub fn stalls() -> u32 {
    STALLS.load(Ordering::Relaxed)
}

/// Runs the flash operation `f`, counted as a stall first, with interrupts
/// masked: the CPU cannot run them during the operation anyway (their code
/// is in the bank being erased or programmed), and masked, none runs
/// between the count and the stall, so the first to run after sees the
/// count changed and its frame says FLASH_STALL.
fn stalling<T>(f: impl FnOnce() -> T) -> T {
    cortex_m::interrupt::free(|_| {
        STALLS.store(
            STALLS.load(Ordering::Relaxed).wrapping_add(1),
            Ordering::Relaxed,
        );
        f()
    })
}

/// FLASH_KEYR's unlock sequence (RM0368, "Unlocking the flash control
/// register").
const KEYS: [u32; 2] = [0x4567_0123, 0xCDEF_89AB];

/// What went wrong with a flash operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// A read outside the flash, or a write or erase outside sectors 6 and 7.
    OutOfBounds,
    /// An erase not from and to sector boundaries.
    NotAligned,
    /// FLASH_CR stayed locked after the unlock sequence (a wrong key was
    /// written since reset: it stays locked until the next).
    Locked,
    /// FLASH_SR's PGSERR: the sequence of operations was wrong.
    Sequence,
    /// FLASH_SR's PGPERR: the access size did not match PSIZE.
    Parallelism,
    /// FLASH_SR's PGAERR: a write crossed a 128-bit row.
    Alignment,
    /// FLASH_SR's WRPERR: the sector is write-protected (option bytes).
    WriteProtected,
    /// FLASH_SR's OPERR: the operation failed.
    Operation,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            FlashError::NotAligned | FlashError::Alignment => NorFlashErrorKind::NotAligned,
            _ => NorFlashErrorKind::Other,
        }
    }
}

impl From<hal_flash::Error> for FlashError {
    fn from(error: hal_flash::Error) -> Self {
        match error {
            hal_flash::Error::ProgrammingSequence => FlashError::Sequence,
            hal_flash::Error::ProgrammingParallelism => FlashError::Parallelism,
            hal_flash::Error::ProgrammingAlignment => FlashError::Alignment,
            hal_flash::Error::WriteProtection => FlashError::WriteProtected,
            hal_flash::Error::Operation => FlashError::Operation,
        }
    }
}

/// Why the board has no calibration flash: never, on this board.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum StorageUnavailable {}

/// The MCU's flash as `embedded-storage` NOR flash, writable in sectors 6
/// and 7 only.
pub struct Flash(pac::FLASH);

impl Flash {
    /// The flash, locked (as after reset) until an operation unlocks it.
    pub(crate) fn new(flash: pac::FLASH) -> Self {
        Self(flash)
    }

    /// `len` bytes from `offset` lie within sectors 6 and 7.
    fn check_writable(offset: u32, len: usize) -> Result<(), FlashError> {
        let end = u64::from(offset) + len as u64;
        if offset < SECTOR_6 || end > u64::from(STORAGE_END) {
            return Err(FlashError::OutOfBounds);
        }
        Ok(())
    }

    fn wait_idle(&self) {
        while self.0.sr().read().bsy().bit_is_set() {}
    }

    /// Clears FLASH_SR's error flags (write 1 to clear), left by an earlier
    /// failure: the HAL reads them after an operation without clearing
    /// them, so one stale flag would fail every later write.
    fn clear_errors(&self) {
        self.0.sr().write(|w| {
            w.pgserr().clear();
            w.pgperr().clear();
            w.pgaerr().clear();
            w.wrperr().clear();
            w.operr().clear()
        });
    }

    /// The error FLASH_SR reports for the operation just ended, if any.
    fn status(&self) -> Result<(), FlashError> {
        let sr = self.0.sr().read();
        if sr.pgserr().bit_is_set() {
            Err(FlashError::Sequence)
        } else if sr.pgperr().bit_is_set() {
            Err(FlashError::Parallelism)
        } else if sr.pgaerr().bit_is_set() {
            Err(FlashError::Alignment)
        } else if sr.wrperr().bit_is_set() {
            Err(FlashError::WriteProtected)
        } else if sr.operr().bit_is_set() {
            Err(FlashError::Operation)
        } else {
            Ok(())
        }
    }

    /// Erases sector `number` with x32 parallelism (RM0368, "Sector erase": unlock,
    /// SER and SNB, then STRT; wait for BSY to clear), then locks again.
    /// The unlock is written here too: the HAL's `unlocked()` holds FLASH
    /// borrowed while unlocked, so CR could not be written beside it.
    fn erase_sector(&mut self, number: u8) -> Result<(), FlashError> {
        let flash = &self.0;
        self.wait_idle();
        self.clear_errors();
        for key in KEYS {
            flash.keyr().write(|w| w.key().set(key));
        }
        if flash.cr().read().lock().bit_is_set() {
            return Err(FlashError::Locked);
        }
        flash.cr().modify(|_, w| {
            w.pg().clear_bit();
            w.psize().psize32();
            w.ser().set_bit();
            // SAFETY: SNB takes sector numbers 0-7 on this device (RM0368,
            // FLASH_CR); callers pass 6 or 7.
            unsafe { w.snb().bits(number) }
        });
        flash.cr().modify(|_, w| w.strt().set_bit());
        self.wait_idle();
        let result = self.status();
        flash.cr().modify(|_, w| w.ser().clear_bit());
        flash.cr().modify(|_, w| w.lock().set_bit());
        result
    }

    /// Empties the flash's data cache, which may hold lines of what a
    /// sector held before it was erased or written (ST's HAL does this after
    /// an erase). DCRST works only with the cache off (RM0368, FLASH_ACR).
    fn flush_data_cache(&self) {
        let acr = self.0.acr();
        let enabled = acr.read().dcen().bit_is_set();
        acr.modify(|_, w| w.dcen().clear_bit());
        acr.modify(|_, w| w.dcrst().set_bit());
        acr.modify(|_, w| w.dcrst().clear_bit());
        acr.modify(|_, w| w.dcen().bit(enabled));
    }
}

impl ErrorType for Flash {
    type Error = FlashError;
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        let start = offset as usize;
        let source = start
            .checked_add(bytes.len())
            .and_then(|end| self.0.read().get(start..end))
            .ok_or(FlashError::OutOfBounds)?;
        bytes.copy_from_slice(source);
        Ok(())
    }

    /// The whole flash (512 KiB, from the device's flash-size register).
    fn capacity(&self) -> usize {
        self.0.len()
    }
}

impl NorFlash for Flash {
    /// The HAL programs a byte at a time.
    const WRITE_SIZE: usize = 1;
    /// Sectors 6 and 7 are 128 KiB each.
    const ERASE_SIZE: usize = SECTOR_LEN as usize;

    /// Erases the sectors in `from..to`: both on sector boundaries within
    /// sectors 6 and 7. Each takes 1–2 s, the firmware stopped.
    fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        if from > to {
            return Err(FlashError::NotAligned);
        }
        Self::check_writable(from, (to - from) as usize)?;
        if !from.is_multiple_of(SECTOR_LEN) || !to.is_multiple_of(SECTOR_LEN) {
            return Err(FlashError::NotAligned);
        }
        let mut result = Ok(());
        for offset in (from..to).step_by(SECTOR_LEN as usize) {
            // The HAL's map of the sectors: 6 at 0x4_0000, 7 at 0x6_0000.
            let number = match self.0.sector(offset as usize) {
                Some(sector) if sector.offset == offset as usize => sector.number,
                _ => {
                    result = Err(FlashError::NotAligned);
                    break;
                }
            };
            result = stalling(|| self.erase_sector(number));
            if result.is_err() {
                break;
            }
        }
        self.flush_data_cache();
        result
    }

    /// Programs `bytes` at `offset`, within sectors 6 and 7 (the HAL does not
    /// check where it writes): about 16 µs a byte (DS10086's word
    /// programming time, typ 16 µs, max 100 µs), 8.4 ms for a 528-byte
    /// record, the firmware stopped.
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        Self::check_writable(offset, bytes.len())?;
        self.wait_idle();
        self.clear_errors();
        // Unlocked for this write only: the HAL locks again on drop. (Its
        // unlock asserts that the flash opened; it stays shut only after a
        // wrong key, and only the right keys are ever written, here and by
        // the HAL.)
        let result = stalling(|| NorFlash::write(&mut self.0.unlocked(), offset, bytes));
        self.flush_data_cache();
        result.map_err(FlashError::from)
    }
}
