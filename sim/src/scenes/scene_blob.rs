//! The binary form of a scene and its seed: what `triad sim --pack` writes
//! and the emulated board embeds (feature `sim-scene`), so that the chip
//! model streams the simulator's samples of that scene.
//!
//! Layout (little-endian):
//!
//! ```text
//! offset  size  field
//! 0       4     magic "TSCN"
//! 4       1     version (2)
//! 5       8     seed (u64)
//! 13      2     payload length N (u16)
//! 15      N     the Scene, postcard-encoded (serde's data model, varints)
//! 15+N    4     CRC-32C of bytes 0 .. 15+N
//! ```
//!
//! A blob that is short, foreign, of another version, damaged or not a scene
//! is refused with what was found; the scene is then checked by
//! [`Simulator::new`](super::simulator::Simulator::new) like any other.

use super::scene::Scene;
use triad::protocol::crc32c::crc32c;

/// The first four bytes of a scene blob.
pub const MAGIC: [u8; 4] = *b"TSCN";
/// The layout version this code reads and writes (2: the scene's effects
/// gained angle/velocity quantisation and the optical gyros).
pub const VERSION: u8 = 2;
/// Bytes before the payload.
const HEADER_LEN: usize = 15;
/// Bytes after the payload.
const CRC_LEN: usize = 4;
/// The largest blob: a scene with every effect named is about 600 bytes.
pub const MAX_BLOB_LEN: usize = 2048;

/// Why a blob was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneBlobError {
    /// Fewer bytes than the header and CRC.
    TooShort {
        /// Bytes given.
        len: usize,
    },
    /// Not a scene blob.
    Magic {
        /// The first four bytes.
        found: [u8; 4],
    },
    /// A layout this code does not read.
    Version {
        /// The version byte.
        found: u8,
    },
    /// The declared payload does not fit the bytes given.
    Length {
        /// Declared payload length.
        declared: usize,
        /// Bytes given in all.
        available: usize,
    },
    /// The CRC does not match: the blob is damaged.
    Crc {
        /// CRC stored in the blob.
        stored: u32,
        /// CRC of the bytes.
        computed: u32,
    },
    /// The payload is not a scene.
    Payload,
    /// The output buffer cannot hold the blob (encoding).
    BufferTooSmall {
        /// Bytes the buffer holds.
        available: usize,
    },
}

impl core::fmt::Display for SceneBlobError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            SceneBlobError::TooShort { len } => {
                write!(f, "{len} bytes: shorter than a scene blob's header and CRC")
            }
            SceneBlobError::Magic { found } => {
                write!(f, "magic {found:02x?} is not \"TSCN\": not a scene blob")
            }
            SceneBlobError::Version { found } => {
                write!(f, "version {found}: this firmware reads version {VERSION}")
            }
            SceneBlobError::Length {
                declared,
                available,
            } => write!(
                f,
                "payload of {declared} bytes declared, but the blob has {available} bytes"
            ),
            SceneBlobError::Crc { stored, computed } => write!(
                f,
                "CRC {stored:#010x} stored, {computed:#010x} computed: the blob is damaged"
            ),
            SceneBlobError::Payload => write!(f, "the payload is not a scene"),
            SceneBlobError::BufferTooSmall { available } => {
                write!(
                    f,
                    "a buffer of {available} bytes cannot hold the scene blob"
                )
            }
        }
    }
}

impl core::error::Error for SceneBlobError {}

/// Writes the blob of `scene` and `seed` into `out`; returns its length.
pub fn encode(scene: &Scene, seed: u64, out: &mut [u8]) -> Result<usize, SceneBlobError> {
    let available = out.len();
    let too_small = SceneBlobError::BufferTooSmall { available };
    if available < HEADER_LEN + CRC_LEN {
        return Err(too_small);
    }
    let payload_end = available - CRC_LEN;
    let payload_len = postcard::to_slice(scene, &mut out[HEADER_LEN..payload_end])
        .map_err(|_| too_small)?
        .len();
    let declared = u16::try_from(payload_len).map_err(|_| too_small)?;
    out[..4].copy_from_slice(&MAGIC);
    out[4] = VERSION;
    out[5..13].copy_from_slice(&seed.to_le_bytes());
    out[13..15].copy_from_slice(&declared.to_le_bytes());
    let end = HEADER_LEN + payload_len;
    let crc = crc32c(&out[..end]);
    out[end..end + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
    Ok(end + CRC_LEN)
}

/// Reads a blob: the scene and its seed.
pub fn decode(bytes: &[u8]) -> Result<(Scene, u64), SceneBlobError> {
    let len = bytes.len();
    if len < HEADER_LEN + CRC_LEN {
        return Err(SceneBlobError::TooShort { len });
    }
    let magic = [bytes[0], bytes[1], bytes[2], bytes[3]];
    if magic != MAGIC {
        return Err(SceneBlobError::Magic { found: magic });
    }
    if bytes[4] != VERSION {
        return Err(SceneBlobError::Version { found: bytes[4] });
    }
    let declared = usize::from(u16::from_le_bytes([bytes[13], bytes[14]]));
    let end = HEADER_LEN + declared;
    if end + CRC_LEN > len {
        return Err(SceneBlobError::Length {
            declared,
            available: len,
        });
    }
    let stored = u32::from_le_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
    let computed = crc32c(&bytes[..end]);
    if stored != computed {
        return Err(SceneBlobError::Crc { stored, computed });
    }
    let mut seed = [0u8; 8];
    seed.copy_from_slice(&bytes[5..13]);
    let scene =
        postcard::from_bytes(&bytes[HEADER_LEN..end]).map_err(|_| SceneBlobError::Payload)?;
    Ok((scene, u64::from_le_bytes(seed)))
}
