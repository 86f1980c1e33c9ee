//! An MCAP's records outside chunks, walked by triad: each record's opcode
//! and length read and checked against the file's end, a chunk's header
//! parsed here and its data left where it is (the chunk workers read it
//! themselves, in parallel, straight into their own buffers), the schema,
//! channel and message records parsed by the `mcap` crate from their
//! bounded bodies, the others skipped.
//!
//! Why not the crate's `LinearReader`: it reads every byte of the file
//! through its own buffer on one thread, so each chunk was copied twice
//! there (the file into its buffer, its buffer into a job) before a worker
//! saw it: with the kernel's copy, a third of `triad allan`'s time on an
//! uncompressed bag. The walk needs only the MCAP specification's record
//! framing (opcode u8, length u64, then the body; a chunk's body: start
//! and end time u64, uncompressed size u64, CRC u32, compression string,
//! compressed size u64, then its records) and the magic at both ends.

use std::fs::File;
use std::io::{BufReader, ErrorKind, Read};
use std::path::Path;

use anyhow::Context;
use mcap::records::{op, ChunkHeader, Record};

/// Bytes the walk reads at a time.
const WALK_BUFFER: usize = 8 << 10;

/// A record outside chunks, as the walk gives it.
pub enum Top<'a> {
    /// A chunk: its header, and where its stored data is.
    Chunk(ChunkAt),
    /// A schema, channel or message record.
    Record(Record<'a>),
}

/// A chunk found by the walk.
#[derive(Clone, Debug)]
pub struct ChunkAt {
    /// Its header.
    pub header: ChunkHeader,
    /// The byte of the file where its stored (compressed) records start;
    /// `header.compressed_size` of them, checked to lie within the record.
    pub data_at: u64,
    /// The byte after the chunk record.
    pub end: u64,
}

impl ChunkAt {
    /// Reads the chunk's stored data from `file` into `buffer`.
    pub fn read(&self, file: &File, buffer: &mut Vec<u8>) -> Result<(), String> {
        let len = usize::try_from(self.header.compressed_size).map_err(|e| e.to_string())?;
        // Every byte is read over: a buffer as long already is not cleared first.
        buffer.resize(len, 0);
        read_exact_at(file, buffer, self.data_at)
            .map_err(|e| format!("cannot read its data at byte {}: {e}", self.data_at))
    }

    /// Reads `buffer.len()` bytes of the chunk's stored data from `file`,
    /// starting `from` bytes into it (the caller keeps within its
    /// `compressed_size`).
    pub fn read_part(&self, file: &File, from: u64, buffer: &mut [u8]) -> Result<(), String> {
        let at = self.data_at + from;
        read_exact_at(file, buffer, at)
            .map_err(|e| format!("cannot read its data at byte {at}: {e}"))
    }
}

#[cfg(unix)]
fn read_exact_at(file: &File, buffer: &mut [u8], at: u64) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buffer, at)
}

#[cfg(windows)]
fn read_exact_at(file: &File, mut buffer: &mut [u8], mut at: u64) -> std::io::Result<()> {
    while !buffer.is_empty() {
        match std::os::windows::fs::FileExt::seek_read(file, buffer, at) {
            Ok(0) => return Err(ErrorKind::UnexpectedEof.into()),
            Ok(n) => {
                buffer = &mut buffer[n..];
                at += n as u64;
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// The bytes of a chunk record's body before its compression's name:
/// start and end time, uncompressed size, CRC, the name's length.
const CHUNK_FIXED: usize = 8 + 8 + 8 + 4 + 4;

/// The longest compression name read ("zstd", "lz4"; a longer one is corrupt).
const MAX_COMPRESSION_NAME: u32 = 64;

/// Walks the MCAP at `path`, giving each chunk and each schema, channel and
/// message record outside chunks to `each` in the file's order; where the
/// file breaks, `broken` of the bytes it is known to hold up to there and
/// why is the error. `name` names the file in messages.
pub fn walk(
    path: &Path,
    name: &str,
    broken: &dyn Fn(u64, String) -> anyhow::Error,
    mut each: impl FnMut(Top<'_>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let len = file
        .metadata()
        .with_context(|| format!("{name}: cannot read its size"))?
        .len();
    // Small: after a chunk the reader seeks past its data and the message
    // indexes that follow it, and each refill after a seek is read whole
    // (64 KiB refills copied a tenth of an uncompressed bag again).
    let mut file = BufReader::with_capacity(WALK_BUFFER, file);
    let mut at = 0u64;
    // Reads `buffer.len()` bytes at `at`; a short file is `broken`.
    let take = |file: &mut BufReader<File>, buffer: &mut [u8], at: &mut u64, what: &str| match file
        .read_exact(buffer)
    {
        Ok(()) => {
            *at += buffer.len() as u64;
            Ok(())
        }
        Err(e) if e.kind() == ErrorKind::UnexpectedEof => Err(broken(
            len,
            format!("the file ends in {what} (byte {at} of {len})"),
        )),
        Err(e) => Err(anyhow::anyhow!("{name}: cannot read at byte {at}: {e}")),
    };
    let mut magic = [0u8; 8];
    take(&mut file, &mut magic, &mut at, "its magic")?;
    if magic != mcap::MAGIC {
        return Err(broken(8, "it does not start with MCAP's magic".into()));
    }
    let mut body = Vec::new();
    loop {
        let start = at;
        let mut framing = [0u8; 9];
        take(
            &mut file,
            &mut framing,
            &mut at,
            "a record's opcode and length",
        )?;
        let opcode = framing[0];
        let size = u64::from_le_bytes(framing[1..].try_into().unwrap_or_default());
        let left = len.saturating_sub(at);
        if size > left {
            return Err(broken(
                len,
                format!("record 0x{opcode:02x} at byte {start} of {size} bytes runs past the file's end ({left} bytes left)"),
            ));
        }
        let end = at + size;
        match opcode {
            op::CHUNK => {
                let chunk = chunk_header(&mut file, &mut at, size)
                    .map_err(|why| broken(end, format!("the chunk at byte {start}: {why}")))?;
                let data_at = at;
                file.seek_relative((end - at) as i64)
                    .with_context(|| format!("{name}: cannot read at byte {end}"))?;
                at = end;
                each(Top::Chunk(ChunkAt {
                    header: chunk,
                    data_at,
                    end,
                }))?;
            }
            op::SCHEMA | op::CHANNEL | op::MESSAGE | op::FOOTER => {
                body.resize(size as usize, 0);
                take(&mut file, &mut body, &mut at, "a record")?;
                if opcode == op::FOOTER {
                    take(&mut file, &mut magic, &mut at, "its closing magic")?;
                    if magic != mcap::MAGIC {
                        return Err(broken(at, "it does not end with MCAP's magic".into()));
                    }
                    return Ok(());
                }
                let record = mcap::parse_record(opcode, &body).map_err(|e| {
                    broken(at, format!("record 0x{opcode:02x} at byte {start}: {e}"))
                })?;
                each(Top::Record(record))?;
            }
            _ => {
                file.seek_relative(size as i64)
                    .with_context(|| format!("{name}: cannot read at byte {end}"))?;
                at = end;
            }
        }
    }
}

/// Reads a chunk record's header (its body of `size` bytes starting at
/// `at`), leaving the file at its stored data, checked to fit the record.
fn chunk_header(file: &mut impl Read, at: &mut u64, size: u64) -> Result<ChunkHeader, String> {
    let mut fixed = [0u8; CHUNK_FIXED];
    if size < (CHUNK_FIXED + 8) as u64 {
        return Err(format!("{size} bytes, too short for a chunk's header"));
    }
    file.read_exact(&mut fixed).map_err(|e| e.to_string())?;
    let u64_at = |k: usize| u64::from_le_bytes(fixed[k..k + 8].try_into().unwrap_or_default());
    let u32_at = |k: usize| u32::from_le_bytes(fixed[k..k + 4].try_into().unwrap_or_default());
    let name_len = u32_at(28);
    if name_len > MAX_COMPRESSION_NAME || (CHUNK_FIXED + 8) as u64 + name_len as u64 > size {
        return Err(format!("a compression name of {name_len} bytes"));
    }
    let mut rest = vec![0u8; name_len as usize + 8];
    file.read_exact(&mut rest).map_err(|e| e.to_string())?;
    *at += (CHUNK_FIXED + rest.len()) as u64;
    let (compression, compressed_size) = rest.split_at(name_len as usize);
    let compression = String::from_utf8(compression.to_vec())
        .map_err(|_| "a compression name that is not UTF-8".to_string())?;
    let compressed_size = u64::from_le_bytes(compressed_size.try_into().unwrap_or_default());
    let header_len = (CHUNK_FIXED + 8) as u64 + name_len as u64;
    if compressed_size > size - header_len {
        return Err(format!(
            "{compressed_size} bytes of data in a record of {} after its header",
            size - header_len
        ));
    }
    Ok(ChunkHeader {
        message_start_time: u64_at(0),
        message_end_time: u64_at(8),
        uncompressed_size: u64_at(16),
        uncompressed_crc: u32_at(24),
        compression,
        compressed_size,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// An MCAP of three messages on one channel, in uncompressed chunks.
    fn file() -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .create(&mut out)
            .unwrap();
        let channel = w.add_channel(0, "/x", "cdr", &BTreeMap::new()).unwrap();
        for k in 0..3u32 {
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: k,
                log_time: u64::from(k),
                publish_time: 0,
            };
            w.write_to_known_channel(&header, &[k as u8; 5]).unwrap();
        }
        w.finish().unwrap();
        drop(w);
        out.into_inner()
    }

    /// What the walk of `bytes` gives: each chunk's size, each record's
    /// opcode, or the error.
    fn walked(bytes: &[u8], name: &str) -> Result<Vec<String>, String> {
        let path =
            std::env::temp_dir().join(format!("triad-mcap-walk-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        let file = File::open(&path).unwrap();
        let mut seen = Vec::new();
        let broken = |at, why| anyhow::anyhow!("{name}: broken within its first {at} bytes: {why}");
        let result = walk(&path, name, &broken, |top| {
            seen.push(match top {
                Top::Chunk(c) => {
                    let mut data = Vec::new();
                    c.read(&file, &mut data).map_err(anyhow::Error::msg)?;
                    format!("chunk of {} bytes", data.len())
                }
                Top::Record(r) => format!("record 0x{:02x}", r.opcode()),
            });
            Ok(())
        });
        let _ = std::fs::remove_file(&path);
        result.map(|()| seen).map_err(|e| e.to_string())
    }

    #[test]
    fn a_file_gives_its_chunk_and_a_broken_one_says_where() {
        let good = file();
        // The chunk, then the summary's channel record (given as well).
        let seen = walked(&good, "good.mcap").unwrap();
        assert!(seen[0].starts_with("chunk of "), "{seen:?}");
        assert_eq!(seen[1..], ["record 0x04"], "{seen:?}");
        // Not an MCAP.
        let e = walked(b"\x89MCAP1\r\n\x01", "other.mcap").unwrap_err();
        assert_eq!(
            e,
            "other.mcap: broken within its first 8 bytes: it does not start with MCAP's magic"
        );
        // Cut at every length: an error naming where, never a panic.
        for len in 0..good.len() - 8 {
            let e = walked(&good[..len], "cut.mcap").unwrap_err();
            assert!(
                e.starts_with("cut.mcap: broken within its first"),
                "{len}: {e}"
            );
        }
        // The first record's length made larger than the file.
        let mut long = good.clone();
        long[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
        let e = walked(&long, "long.mcap").unwrap_err();
        assert!(
            e.contains(
                "record 0x01 at byte 8 of 18446744073709551615 bytes runs past the file's end"
            ),
            "{e}"
        );
    }
}
