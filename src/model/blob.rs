//! The compact binary form of a [`Calibration`] that the firmware embeds at
//! build time (`triad calib pack`) and checks at start.
//!
//! Byte layout (all multi-byte values little-endian, f64 as IEEE 754 binary64):
//!
//! | offset | size | content                                              |
//! |-------:|-----:|------------------------------------------------------|
//! |      0 |    4 | magic `TRCL` (0x54 0x52 0x43 0x4C)                    |
//! |      4 |    1 | version, [`VERSION`] = 3                              |
//! |      5 |    1 | flags: bit 0 accel has temperature terms, bit 1 gyro, bit 2 gyro has a g-sensitivity; other bits 0 |
//! |      6 |    2 | reserved, 0                                           |
//! |      8 |    4 | calibration id, u32                                   |
//! |     12 |  248 | accel triad (below)                                   |
//! |    260 |  248 | gyro triad (below)                                    |
//! |    508 |   72 | gyro g-sensitivity G, 9 f64 row-major, (rad/s)/(m/s²); 0 without G (flag bit 2 clear) |
//! |    580 |    4 | CRC-32C ([`crc32c`]) of bytes 0..580, u32             |
//!
//! A triad is 31 f64: `scale_misalignment` row-major (9), `bias` (3),
//! `temperature.reference_c` (1), `temperature.bias_coefficients` per axis
//! c1, c2, c3 (9), `temperature.scale_misalignment_per_c` row-major (9).
//! Without temperature terms (flag bit clear) those 19 values are 0.
//!
//! Version 2 ([`V2_LEN`] = 512 bytes) is version 3 without G: its CRC is at
//! 508, over bytes 0..508, and flag bit 2 is reserved. It is still read (as
//! G = 0), so blobs packed before G existed keep working; this code writes
//! version 3 only.
//!
//! The parameter bytes 12..508, with 508..580 when there is a G, also give a
//! calibration its default identity ([`parameter_id`]) when the file sets
//! none (so a calibration without G keeps the identity version 2 gave it).
//! Decoding checks the framing only; [`Corrector::new`](super::Corrector::new)
//! validates the values.

use core::fmt;

use super::calibration::{Calibration, TemperatureTerms, TriadCalibration};
use crate::protocol::crc32c::crc32c;

/// Total length of a blob in bytes (version 3).
pub const BLOB_LEN: usize = 584;
/// Total length of a version-2 blob (no g-sensitivity), still read.
pub const V2_LEN: usize = 512;
/// The magic at offset 0.
pub const MAGIC: [u8; 4] = *b"TRCL";
/// The layout version this code writes and reads. Version 1 closed the blob
/// with the Ethernet CRC-32; version 2 uses the project's one CRC, CRC-32C,
/// so a version-1 blob is refused by its version (re-pack it). Version 3
/// adds the gyroscope's g-sensitivity; version 2 is still read.
pub const VERSION: u8 = 3;

const TRIAD_LEN: usize = 31 * 8;
const TRIADS: core::ops::Range<usize> = 12..12 + 2 * TRIAD_LEN;
const G_SENSITIVITY: core::ops::Range<usize> = TRIADS.end..TRIADS.end + 9 * 8;
const CRC_AT: usize = BLOB_LEN - 4;
const FLAG_ACCEL_TEMPERATURE: u8 = 1;
const FLAG_GYRO_TEMPERATURE: u8 = 2;
const FLAG_G_SENSITIVITY: u8 = 4;

/// Why bytes are not a calibration blob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlobError {
    /// Not the length of its version ([`BLOB_LEN`], or [`V2_LEN`] for
    /// version 2), or too short to hold a version.
    WrongLength {
        /// The length given.
        len: usize,
        /// The length its version has ([`BLOB_LEN`] when the version is unreadable).
        expected: usize,
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
            BlobError::WrongLength { len, expected } => {
                write!(f, "calibration blob is {len} bytes, expected {expected}")
            }
            BlobError::BadMagic { found } => write!(
                f,
                "calibration blob magic is {found:02x?}, expected \"TRCL\""
            ),
            BlobError::UnsupportedVersion { version } => {
                write!(f, "calibration blob version {version} is not supported (this build reads 2 and {VERSION})")
            }
            BlobError::CrcMismatch { stored, computed } => write!(
                f,
                "calibration blob CRC-32C mismatch: stored {stored:#010x}, computed {computed:#010x}"
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
    encode_into(cal, &mut out);
    out
}

/// The blob of `cal` written over `out` (every byte), without a copy on the
/// stack (the device's upload keeps one buffer).
pub fn encode_into(cal: &Calibration, out: &mut [u8; BLOB_LEN]) {
    out.fill(0);
    out[0..4].copy_from_slice(&MAGIC);
    out[4] = VERSION;
    let flag = |set: bool, bit: u8| if set { bit } else { 0 };
    out[5] = flag(cal.accel.temperature.is_some(), FLAG_ACCEL_TEMPERATURE)
        | flag(cal.gyro.temperature.is_some(), FLAG_GYRO_TEMPERATURE)
        | flag(cal.g_sensitivity.is_some(), FLAG_G_SENSITIVITY);
    out[8..12].copy_from_slice(&cal.id.to_le_bytes());
    put_triad(out, TRIADS.start, &cal.accel);
    put_triad(out, TRIADS.start + TRIAD_LEN, &cal.gyro);
    let mut at = G_SENSITIVITY.start;
    for row in &cal.g_sensitivity.unwrap_or([[0.0; 3]; 3]) {
        put(out, &mut at, row);
    }
    let crc = crc32c(&out[..CRC_AT]);
    out[CRC_AT..].copy_from_slice(&crc.to_le_bytes());
}

/// The default calibration identity: CRC-32C of the parameter bytes 12..508
/// of the blob, and 508..580 when there is a G, so equal parameters give
/// equal identities whatever the id.
pub fn parameter_id(cal: &Calibration) -> u32 {
    let end = if cal.g_sensitivity.is_some() {
        G_SENSITIVITY.end
    } else {
        TRIADS.end
    };
    crc32c(&encode(cal)[TRIADS.start..end])
}

/// The current-version blob of `bytes`: the bytes themselves when they are
/// version 3 already, else (version 2) the same calibration encoded anew;
/// `None` when [`decode`] refuses them.
pub fn upgrade(bytes: &[u8]) -> Option<[u8; BLOB_LEN]> {
    let cal = decode(bytes).ok()?;
    Some(<[u8; BLOB_LEN]>::try_from(bytes).unwrap_or_else(|_| encode(&cal)))
}

/// Checks magic, version, length, reserved bits and CRC, then reads the
/// values. Reads version 3 and version 2 (as G = 0).
pub fn decode(bytes: &[u8]) -> Result<Calibration, BlobError> {
    let Some(header) = bytes.get(..5) else {
        return Err(BlobError::WrongLength {
            len: bytes.len(),
            expected: BLOB_LEN,
        });
    };
    let magic = [header[0], header[1], header[2], header[3]];
    if magic != MAGIC {
        return Err(BlobError::BadMagic { found: magic });
    }
    let (expected, known_flags) = match header[4] {
        2 => (V2_LEN, FLAG_ACCEL_TEMPERATURE | FLAG_GYRO_TEMPERATURE),
        VERSION => (
            BLOB_LEN,
            FLAG_ACCEL_TEMPERATURE | FLAG_GYRO_TEMPERATURE | FLAG_G_SENSITIVITY,
        ),
        version => return Err(BlobError::UnsupportedVersion { version }),
    };
    if bytes.len() != expected {
        return Err(BlobError::WrongLength {
            len: bytes.len(),
            expected,
        });
    }
    let crc_at = expected - 4;
    let stored = u32::from_le_bytes([
        bytes[crc_at],
        bytes[crc_at + 1],
        bytes[crc_at + 2],
        bytes[crc_at + 3],
    ]);
    let computed = crc32c(&bytes[..crc_at]);
    if stored != computed {
        return Err(BlobError::CrcMismatch { stored, computed });
    }
    let flags = bytes[5];
    if flags & !known_flags != 0 {
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
    let g_sensitivity = (flags & FLAG_G_SENSITIVITY != 0).then(|| {
        let mut g = [[0.0; 3]; 3];
        let mut at = G_SENSITIVITY.start;
        for row in g.iter_mut() {
            get(bytes, &mut at, row);
        }
        g
    });
    Ok(Calibration {
        id: u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]),
        accel: get_triad(bytes, TRIADS.start, flags & FLAG_ACCEL_TEMPERATURE != 0),
        gyro: get_triad(
            bytes,
            TRIADS.start + TRIAD_LEN,
            flags & FLAG_GYRO_TEMPERATURE != 0,
        ),
        g_sensitivity,
    })
}
