//! The emulated board's calibration flash: a file on the host, reached by
//! semihosting, so a calibration saved in one QEMU run is there in the next.
//!
//! `cargo xtask serve --storage FILE` (or `run`) creates the file (all 0xFF,
//! [`CAPACITY`] bytes) when it does not exist and names it on QEMU's
//! semihosting command line as `triad storage=PATH`; without it the board has
//! no storage. The file behaves as NOR flash: a write may only clear bits
//! (the model ANDs, so a store that programs a byte twice finds what real
//! flash would hold), an erase sets a whole 16 KiB unit (the STM32F4's small
//! sector) to 0xFF.
//!
//! For the power-cut test, `cut-after=N` on the command line ends the run
//! (QEMU exits, as if the power went) at the N-th write or erase operation,
//! before it is performed.

use cortex_m_semihosting::{debug, nr, syscall};
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Bytes of emulated flash: two 16 KiB slots.
pub const CAPACITY: usize = 2 * ERASE_SIZE;
/// The erase unit.
const ERASE_SIZE: usize = 16 * 1024;

/// What went wrong talking to the host's file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum FileError {
    /// An offset or length outside the flash.
    OutOfBounds,
    /// A write or erase not aligned to its unit.
    NotAligned,
    /// The host's seek, read or write failed.
    Host,
}

impl NorFlashError for FileError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FileError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            FileError::NotAligned => NorFlashErrorKind::NotAligned,
            FileError::Host => NorFlashErrorKind::Other,
        }
    }
}

/// Why the board has no storage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Unavailable {
    /// QEMU's semihosting command line names no `storage=` file.
    NotConfigured,
    /// The file named could not be opened (it must exist: xtask creates it).
    Open,
    /// The file is not [`CAPACITY`] bytes long.
    Length(usize),
}

/// The host file as NOR flash.
pub struct SemihostingFlash {
    handle: usize,
    /// Operations left before the simulated power cut (`None`: no cut).
    cut_after: Option<u32>,
}

/// Bytes of the semihosting command line the board reads.
pub(crate) const COMMAND_LINE_MAX: usize = 512;

/// The semihosting command line (`triad [fault=SPEC ...] storage=PATH
/// [cut-after=N]`) in `buf`.
pub(crate) fn command_line(buf: &mut [u8; COMMAND_LINE_MAX]) -> Option<&str> {
    // SYS_GET_CMDLINE takes a block {buffer, length} and writes the length back.
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: the block points at `buf`, which outlives the call.
    let failed =
        unsafe { cortex_m_semihosting::syscall1(nr::GET_CMDLINE, block.as_mut_ptr() as usize) };
    if failed != 0 {
        return None;
    }
    let len = block[1].min(buf.len());
    core::str::from_utf8(&buf[..len]).ok()
}

impl SemihostingFlash {
    /// Opens the file the command line names.
    pub fn open() -> Result<Self, Unavailable> {
        let mut buf = [0u8; COMMAND_LINE_MAX];
        let line = command_line(&mut buf).ok_or(Unavailable::NotConfigured)?;
        let mut path = None;
        let mut cut_after = None;
        // The path is everything after `storage=` up to ` cut-after=` or the
        // end, so it may hold spaces.
        if let Some((_, rest)) = line.split_once("storage=") {
            let (file, cut) = match rest.split_once(" cut-after=") {
                Some((file, cut)) => (file, cut.trim().parse::<u32>().ok()),
                None => (rest.trim_end(), None),
            };
            path = Some(file);
            cut_after = cut;
        }
        let path = path.ok_or(Unavailable::NotConfigured)?;
        let mut zpath = [0u8; COMMAND_LINE_MAX + 1];
        zpath[..path.len()].copy_from_slice(path.as_bytes());
        // SAFETY: a NUL-terminated path in a live buffer; mode "r+b".
        let handle = unsafe { syscall!(OPEN, zpath.as_ptr(), nr::open::RW_BINARY, path.len()) };
        if handle == usize::MAX {
            return Err(Unavailable::Open);
        }
        // SAFETY: a handle the host just returned.
        let len = unsafe { syscall!(FLEN, handle) };
        if len != CAPACITY {
            return Err(Unavailable::Length(len));
        }
        Ok(Self { handle, cut_after })
    }

    /// One write or erase is about to happen: the power cut, if armed, is now.
    fn operation(&mut self) {
        match &mut self.cut_after {
            Some(0) => {
                defmt::warn!("storage: simulated power cut");
                debug::exit(debug::EXIT_FAILURE);
            }
            Some(left) => *left -= 1,
            None => {}
        }
    }

    fn seek(&self, offset: u32) -> Result<(), FileError> {
        // SAFETY: seek on our handle.
        match unsafe { syscall!(SEEK, self.handle, offset) } {
            0 => Ok(()),
            _ => Err(FileError::Host),
        }
    }

    fn check(offset: u32, len: usize) -> Result<(), FileError> {
        match (offset as usize).checked_add(len) {
            Some(end) if end <= CAPACITY => Ok(()),
            _ => Err(FileError::OutOfBounds),
        }
    }

    fn write_file(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FileError> {
        self.seek(offset)?;
        // SAFETY: the host reads `bytes` during the call; returns bytes not written.
        match unsafe { syscall!(WRITE, self.handle, bytes.as_ptr(), bytes.len()) } {
            0 => Ok(()),
            _ => Err(FileError::Host),
        }
    }
}

impl ErrorType for SemihostingFlash {
    type Error = FileError;
}

impl ReadNorFlash for SemihostingFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FileError> {
        Self::check(offset, bytes.len())?;
        self.seek(offset)?;
        // SAFETY: the host fills `bytes`; returns bytes not read.
        match unsafe { syscall!(READ, self.handle, bytes.as_mut_ptr(), bytes.len()) } {
            0 => Ok(()),
            _ => Err(FileError::Host),
        }
    }

    fn capacity(&self) -> usize {
        CAPACITY
    }
}

impl NorFlash for SemihostingFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FileError> {
        if !(from as usize).is_multiple_of(ERASE_SIZE)
            || !(to as usize).is_multiple_of(ERASE_SIZE)
            || to < from
        {
            return Err(FileError::NotAligned);
        }
        Self::check(from, (to - from) as usize)?;
        let erased = [0xFFu8; 1024];
        for unit in (from..to).step_by(ERASE_SIZE) {
            self.operation();
            for at in (unit..unit + ERASE_SIZE as u32).step_by(erased.len()) {
                self.write_file(at, &erased)?;
            }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FileError> {
        if !(offset as usize).is_multiple_of(Self::WRITE_SIZE)
            || !bytes.len().is_multiple_of(Self::WRITE_SIZE)
        {
            return Err(FileError::NotAligned);
        }
        Self::check(offset, bytes.len())?;
        // Programming only clears bits: AND with what is there, a unit of
        // 64 bytes at a time.
        let mut at = 0;
        while at < bytes.len() {
            self.operation();
            let n = (bytes.len() - at).min(64);
            let mut cell = [0u8; 64];
            self.read(offset + at as u32, &mut cell[..n])?;
            for (c, b) in cell[..n].iter_mut().zip(&bytes[at..at + n]) {
                *c &= b;
            }
            self.write_file(offset + at as u32, &cell[..n])?;
            at += n;
        }
        Ok(())
    }
}
