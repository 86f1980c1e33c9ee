//! An uncompressed chunk without a CRC (what rosbag2's MCAP storage writes
//! by default) decoded a window of its records at a time: each window read
//! from the file into a buffer that stays in the core's cache and its
//! whole records decoded at once, a record cut by the window's end carried
//! to the start of the next. The same records, in the same order, through
//! the same checks ([`split_record`], [`message_fields`]) as a chunk read
//! whole, so the same batch or the same error.
//!
//! Why: a chunk is a MiB or more; read whole, its first records have left
//! the core's L2 by the time they are decoded (and the Allan threads
//! sharing the core push them further out), so every message was fetched
//! from memory twice, once by the kernel's copy and once by the decoder.
//! A chunk with a CRC is read whole: its CRC is checked before any record
//! in it is parsed. A compressed chunk is decompressed whole.

use std::fs::File;

use mcap::records::{op, ChunkHeader};

use super::mcap_chunks::{message_fields, split_record, Decode, Ended, MAX_CHUNK};
use super::mcap_walk::ChunkAt;

/// Bytes read at a time (a record longer than that is read whole).
pub const WINDOW: usize = 256 << 10;

/// Whether the chunk of `header` is decoded a window at a time.
pub fn applies(header: &ChunkHeader) -> bool {
    header.compression.is_empty() && header.uncompressed_crc == 0
}

/// Decodes the messages of `chunk` (one [`applies`] to) from `file`,
/// through `window` (reused from chunk to chunk), into `batch` as
/// `decoder` makes them.
pub(super) fn decode<D: Decode>(
    file: &File,
    chunk: &ChunkAt,
    window: &mut Vec<u8>,
    decoder: &D,
    batch: &mut D::Batch,
) -> Ended {
    let h = &chunk.header;
    // The checks a chunk read whole has, in its words.
    if h.uncompressed_size > MAX_CHUNK {
        return Err(format!(
            "{} bytes decompressed, more than the {MAX_CHUNK} read",
            h.uncompressed_size
        ));
    }
    if h.compressed_size != h.uncompressed_size {
        return Err(format!(
            "{} bytes decompressed where its header says {}",
            h.compressed_size, h.uncompressed_size
        ));
    }
    let len = h.compressed_size;
    // Bytes of the chunk read so far; bytes at the window's start carried over.
    let (mut read, mut kept) = (0u64, 0usize);
    while read < len {
        // A window, or more to finish the record carried over.
        let missing = record_length(&window[..kept]).map_or(0, |n| n.saturating_sub(kept as u64));
        let piece = missing.max(WINDOW as u64).min(len - read) as usize;
        let end = kept + piece;
        if window.len() < end {
            window.resize(end, 0);
        }
        chunk.read_part(file, read, &mut window[kept..end])?;
        read += piece as u64;
        let mut rest = &window[..end];
        while !rest.is_empty() {
            // Cut by the window's end: read on (at the chunk's end, split_record says how it is cut).
            if read < len && record_length(rest).is_none_or(|n| n > rest.len() as u64) {
                break;
            }
            let (opcode, body, after) = split_record(rest)?;
            rest = after;
            if opcode != op::MESSAGE {
                continue;
            }
            let (channel, log_time, data) = message_fields(body)?;
            if !decoder.message(channel, log_time, data, batch) {
                return Ok(false);
            }
        }
        kept = rest.len();
        window.copy_within(end - kept..end, 0);
    }
    Ok(true)
}

/// The whole length of the record starting `bytes` (opcode, length, body),
/// once its opcode and length are there.
fn record_length(bytes: &[u8]) -> Option<u64> {
    let len = bytes.get(1..9)?;
    let len = u64::from_le_bytes(len.try_into().ok()?);
    Some(len.saturating_add(9))
}

#[cfg(test)]
mod tests {
    use super::super::imu_msg::{encode_cdr, Header, Imu, ROS2_TYPE};
    use super::super::mcap_chunks::{decode_chunk, split_record, Batch, Wanted};
    use super::super::mcap_walk::{self, Top};
    use super::*;

    /// An MCAP of IMU messages in uncompressed chunks without CRCs (as
    /// rosbag2 writes them) of three windows and more, some messages longer than a
    /// window (a frame_id of 200 KB), the others of many lengths: its bytes.
    fn bag() -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .calculate_chunk_crcs(false)
            .chunk_size(Some(3 * WINDOW as u64 + 1000))
            .create(&mut out)
            .unwrap();
        let schema = w.add_schema(ROS2_TYPE, "ros2msg", b"").unwrap();
        let imu = w
            .add_channel(schema, "/imu", "cdr", &Default::default())
            .unwrap();
        for k in 0..12_000u32 {
            let id_len = if k % 3000 == 700 {
                200 << 10
            } else {
                (k * 37 % 301) as usize
            };
            let msg = Imu {
                header: Header {
                    stamp: super::super::imu_msg::stamp_of(f64::from(k) * 0.01),
                    frame_id: "f".repeat(id_len),
                },
                angular_velocity: [f64::from(k), 0.5, -1.0],
                linear_acceleration: [0.1, f64::from(k) * 1e-3, 9.8],
                ..Imu::default()
            };
            let header = mcap::records::MessageHeader {
                channel_id: imu,
                sequence: k,
                log_time: u64::from(k) * 10_000_000,
                publish_time: 0,
            };
            w.write_to_known_channel(&header, &encode_cdr(&msg))
                .unwrap();
        }
        w.finish().unwrap();
        drop(w);
        out.into_inner()
    }

    /// The chunks of the MCAP at `path`.
    fn chunks(path: &std::path::Path) -> Vec<ChunkAt> {
        let mut found = Vec::new();
        let broken = |at, why| anyhow::anyhow!("at {at}: {why}");
        mcap_walk::walk(path, "bag", &broken, |top| {
            if let Top::Chunk(chunk) = top {
                found.push(chunk);
            }
            Ok(())
        })
        .unwrap();
        found
    }

    /// Each chunk decoded a window at a time and read whole: the same
    /// batch and the same end (its error included).
    fn both(path: &std::path::Path, chunks: &[ChunkAt]) -> Vec<(String, String)> {
        let file = File::open(path).unwrap();
        let wanted = Wanted {
            imu: vec![1],
            temperature: vec![],
        };
        let (mut window, mut stored, mut buffer, mut zstd) =
            (Vec::new(), Vec::new(), Vec::new(), None);
        chunks
            .iter()
            .map(|chunk| {
                assert!(applies(&chunk.header));
                let mut batch = Batch::default();
                let ended = decode(&file, chunk, &mut window, &wanted, &mut batch);
                let windowed = format!("{ended:?} {batch:?}");
                let mut batch = Batch::default();
                let ended = chunk.read(&file, &mut stored).and_then(|()| {
                    decode_chunk(
                        &chunk.header,
                        &stored,
                        &mut buffer,
                        &mut zstd,
                        &wanted,
                        &mut batch,
                    )
                });
                (windowed, format!("{ended:?} {batch:?}"))
            })
            .collect()
    }

    #[test]
    fn windows_give_what_the_whole_chunk_gives() {
        let bytes = bag();
        let path =
            std::env::temp_dir().join(format!("triad-mcap-windows-{}.mcap", std::process::id()));
        std::fs::write(&path, &bytes).unwrap();
        let found = chunks(&path);
        assert!(found.len() >= 5, "{} chunks", found.len());
        assert!(found
            .iter()
            .any(|c| c.header.compressed_size > 3 * WINDOW as u64));
        let mut messages = 0;
        for (windowed, whole) in both(&path, &found) {
            assert_eq!(windowed, whole);
            assert!(windowed.starts_with("Ok(true) ") && !windowed.contains("undecodable: Some"));
            messages += windowed.matches("Imu {").count();
        }
        assert_eq!(messages, 12_000);
        // Corrupt the records' framing and headers (opcode, length, channel,
        // CDR encapsulation, frame_id's length), at records on and near the
        // windows' edges and all through the chunks: each decoder's outcome
        // is the other's.
        let (mut broken, mut undecodable) = (0, 0);
        for (c, chunk) in found.iter().enumerate().step_by(3) {
            let start = chunk.data_at as usize;
            let data = &bytes[start..start + chunk.header.compressed_size as usize];
            let (mut rest, mut starts) = (data, Vec::new());
            while !rest.is_empty() {
                starts.push(data.len() - rest.len());
                rest = split_record(rest).unwrap().2;
            }
            let near_edge = |r: usize| (r % WINDOW) < 400 || (r % WINDOW) > WINDOW - 400;
            for (k, &r) in starts.iter().enumerate() {
                if !(near_edge(r) || k % 97 == 0) {
                    continue;
                }
                for (field, flip) in [
                    (0, 0x04u8),
                    (2, 0x01),
                    (5, 0x80),
                    (9, 0x02),
                    (32, 0x01),
                    (43, 0x10),
                ] {
                    let Some(i) = (r + field < data.len()).then_some(start + r + field) else {
                        continue;
                    };
                    let mut bad = bytes.clone();
                    bad[i] ^= flip;
                    std::fs::write(&path, &bad).unwrap();
                    let (windowed, whole) = both(&path, std::slice::from_ref(chunk)).remove(0);
                    assert_eq!(windowed, whole, "chunk {c}, record at {r}, byte {field}");
                    broken += usize::from(windowed.starts_with("Err"));
                    undecodable += usize::from(windowed.contains("undecodable: Some"));
                }
            }
        }
        // Both kinds of outcome were met: a broken chunk, a message that does not decode.
        assert!(
            broken > 0 && undecodable > 0,
            "{broken} broken, {undecodable} undecodable"
        );
        std::fs::remove_file(&path).unwrap();
    }
}
