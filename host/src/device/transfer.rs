//! A calibration blob to and from the device: uploaded in chunks of at most
//! [`CHUNK_LEN`] bytes, in order from offset 0, then committed with its
//! length and CRC-32C (the device checks it as `triad calib check` does and
//! applies it whole, or changes nothing); read back chunk by chunk.

use std::io::{Read, Write};

use triad::protocol::bytes::Reader;
use triad::protocol::crc32c::crc32c;
use triad::protocol::{Command, Payload, CHUNK_LEN};

use super::link::{Link, LinkError};

/// Uploads `blob` and commits it; returns the calibration id the device
/// now applies.
pub fn upload<P: Read + Write>(link: &mut Link<P>, blob: &[u8]) -> Result<u32, LinkError> {
    let too_long = |what: &str| LinkError::BadResult {
        command: "upload chunk",
        reason: format!("{what}: a blob of {} bytes is too long", blob.len()),
    };
    let len = u16::try_from(blob.len()).map_err(|_| too_long("length"))?;
    for (n, chunk) in blob.chunks(CHUNK_LEN).enumerate() {
        let offset = u16::try_from(n * CHUNK_LEN).map_err(|_| too_long("offset"))?;
        // A chunk is CHUNK_LEN bytes at most, which a payload holds.
        let data = Payload::new(chunk).map_err(|_| too_long("chunk"))?;
        link.command(&Command::UploadChunk { offset, data })?;
    }
    let reply = link.command(&Command::UploadCommit {
        len,
        crc: crc32c(blob),
    })?;
    let mut r = Reader::new(reply.payload.as_slice());
    let id = r.u32();
    if r.ran_short() {
        return Err(LinkError::BadResult {
            command: "upload commit",
            reason: format!(
                "{} bytes, expected the 4-byte calibration id",
                reply.payload.as_slice().len()
            ),
        });
    }
    Ok(id)
}

/// Reads back the active calibration's blob; `None` when the device runs
/// none (the identity, its frames flagged UNCALIBRATED).
pub fn download<P: Read + Write>(link: &mut Link<P>) -> Result<Option<Vec<u8>>, LinkError> {
    let mut blob = Vec::new();
    loop {
        let offset = u16::try_from(blob.len()).unwrap_or(u16::MAX);
        let reply = link.command(&Command::ReadCalibration { offset })?;
        let bad = |reason: String| LinkError::BadResult {
            command: "read calibration",
            reason,
        };
        let mut r = Reader::new(reply.payload.as_slice());
        let total = usize::from(r.u16());
        let bytes = r.rest();
        if r.ran_short() {
            return Err(bad("no total length".into()));
        }
        if total == 0 {
            return Ok(None);
        }
        let end = blob.len() + bytes.len();
        if bytes.is_empty() || end > total {
            return Err(bad(format!(
                "{} bytes from byte {} of a {total}-byte blob",
                bytes.len(),
                blob.len()
            )));
        }
        blob.extend_from_slice(bytes);
        if end == total {
            return Ok(Some(blob));
        }
    }
}
