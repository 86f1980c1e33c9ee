//! The compact binary form of a [`Calibration`] that the firmware embeds at
//! build time (`triad calib pack`) and checks at start.
//!
//! Byte layout (all multi-byte values little-endian, f64 as IEEE 754 binary64):
//!
//! | offset | size | content                                              |
//! |-------:|-----:|------------------------------------------------------|
//! |      0 |    4 | magic `TRCL` (0x54 0x52 0x43 0x4C)                    |
//! |      4 |    1 | version, [`VERSION`] = 2                              |
//! |      5 |    1 | flags: bit 0 accel has temperature terms, bit 1 gyro; other bits 0 |
//! |      6 |    2 | reserved, 0                                           |
//! |      8 |    4 | calibration id, u32                                   |
//! |     12 |  248 | accel triad (below)                                   |
//! |    260 |  248 | gyro triad (below)                                    |
//! |    508 |    4 | CRC-32C ([`crc32c`]) of bytes 0..508, u32             |
//!
//! A triad is 31 f64: `scale_misalignment` row-major (9), `bias` (3),
//! `temperature.reference_c` (1), `temperature.bias_coefficients` per axis
//! c1, c2, c3 (9), `temperature.scale_misalignment_per_c` row-major (9).
//! Without temperature terms (flag bit clear) those 19 values are 0.
//!
//! The parameter bytes 12..508 also give a calibration its default identity
//! ([`parameter_id`]) when the file sets none. Decoding checks the framing
//! only; [`Corrector::new`](super::Corrector::new) validates the values.

use core::fmt;

use super::calibration::{Calibration, TemperatureTerms, TriadCalibration};
use crate::crc32c::crc32c;

/// Total length of a blob in bytes.
pub const BLOB_LEN: usize = 512;
/// The magic at offset 0.
pub const MAGIC: [u8; 4] = *b"TRCL";
/// The layout version this code writes and reads. Version 1 closed the blob
/// with the Ethernet CRC-32; version 2 uses the project's one CRC, CRC-32C,
/// so a version-1 blob is refused by its version (re-pack it).
pub const VERSION: u8 = 2;

const TRIAD_LEN: usize = 31 * 8;
const PARAMS: core::ops::Range<usize> = 12..12 + 2 * TRIAD_LEN;
const CRC_AT: usize = BLOB_LEN - 4;
const FLAG_ACCEL_TEMPERATURE: u8 = 1;
const FLAG_GYRO_TEMPERATURE: u8 = 2;

/// Why bytes are not a calibration blob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlobError {
    /// Not [`BLOB_LEN`] bytes.
    WrongLength {
        /// The length given.
        len: usize,
    },
    /// The first four bytes are not [`MAGIC`].
    BadMagic {
        /// The bytes found.
        found: [u8; 4],
    },
    /// A version this code does not read.
    UnsupportedVersion {
        /// The version found.
        version: u8,
    },
    /// The stored CRC does not match the computed one.
    CrcMismatch {
        /// The CRC stored in the blob.
        stored: u32,
        /// The CRC computed over bytes 0..508.
        computed: u32,
    },
    /// Unknown flag bits or non-zero reserved bytes.
    ReservedBits {
        /// Byte offset.
        offset: u8,
        /// The byte.
        value: u8,
    },
}

impl fmt::Display for BlobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BlobError::WrongLength { len } => {
                write!(f, "calibration blob is {len} bytes, expected {BLOB_LEN}")
            }
            BlobError::BadMagic { found } => write!(
                f,
                "calibration blob magic is {found:02x?}, expected \"TRCL\""
            ),
            BlobError::UnsupportedVersion { version } => {
                write!(f, "calibration blob version {version} is not supported (this build reads {VERSION})")
            }
            BlobError::CrcMismatch { stored, computed } => write!(
                f,
                "calibration blob CRC-32 mismatch: stored {stored:#010x}, computed {computed:#010x}"
            ),
            BlobError::ReservedBits { offset, value } => {
                write!(
                    f,
                    "calibration blob byte {offset} = {value:#04x}: reserved bits set"
                )
            }
        }
    }
}

/// Writes f64 values from `values` into `out` little-endian.
fn put(out: &mut [u8], at: &mut usize, values: &[f64]) {
    for v in values {
        if let Some(slot) = out.get_mut(*at..*at + 8) {
            slot.copy_from_slice(&v.to_le_bytes());
        }
        *at += 8;
    }
}

fn put_triad(out: &mut [u8], at: usize, t: &TriadCalibration) {
    let mut at = at;
    let zero = TemperatureTerms {
        reference_c: 0.0,
        bias_coefficients: [[0.0; 3]; 3],
        scale_misalignment_per_c: [[0.0; 3]; 3],
    };
    let terms = t.temperature.unwrap_or(zero);
    for row in &t.scale_misalignment {
        put(out, &mut at, row);
    }
    put(out, &mut at, &t.bias);
    put(out, &mut at, &[terms.reference_c]);
    for row in terms
        .bias_coefficients
        .iter()
        .chain(terms.scale_misalignment_per_c.iter())
    {
        put(out, &mut at, row);
    }
}

/// Reads f64 values little-endian (the caller has checked the length).
fn get(bytes: &[u8], at: &mut usize, out: &mut [f64]) {
    for v in out.iter_mut() {
        let mut b = [0u8; 8];
        if let Some(slot) = bytes.get(*at..*at + 8) {
            b.copy_from_slice(slot);
        }
        *v = f64::from_le_bytes(b);
        *at += 8;
    }
}

fn get_triad(bytes: &[u8], at: usize, has_temperature: bool) -> TriadCalibration {
    let mut at = at;
    let mut t = TriadCalibration::IDENTITY;
    for row in t.scale_misalignment.iter_mut() {
        get(bytes, &mut at, row);
    }
    get(bytes, &mut at, &mut t.bias);
    let mut reference = [0.0];
    get(bytes, &mut at, &mut reference);
    let mut terms = TemperatureTerms {
        reference_c: reference[0],
        bias_coefficients: [[0.0; 3]; 3],
        scale_misalignment_per_c: [[0.0; 3]; 3],
    };
    for row in terms
        .bias_coefficients
        .iter_mut()
        .chain(terms.scale_misalignment_per_c.iter_mut())
    {
        get(bytes, &mut at, row);
    }
    t.temperature = has_temperature.then_some(terms);
    t
}

/// The blob of `cal`.
pub fn encode(cal: &Calibration) -> [u8; BLOB_LEN] {
    let mut out = [0u8; BLOB_LEN];
    out[0..4].copy_from_slice(&MAGIC);
    out[4] = VERSION;
    out[5] = if cal.accel.temperature.is_some() {
        FLAG_ACCEL_TEMPERATURE
    } else {
        0
    } | if cal.gyro.temperature.is_some() {
        FLAG_GYRO_TEMPERATURE
    } else {
        0
    };
    out[8..12].copy_from_slice(&cal.id.to_le_bytes());
    put_triad(&mut out, PARAMS.start, &cal.accel);
    put_triad(&mut out, PARAMS.start + TRIAD_LEN, &cal.gyro);
    let crc = crc32c(&out[..CRC_AT]);
    out[CRC_AT..].copy_from_slice(&crc.to_le_bytes());
    out
}

/// The default calibration identity: CRC-32 of the parameter bytes 12..508
/// of the blob, so equal parameters give equal identities whatever the id.
pub fn parameter_id(cal: &Calibration) -> u32 {
    crc32c(&encode(cal)[PARAMS])
}

/// Checks length, magic, version, reserved bits and CRC, then reads the values.
pub fn decode(bytes: &[u8]) -> Result<Calibration, BlobError> {
    let bytes: &[u8; BLOB_LEN] = bytes
        .try_into()
        .map_err(|_| BlobError::WrongLength { len: bytes.len() })?;
    let magic = [bytes[0], bytes[1], bytes[2], bytes[3]];
    if magic != MAGIC {
        return Err(BlobError::BadMagic { found: magic });
    }
    if bytes[4] != VERSION {
        return Err(BlobError::UnsupportedVersion { version: bytes[4] });
    }
    let stored = u32::from_le_bytes([
        bytes[CRC_AT],
        bytes[CRC_AT + 1],
        bytes[CRC_AT + 2],
        bytes[CRC_AT + 3],
    ]);
    let computed = crc32c(&bytes[..CRC_AT]);
    if stored != computed {
        return Err(BlobError::CrcMismatch { stored, computed });
    }
    let flags = bytes[5];
    if flags & !(FLAG_ACCEL_TEMPERATURE | FLAG_GYRO_TEMPERATURE) != 0 {
        return Err(BlobError::ReservedBits {
            offset: 5,
            value: flags,
        });
    }
    for offset in 6..8u8 {
        let value = bytes[usize::from(offset)];
        if value != 0 {
            return Err(BlobError::ReservedBits { offset, value });
        }
    }
    Ok(Calibration {
        id: u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]),
        accel: get_triad(bytes, PARAMS.start, flags & FLAG_ACCEL_TEMPERATURE != 0),
        gyro: get_triad(
            bytes,
            PARAMS.start + TRIAD_LEN,
            flags & FLAG_GYRO_TEMPERATURE != 0,
        ),
    })
}
