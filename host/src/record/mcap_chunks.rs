//! An MCAP file's messages on the chosen channels, decoded on every core:
//! one thread reads the file in order (buffered reads, not a map: a file
//! truncated under a map would kill the process with SIGBUS), the `mcap`
//! crate's reader yields each chunk whole, still compressed; worker threads
//! decompress a chunk, check its CRC, walk its records (the crate parses
//! each) and decode the messages of the wanted channels; the results are
//! taken back in the file's order. Chunks are independent by the format,
//! so the messages are those a serial reader gives, in the same order.
//! Memory: at most [`IN_FLIGHT`] chunks per worker, each at most
//! [`MAX_CHUNK`] bytes decompressed.

use std::collections::VecDeque;
use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

use anyhow::{anyhow, bail, Context};
use mcap::records::{op, ChunkHeader, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::imu_msg::{self, ImuFields, Time};

/// The largest decompressed chunk read (writers' chunks are a few MiB).
pub const MAX_CHUNK: u64 = 256 << 20;

/// The smallest read [`read_size`] allows past a file's known end (a file
/// still being written is read on in steps of this).
const PAST_END_STEP: usize = 64 << 10;

/// How much of a reader's request for `need` bytes at byte `offset` of a
/// file of `len` bytes to read: no more than the file has left (or a
/// [`PAST_END_STEP`]). The crate allocates and zeroes what is asked for
/// before the read: a corrupt length within the record length limit
/// (256 MiB) would cost that much memory and time on a file of a few KiB;
/// capped, the read comes up short and the crate reports the file's end.
pub fn read_size(need: usize, offset: u64, len: u64) -> usize {
    let left = usize::try_from(len.saturating_sub(offset)).unwrap_or(usize::MAX);
    need.min(left.max(PAST_END_STEP))
}

/// Chunks queued per worker before the reading thread waits.
const IN_FLIGHT: usize = 2;

/// The channels whose messages are decoded, by id.
#[derive(Clone, Debug, Default)]
pub struct Wanted {
    /// Channels of sensor_msgs/msg/Imu (CDR).
    pub imu: Vec<u16>,
    /// Channels of sensor_msgs/msg/Temperature (CDR).
    pub temperature: Vec<u16>,
}

/// A decoded message of a wanted channel.
#[derive(Clone, Copy, Debug)]
pub enum Decoded {
    /// An IMU message.
    Imu {
        /// What the record takes of it.
        fields: ImuFields,
        /// Its log time, ns.
        log_time: u64,
    },
    /// A temperature message.
    Temperature {
        /// Its header's stamp.
        stamp: Time,
        /// °C.
        celsius: f64,
    },
}

/// A wanted message that does not decode: why, and whether it was an IMU
/// one (the caller names it by its place among them).
#[derive(Clone, Debug)]
pub struct Undecodable {
    /// The decoder's reason.
    pub why: String,
    /// An IMU message (else a temperature).
    pub imu: bool,
}

/// What a chunk (or a run of messages outside chunks) gives: its decoded
/// messages in order, ended by the first that does not decode.
#[derive(Debug, Default)]
pub struct Batch {
    /// The wanted messages decoded, in the file's order.
    pub messages: Vec<Decoded>,
    /// The message after them that did not decode (the batch stops there).
    pub undecodable: Option<Undecodable>,
}

/// Reads the messages of `wanted` in the MCAP at `path` and gives them,
/// batch by batch in the file's order, to `take` (which may stop the read
/// with its error). `name` names the file in messages.
pub fn read(
    path: &Path,
    name: &str,
    wanted: &Wanted,
    mut take: impl FnMut(Batch) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let mut file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let len = file.metadata().map_or(u64::MAX, |m| m.len());
    // No record is longer than the file: a corrupt length is an error, not
    // an allocation of that length.
    let options = LinearReaderOptions::default()
        .with_emit_chunks(true)
        .with_record_length_limit(usize::try_from(len.max(MAX_CHUNK)).unwrap_or(usize::MAX));
    let mut reader = LinearReader::new_with_options(options);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        let mut pool = Vec::new();
        for _ in 0..workers {
            let (jobs, inbox) = sync_channel::<Job>(IN_FLIGHT);
            let (outbox, results) = sync_channel(IN_FLIGHT);
            scope.spawn(move || work(inbox, outbox, wanted));
            pool.push((jobs, results));
        }
        let mut order = Order {
            name,
            pool,
            pending: VecDeque::new(),
            next: 0,
            loose: Batch::default(),
        };
        let mut offset = 0u64;
        while let Some(event) = reader.next_event() {
            let record = match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let n = file
                        .read(reader.insert(read_size(need, offset, len)))
                        .with_context(|| format!("{name}: cannot read at byte {offset}"))?;
                    reader.notify_read(n);
                    offset += n as u64;
                    continue;
                }
                Ok(LinearReadEvent::Record { opcode, data }) => mcap::parse_record(opcode, data),
                Err(e) => Err(e),
            };
            let record = record.map_err(|e| broken(name, offset, e))?;
            match record {
                Record::Chunk { header, data } => {
                    order.flush_loose(&mut take)?;
                    let job = Job {
                        header,
                        data: data.into_owned(),
                        offset,
                    };
                    order.send(job, &mut take)?;
                }
                // A message outside chunks (an unchunked file): decoded
                // here, in order, up to the first that does not decode.
                Record::Message { header, data } if order.loose.undecodable.is_none() => {
                    decode(
                        wanted,
                        header.channel_id,
                        header.log_time,
                        &data,
                        &mut order.loose,
                    );
                }
                _ => {}
            }
        }
        order.flush_loose(&mut take)?;
        order.drain(&mut take)?;
        Ok(())
    })
}

/// The error of a file that broke within its first `offset` bytes.
fn broken(name: &str, offset: u64, e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{name}: broken MCAP within its first {offset} bytes: {e}")
}

/// A compressed chunk and where it ends in the file.
struct Job {
    header: ChunkHeader,
    data: Vec<u8>,
    offset: u64,
}

type Done = Result<Batch, String>;

/// The workers' queues and the chunks sent, in order.
struct Order<'a> {
    /// The file, in messages.
    name: &'a str,
    pool: Vec<(SyncSender<Job>, Receiver<Done>)>,
    /// (worker, the chunk's end in the file) of each chunk sent, oldest first.
    pending: VecDeque<(usize, u64)>,
    /// The worker of the next chunk.
    next: usize,
    /// Messages outside chunks not yet given.
    loose: Batch,
}

impl Order<'_> {
    /// Sends `job` to the next worker (round robin, so results come back in
    /// order), first taking the oldest result when every queue is full.
    fn send(
        &mut self,
        job: Job,
        take: &mut impl FnMut(Batch) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        if self.pending.len() >= self.pool.len() * IN_FLIGHT {
            self.take_oldest(take)?;
        }
        let w = self.next;
        self.next = (self.next + 1) % self.pool.len();
        let offset = job.offset;
        self.pool[w]
            .0
            .send(job)
            .map_err(|_| anyhow!("a chunk-decoding thread stopped"))?;
        self.pending.push_back((w, offset));
        Ok(())
    }

    fn take_oldest(
        &mut self,
        take: &mut impl FnMut(Batch) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let Some((w, offset)) = self.pending.pop_front() else {
            return Ok(());
        };
        let done = self.pool[w]
            .1
            .recv()
            .map_err(|_| anyhow!("a chunk-decoding thread stopped"))?;
        match done {
            Ok(batch) => take(batch),
            Err(why) => bail!(
                "{}: broken MCAP: the chunk that ends at byte {offset}: {why}",
                self.name
            ),
        }
    }

    /// Gives the messages outside chunks read so far (all of them before the next chunk).
    fn flush_loose(
        &mut self,
        take: &mut impl FnMut(Batch) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        if self.loose.messages.is_empty() && self.loose.undecodable.is_none() {
            return Ok(());
        }
        self.drain(take)?;
        take(std::mem::take(&mut self.loose))
    }

    /// Takes every result still pending.
    fn drain(&mut self, take: &mut impl FnMut(Batch) -> anyhow::Result<()>) -> anyhow::Result<()> {
        while !self.pending.is_empty() {
            self.take_oldest(take)?;
        }
        Ok(())
    }
}

/// A worker: decodes each chunk it is sent, reusing one buffer and one
/// zstd context.
fn work(inbox: Receiver<Job>, outbox: SyncSender<Done>, wanted: &Wanted) {
    let mut buffer = Vec::new();
    let mut zstd = None;
    for job in inbox {
        let done = decode_chunk(&job, &mut buffer, &mut zstd, wanted);
        if outbox.send(done).is_err() {
            return;
        }
    }
}

/// Decompresses a chunk into `buffer`, checks its CRC (where the writer
/// gave one) before any record in it is parsed, and decodes its wanted messages.
fn decode_chunk(
    job: &Job,
    buffer: &mut Vec<u8>,
    zstd: &mut Option<zstd::bulk::Decompressor<'static>>,
    wanted: &Wanted,
) -> Done {
    let h = &job.header;
    if h.uncompressed_size > MAX_CHUNK {
        return Err(format!(
            "{} bytes decompressed, more than the {MAX_CHUNK} read",
            h.uncompressed_size
        ));
    }
    let size = h.uncompressed_size as usize;
    buffer.clear();
    let data: &[u8] = match h.compression.as_str() {
        "" => &job.data,
        "zstd" => {
            buffer.reserve(size);
            let context = match zstd {
                Some(context) => context,
                None => {
                    zstd.insert(zstd::bulk::Decompressor::new().map_err(|e| format!("zstd: {e}"))?)
                }
            };
            // The chunk's CRC, where the writer gave one, is checked below:
            // zstd's own checksum of the same bytes (XXH64, where the frame
            // has one) would be a second pass over them.
            context
                .set_parameter(zstd::zstd_safe::DParameter::ForceIgnoreChecksum(
                    h.uncompressed_crc != 0,
                ))
                .map_err(|e| format!("zstd: {e}"))?;
            // Into the buffer's capacity: a chunk longer than announced is an error.
            context
                .decompress_to_buffer(&job.data, buffer)
                .map_err(|e| format!("zstd: {e}"))?;
            buffer
        }
        "lz4" => {
            buffer.reserve(size);
            let mut decoder = lz4::Decoder::new(&job.data[..]).map_err(|e| format!("lz4: {e}"))?;
            // One byte more than announced: a longer stream is then seen.
            (&mut decoder)
                .take(h.uncompressed_size + 1)
                .read_to_end(buffer)
                .map_err(|e| format!("lz4: {e}"))?;
            buffer
        }
        other => return Err(format!("compression `{other}` is not one MCAP defines")),
    };
    if data.len() != size {
        return Err(format!(
            "{} bytes decompressed where its header says {size}",
            data.len()
        ));
    }
    if h.uncompressed_crc != 0 && crc32fast::hash(data) != h.uncompressed_crc {
        return Err("its CRC does not match its content".into());
    }
    let mut batch = Batch::default();
    let mut rest = data;
    while !rest.is_empty() {
        let (opcode, body, after) = split_record(rest)?;
        rest = after;
        if opcode != op::MESSAGE {
            continue;
        }
        let (channel, log_time, data) = message_fields(body)?;
        decode(wanted, channel, log_time, data, &mut batch);
        if batch.undecodable.is_some() {
            break;
        }
    }
    Ok(batch)
}

/// The first record of `data`: (opcode, body, what follows).
fn split_record(data: &[u8]) -> Result<(u8, &[u8], &[u8]), String> {
    let Some((&opcode, rest)) = data.split_first() else {
        return Err("an empty record".into());
    };
    let Some((len, rest)) = rest.split_first_chunk::<8>() else {
        return Err(format!("record 0x{opcode:02x} cut in its length"));
    };
    let len = u64::from_le_bytes(*len);
    if len > rest.len() as u64 {
        return Err(format!(
            "record 0x{opcode:02x} of {len} bytes runs past the chunk's end ({} left)",
            rest.len()
        ));
    }
    let (body, after) = rest.split_at(len as usize);
    Ok((opcode, body, after))
}

/// A Message record's body, read where the MCAP specification puts its
/// fields (channel id u16, sequence u32, log time u64, publish time u64,
/// then the data), without the crate's general record parser: (channel,
/// log time, data).
fn message_fields(body: &[u8]) -> Result<(u16, u64, &[u8]), String> {
    let Some((fields, data)) = body.split_first_chunk::<MESSAGE_HEADER>() else {
        return Err(format!(
            "a message record of {} bytes, shorter than its {MESSAGE_HEADER}-byte header",
            body.len()
        ));
    };
    let channel = u16::from_le_bytes([fields[0], fields[1]]);
    let mut log_time = [0u8; 8];
    log_time.copy_from_slice(&fields[6..14]);
    Ok((channel, u64::from_le_bytes(log_time), data))
}

/// The bytes of a Message record's fields before its data.
const MESSAGE_HEADER: usize = 2 + 4 + 8 + 8;

/// Decodes the message `data` of channel `channel` into `batch` if it is wanted.
fn decode(wanted: &Wanted, channel: u16, log_time: u64, data: &[u8], batch: &mut Batch) {
    if wanted.imu.contains(&channel) {
        match imu_msg::decode_cdr(data) {
            Ok(fields) => batch.messages.push(Decoded::Imu { fields, log_time }),
            Err(e) => {
                batch.undecodable = Some(Undecodable {
                    why: e.to_string(),
                    imu: true,
                })
            }
        }
    } else if wanted.temperature.contains(&channel) {
        match imu_msg::decode_header_and_floats::<2>(data, TEMPERATURE_TYPE) {
            Ok((stamp, [celsius, _variance])) => {
                batch.messages.push(Decoded::Temperature { stamp, celsius })
            }
            Err(e) => {
                batch.undecodable = Some(Undecodable {
                    why: e.to_string(),
                    imu: false,
                })
            }
        }
    }
}

/// The type of the temperature topic read beside an IMU topic.
pub const TEMPERATURE_TYPE: &str = "sensor_msgs/msg/Temperature";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::imu_msg::{encode_cdr, Header, Imu};
    use mcap::records::MessageHeader;
    use std::collections::BTreeMap;
    use std::io::Cursor;

    /// An MCAP of `n` IMU messages on channel 1 and, between them, messages
    /// of another topic, written by the `mcap` crate with `options`.
    fn file(n: u32, options: mcap::WriteOptions) -> Vec<u8> {
        let mut out = Cursor::new(Vec::new());
        let mut w = options.create(&mut out).unwrap();
        let schema = w.add_schema(imu_msg::ROS2_TYPE, "ros2msg", b"").unwrap();
        let imu = w
            .add_channel(schema, "/imu", "cdr", &BTreeMap::new())
            .unwrap();
        let other = w
            .add_channel(schema, "/other", "cdr", &BTreeMap::new())
            .unwrap();
        for k in 0..n {
            let msg = Imu {
                header: Header {
                    stamp: Time {
                        sec: k as i32,
                        nanosec: k,
                    },
                    frame_id: "imu".into(),
                },
                angular_velocity: [f64::from(k), 0.5, -1.0],
                linear_acceleration: [0.0, f64::from(k) * 0.25, 9.81],
                ..Imu::default()
            };
            for channel_id in [imu, other] {
                let header = MessageHeader {
                    channel_id,
                    sequence: k,
                    log_time: u64::from(k) * 10,
                    publish_time: 0,
                };
                w.write_to_known_channel(&header, &encode_cdr(&msg))
                    .unwrap();
            }
        }
        w.finish().unwrap();
        drop(w);
        out.into_inner()
    }

    /// The IMU messages of `bytes` as the parallel reader gives them.
    fn read_bytes(bytes: &[u8], name: &str) -> anyhow::Result<Vec<(u32, f64, u64)>> {
        let path =
            std::env::temp_dir().join(format!("triad-mcap-chunks-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        let wanted = Wanted {
            imu: vec![1],
            temperature: vec![],
        };
        let mut got = Vec::new();
        let result = read(&path, name, &wanted, |batch| {
            for m in batch.messages {
                if let Decoded::Imu { fields, log_time } = m {
                    got.push((fields.stamp.nanosec, fields.angular_velocity[0], log_time));
                }
            }
            match batch.undecodable {
                Some(u) => Err(anyhow!("{}", u.why)),
                None => Ok(()),
            }
        });
        let _ = std::fs::remove_file(&path);
        result.map(|()| got)
    }

    #[test]
    fn every_compression_and_none_and_no_chunks_give_every_message_in_order() {
        let n = 5000;
        let small = || mcap::WriteOptions::new().chunk_size(Some(4096));
        for (what, options) in [
            ("zstd", small()),
            ("lz4", small().compression(Some(mcap::Compression::Lz4))),
            ("none", small().compression(None)),
            ("unchunked", mcap::WriteOptions::new().use_chunks(false)),
        ] {
            let got = read_bytes(&file(n, options), what).unwrap();
            assert_eq!(got.len(), n as usize, "{what}");
            for (k, &(nanosec, gx, log_time)) in got.iter().enumerate() {
                assert_eq!(
                    (nanosec, gx, log_time),
                    (k as u32, k as f64, 10 * k as u64),
                    "{what}"
                );
            }
        }
    }

    /// The middle byte of the compressed data of the `n`th chunk (from 1) of `file`.
    fn chunk_data(file: &[u8], n: usize) -> usize {
        let mut at = 8; // the magic
        let mut seen = 0;
        loop {
            let (opcode, len) = (
                file[at],
                u64::from_le_bytes(file[at + 1..at + 9].try_into().unwrap()),
            );
            let body = at + 9;
            if opcode == op::CHUNK {
                seen += 1;
                if seen == n {
                    // start, end, uncompressed size, CRC, compression (u32 length + name), compressed size.
                    let name = u32::from_le_bytes(file[body + 28..body + 32].try_into().unwrap());
                    let data = body + 32 + name as usize + 8;
                    return (data + body + len as usize) / 2;
                }
            }
            at = body + len as usize;
        }
    }

    #[test]
    fn a_message_record_is_read_where_the_specification_puts_its_fields() {
        let mut body = Vec::new();
        body.extend_from_slice(&7u16.to_le_bytes());
        body.extend_from_slice(&3u32.to_le_bytes());
        body.extend_from_slice(&123_456_789_012u64.to_le_bytes());
        body.extend_from_slice(&5u64.to_le_bytes());
        body.extend_from_slice(b"cdr");
        let (channel, log_time, data) = message_fields(&body).unwrap();
        assert_eq!((channel, log_time, data), (7, 123_456_789_012, &b"cdr"[..]));
        let e = message_fields(&body[..21]).unwrap_err();
        assert_eq!(
            e,
            "a message record of 21 bytes, shorter than its 22-byte header"
        );
    }

    #[test]
    fn a_corrupt_chunk_or_a_cut_file_is_an_error_naming_where() {
        let good = file(2000, mcap::WriteOptions::new().chunk_size(Some(4096)));
        // A byte in the middle of the second chunk's compressed data
        // changed: zstd or the chunk's CRC refuses it.
        let mut bad = good.clone();
        let at = chunk_data(&good, 2);
        bad[at] ^= 0x55;
        let e = read_bytes(&bad, "bad.mcap").map(|m| m.len());
        let e = e.unwrap_err().to_string();
        assert!(e.starts_with("bad.mcap: broken MCAP"), "{e}");
        assert!(e.contains("byte"), "{e}");
        // Cut in the middle: an error, not a panic, and no message after the cut.
        let e = read_bytes(&good[..good.len() / 2], "cut.mcap")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cut.mcap: broken MCAP within its first"),
            "{e}"
        );
    }
}
