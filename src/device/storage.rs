//! The calibration the device keeps in flash, safe against a power cut at any
//! point: an A/B pair of erase units ("slots"), each holding at most one
//! record, over any `embedded-storage` [`NorFlash`].
//!
//! Why A/B and not a log (`sequential-storage`): the device keeps one value of
//! fixed size (a [`BLOB_LEN`]-byte calibration blob), so two slots are the
//! whole design; a save is one erase and two writes, a power-cut argument fits
//! in this comment, and nothing is async.
//!
//! A record is a 16-byte header and the blob:
//!
//! | offset | size | content                                                  |
//! |-------:|-----:|----------------------------------------------------------|
//! |      0 |    4 | magic `TRST`                                              |
//! |      4 |    4 | generation, u32 LE: one more than the newest it replaces |
//! |      8 |    4 | blob length, u32 LE ([`BLOB_LEN`])                        |
//! |     12 |    4 | CRC-32C of bytes 4..12 and of the blob, u32 LE            |
//! |     16 |  512 | the calibration blob                                      |
//!
//! A save erases the slot that does not hold the newest valid record, writes
//! the blob, then the header. The header's CRC covers the blob, so whatever
//! a cut leaves in that slot (half erased, part of the blob, part of the
//! header) fails the check, and the other slot, never touched, still holds
//! the previous record, which [`CalibrationStore::load`] returns. Only a
//! complete header over a complete blob makes the new record, and its higher
//! generation makes it win. (Header last is not needed for that, given the
//! CRC; it keeps a cut slot recognisably incomplete: no magic.)
//! [`CalibrationStore::erase`] erases the older slot first, so a cut leaves
//! the newest record (as if nothing happened) or none, never an older one.
//! Each save erases one slot: each slot is erased once per two saves.

use embedded_storage::nor_flash::NorFlash;

use crate::model::blob::BLOB_LEN;
use crate::protocol::crc32c::crc32c_update;

/// The record's magic.
const MAGIC: [u8; 4] = *b"TRST";
/// Header bytes before the blob.
const HEADER_LEN: usize = 16;
/// A record: header and blob.
pub const RECORD_LEN: usize = HEADER_LEN + BLOB_LEN;
/// The largest write granularity the store handles (the tail of a record is
/// padded to the flash's `WRITE_SIZE` in a buffer this long).
const MAX_WRITE_SIZE: usize = 16;

/// What can go wrong with the store.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StorageError<E> {
    /// The flash driver failed.
    Flash(E),
    /// The slots do not fit the flash: what is wrong, with the value.
    Layout {
        /// Which requirement failed.
        what: &'static str,
        /// The offending value.
        value: u32,
    },
}

/// A record found in a slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stored {
    /// The record's generation (higher is newer).
    pub generation: u32,
    /// The slot it is in (0 or 1).
    pub slot: u8,
}

/// What [`CalibrationStore::load`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Loaded {
    /// The newest valid record, whose blob was copied out; `None`: none.
    pub record: Option<Stored>,
    /// Slots holding something that is not a valid record (a cut save, worn
    /// or foreign data): reported, never used. Bit n: slot n.
    pub damaged_slots: u8,
}

/// The record's CRC-32C over the header's generation and length, then the blob.
fn record_crc(fields: &[u8], blob: &[u8]) -> u32 {
    !crc32c_update(crc32c_update(!0, fields), blob)
}

/// Two slots of one erase unit each (or more), at `base` and `base + slot_len`.
#[derive(Debug)]
pub struct CalibrationStore<F> {
    flash: F,
    base: u32,
    slot_len: u32,
}

/// The state of one slot.
enum Slot {
    /// Erased (all 0xFF header): nothing stored.
    Empty,
    /// A valid record of this generation.
    Valid(u32),
    /// Anything else.
    Damaged,
}

impl<F: NorFlash> CalibrationStore<F> {
    /// The store over `flash`, its two slots from `base`, each `slot_len`
    /// bytes: both multiples of the flash's erase size, the record fitting
    /// in a slot and the two slots in the flash.
    pub fn new(flash: F, base: u32, slot_len: u32) -> Result<Self, StorageError<F::Error>> {
        let layout = |what, value| Err(StorageError::Layout { what, value });
        let erase = F::ERASE_SIZE as u32;
        if !base.is_multiple_of(erase) {
            return layout("slot base must be a multiple of the erase size", base);
        }
        if slot_len == 0 || !slot_len.is_multiple_of(erase) {
            return layout("slot length must be a multiple of the erase size", slot_len);
        }
        if (slot_len as usize) < RECORD_LEN {
            return layout("slot length must hold a record (528 bytes)", slot_len);
        }
        let end = u64::from(base) + 2 * u64::from(slot_len);
        if end > flash.capacity() as u64 {
            return layout("the two slots must fit in the flash", end as u32);
        }
        if F::WRITE_SIZE > MAX_WRITE_SIZE || !HEADER_LEN.is_multiple_of(F::WRITE_SIZE) {
            return layout("flash write size must divide 16", F::WRITE_SIZE as u32);
        }
        Ok(Self {
            flash,
            base,
            slot_len,
        })
    }

    /// The flash (to inspect it, or arm a fault in a test's flash).
    pub fn flash_mut(&mut self) -> &mut F {
        &mut self.flash
    }

    /// Gives the flash back.
    pub fn release(self) -> F {
        self.flash
    }

    fn slot_offset(&self, slot: u8) -> u32 {
        self.base + u32::from(slot) * self.slot_len
    }

    /// Reads slot `slot`'s record into `blob` and says what it holds.
    fn read_slot(
        &mut self,
        slot: u8,
        blob: &mut [u8; BLOB_LEN],
    ) -> Result<Slot, StorageError<F::Error>> {
        let offset = self.slot_offset(slot);
        let mut header = [0u8; HEADER_LEN];
        self.flash
            .read(offset, &mut header)
            .map_err(StorageError::Flash)?;
        if header.iter().all(|&b| b == 0xFF) {
            return Ok(Slot::Empty);
        }
        let word = |at: usize| {
            u32::from_le_bytes([header[at], header[at + 1], header[at + 2], header[at + 3]])
        };
        if header[0..4] != MAGIC || word(8) != BLOB_LEN as u32 {
            return Ok(Slot::Damaged);
        }
        self.flash
            .read(offset + HEADER_LEN as u32, blob)
            .map_err(StorageError::Flash)?;
        Ok(if record_crc(&header[4..12], blob) == word(12) {
            Slot::Valid(word(4))
        } else {
            Slot::Damaged
        })
    }

    /// The newest valid record: its blob copied into `blob` (left as it
    /// was when there is none), and which slots hold damage.
    pub fn load(&mut self, blob: &mut [u8; BLOB_LEN]) -> Result<Loaded, StorageError<F::Error>> {
        let (mut a, mut b) = ([0u8; BLOB_LEN], [0u8; BLOB_LEN]);
        let states = [self.read_slot(0, &mut a)?, self.read_slot(1, &mut b)?];
        let damaged = |slot: &Slot| u8::from(matches!(slot, Slot::Damaged));
        let damaged_slots = damaged(&states[0]) | (damaged(&states[1]) << 1);
        let record = match states {
            [Slot::Valid(ga), Slot::Valid(gb)] if gb > ga => Some((gb, 1)),
            [Slot::Valid(ga), _] => Some((ga, 0)),
            [_, Slot::Valid(gb)] => Some((gb, 1)),
            _ => None,
        }
        .map(|(generation, slot)| {
            *blob = if slot == 0 { a } else { b };
            Stored { generation, slot }
        });
        Ok(Loaded {
            record,
            damaged_slots,
        })
    }

    /// Stores `blob` as the newest record (see the module's power-cut
    /// argument); returns where it went.
    pub fn save(&mut self, blob: &[u8; BLOB_LEN]) -> Result<Stored, StorageError<F::Error>> {
        let newest = self.load(&mut [0u8; BLOB_LEN])?.record;
        let (slot, generation) = match newest {
            Some(stored) => (1 - stored.slot, stored.generation.wrapping_add(1)),
            None => (0, 1),
        };
        let offset = self.slot_offset(slot);
        self.flash
            .erase(offset, offset + self.slot_len)
            .map_err(StorageError::Flash)?;
        self.write_padded(offset + HEADER_LEN as u32, blob)?;
        let mut header = [0u8; HEADER_LEN];
        header[0..4].copy_from_slice(&MAGIC);
        header[4..8].copy_from_slice(&generation.to_le_bytes());
        header[8..12].copy_from_slice(&(BLOB_LEN as u32).to_le_bytes());
        let crc = record_crc(&header[4..12], blob);
        header[12..16].copy_from_slice(&crc.to_le_bytes());
        self.flash
            .write(offset, &header)
            .map_err(StorageError::Flash)?;
        Ok(Stored { generation, slot })
    }

    /// Removes every record: the older slot first, then the newer (see the
    /// module's power-cut argument).
    pub fn erase(&mut self) -> Result<(), StorageError<F::Error>> {
        let newest = self
            .load(&mut [0u8; BLOB_LEN])?
            .record
            .map_or(1, |s| s.slot);
        for slot in [1 - newest, newest] {
            let offset = self.slot_offset(slot);
            self.flash
                .erase(offset, offset + self.slot_len)
                .map_err(StorageError::Flash)?;
        }
        Ok(())
    }

    /// Writes `bytes` at `offset`, the last partial write unit padded with 0xFF.
    fn write_padded(&mut self, offset: u32, bytes: &[u8]) -> Result<(), StorageError<F::Error>> {
        let whole = bytes.len() - bytes.len() % F::WRITE_SIZE;
        self.flash
            .write(offset, &bytes[..whole])
            .map_err(StorageError::Flash)?;
        if whole < bytes.len() {
            let mut tail = [0xFF; MAX_WRITE_SIZE];
            tail[..bytes.len() - whole].copy_from_slice(&bytes[whole..]);
            self.flash
                .write(offset + whole as u32, &tail[..F::WRITE_SIZE])
                .map_err(StorageError::Flash)?;
        }
        Ok(())
    }
}
