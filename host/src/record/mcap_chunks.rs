//! An MCAP file's messages on the chosen channels, decoded on every core:
//! one thread walks the file's records in order ([`mcap_walk`]: reads, not
//! a map: a file truncated under a map would kill the process with
//! SIGBUS) and sends the places of a run of consecutive chunks (about
//! [`RUN_BYTES`]) to a worker; the worker reads each chunk's data there,
//! decompresses it, checks its CRC, walks its records (each bounded by the
//! chunk) and makes the run's messages into one batch as a [`Decode`] says
//! (the decoded messages of the wanted channels, or a command's rows
//! straight from them); the batches are taken back in the file's order.
//! Chunks are independent by the format, so the messages are those a
//! serial reader gives, in the same order. Memory: at most [`IN_FLIGHT`]
//! runs' batches per worker, and one chunk at a time in its buffers, at
//! most [`MAX_CHUNK`] bytes decompressed.
//!
//! Why runs: writers' chunks are about a MiB (rosbag2's and the mcap
//! crate's default is 768 KiB of records), and a hand-off per chunk between
//! the threads (walk → worker → walk → consumer) made ~15 000 context
//! switches on an 8-hour bag, each a wake-up the two cores waited on.

use std::collections::VecDeque;
use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

use anyhow::{anyhow, bail, Context};
use mcap::records::{op, ChunkHeader, Record};

use super::imu_msg::{self, ImuFields, Time};
use super::mcap_walk::{self, ChunkAt, Top};
use super::mcap_windows;

/// The largest decompressed chunk read (writers' chunks are a few MiB).
pub const MAX_CHUNK: u64 = 256 << 20;

/// Runs queued per worker before the reading thread waits.
const IN_FLIGHT: usize = 2;

/// Bytes of records (decompressed) after which a run of chunks is sent.
pub const RUN_BYTES: u64 = 4 << 20;

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

/// What a worker makes of the messages of a chunk (or of a run of
/// messages outside chunks, on the reading thread), one at a time in the
/// file's order: the decoded messages ([`Wanted`]), or the rows a command
/// takes straight from them.
pub trait Decode: Sync {
    /// What a chunk gives.
    type Batch: Default + Send;
    /// An empty batch for a chunk of `bytes` bytes of records (its room
    /// made for them at once, where the decoder can tell).
    fn batch(&self, bytes: usize) -> Self::Batch {
        let _ = bytes;
        Self::Batch::default()
    }
    /// Takes the message `data` of channel `channel`, logged at `log_time`
    /// (ns), into `batch`; false when the batch must stop there (its
    /// message did not decode, or failed a check).
    fn message(&self, channel: u16, log_time: u64, data: &[u8], batch: &mut Self::Batch) -> bool;
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

/// Reads the messages of the MCAP at `path` as `decoder` makes them into
/// batches, on every core, and gives the batches in the file's order to
/// `take` (which may stop the read with its error). `name` names the file
/// in messages.
pub fn read<D: Decode>(
    path: &Path,
    name: &str,
    decoder: &D,
    mut take: impl FnMut(D::Batch) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    // The workers read their chunks' data themselves, at its place.
    let file = &File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        let mut pool = Vec::new();
        for _ in 0..workers {
            let (runs, inbox) = sync_channel::<Vec<ChunkAt>>(IN_FLIGHT);
            let (outbox, results) = sync_channel(IN_FLIGHT);
            scope.spawn(move || work(file, inbox, outbox, decoder));
            pool.push((runs, results));
        }
        let mut order = Order {
            name,
            pool,
            pending: VecDeque::new(),
            next: 0,
            run: Vec::new(),
            run_bytes: 0,
            loose: None,
            loose_stopped: false,
        };
        let broken = |offset, why| broken(name, offset, why);
        mcap_walk::walk(path, name, &broken, |top| {
            match top {
                Top::Chunk(chunk) => {
                    order.flush_loose(&mut take)?;
                    order.run_bytes += records_bytes(&chunk);
                    order.run.push(chunk);
                    if order.run_bytes >= RUN_BYTES {
                        order.send_run(&mut take)?;
                    }
                }
                // A message outside chunks (an unchunked file): decoded
                // here, in order, up to the first that does not decode,
                // after the chunks before it.
                Top::Record(Record::Message { header, data }) if !order.loose_stopped => {
                    order.send_run(&mut take)?;
                    let loose = order.loose.get_or_insert_with(D::Batch::default);
                    order.loose_stopped =
                        !decoder.message(header.channel_id, header.log_time, &data, loose);
                }
                _ => {}
            }
            Ok(())
        })?;
        order.send_run(&mut take)?;
        order.flush_loose(&mut take)?;
        order.drain(&mut take)?;
        Ok(())
    })
}

/// Gives every Schema and Channel record of the MCAP at `path`, those in
/// chunks included, in the file's order, to `take`: what a file without a
/// summary says of its channels. Where the file breaks, the error says
/// after how many messages and within how many bytes. A chunk is decompressed and its CRC
/// checked (where the writer gave one) before any record in it is parsed,
/// and each record in it is bounded by the chunk ([`split_record`]): the
/// crate's own reader of a chunk's records trusts their lengths (mcap 0.26,
/// the newest, overflows a subtraction on a corrupt one:
/// fuzz/findings/mcap_scan_subtract_overflow.mcap).
pub fn definitions(
    path: &Path,
    name: &str,
    mut take: impl FnMut(Record<'_>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let (mut stored, mut buffer) = (Vec::new(), Vec::new());
    let mut zstd = None;
    let messages = std::cell::Cell::new(0u64);
    let broken = |offset, why| {
        anyhow!(
            "{name}: broken MCAP after {} message(s), within its first {offset} bytes: {why}",
            messages.get()
        )
    };
    mcap_walk::walk(path, name, &broken, |top| match top {
        Top::Chunk(chunk) => {
            let in_chunk = |why| broken(chunk.end, format!("the chunk that ends there: {why}"));
            chunk.read(&file, &mut stored).map_err(in_chunk)?;
            let mut rest =
                decompress(&chunk.header, &stored, &mut buffer, &mut zstd).map_err(in_chunk)?;
            while !rest.is_empty() {
                let (opcode, body, after) = split_record(rest).map_err(in_chunk)?;
                rest = after;
                if opcode == op::MESSAGE {
                    messages.set(messages.get() + 1);
                } else if opcode == op::SCHEMA || opcode == op::CHANNEL {
                    let record = mcap::parse_record(opcode, body)
                        .map_err(|e| in_chunk(format!("record 0x{opcode:02x}: {e}")))?;
                    take(record)?;
                }
            }
            Ok(())
        }
        Top::Record(r @ (Record::Schema { .. } | Record::Channel(_))) => take(r),
        Top::Record(Record::Message { .. }) => {
            messages.set(messages.get() + 1);
            Ok(())
        }
        _ => Ok(()),
    })
}

/// The error of a file that broke within its first `offset` bytes.
fn broken(name: &str, offset: u64, e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{name}: broken MCAP within its first {offset} bytes: {e}")
}

/// How the decoding of a chunk ended: `Ok(true)` at its end, `Ok(false)`
/// where the decoder stopped the batch, `Err` why the chunk is broken.
pub(super) type Ended = Result<bool, String>;

/// What a run of chunks gives: the batch of its messages, up to where the
/// decoder stopped or a chunk broke (the messages before the break in it
/// included), and that chunk's end in the file with why it is broken.
struct Done<B> {
    batch: B,
    broken: Option<(u64, String)>,
}

/// A worker's queues: the runs it is sent, what it makes of them.
type Queues<B> = (SyncSender<Vec<ChunkAt>>, Receiver<Done<B>>);

/// The workers' queues and the runs sent, in order.
struct Order<'a, B> {
    /// The file, in messages.
    name: &'a str,
    pool: Vec<Queues<B>>,
    /// The worker of each run sent, oldest first.
    pending: VecDeque<usize>,
    /// The worker of the next run.
    next: usize,
    /// The run not yet sent, and its bytes of records.
    run: Vec<ChunkAt>,
    run_bytes: u64,
    /// Messages outside chunks not yet given.
    loose: Option<B>,
    /// A message outside chunks stopped its batch: no more are decoded.
    loose_stopped: bool,
}

impl<B> Order<'_, B> {
    /// Sends the run (if any) to the next worker (round robin, so results
    /// come back in order), first taking the oldest result when every queue
    /// is full.
    fn send_run(&mut self, take: &mut impl FnMut(B) -> anyhow::Result<()>) -> anyhow::Result<()> {
        if self.run.is_empty() {
            return Ok(());
        }
        if self.pending.len() >= self.pool.len() * IN_FLIGHT {
            self.take_oldest(take)?;
        }
        let w = self.next;
        self.next = (self.next + 1) % self.pool.len();
        self.run_bytes = 0;
        self.pool[w]
            .0
            .send(std::mem::take(&mut self.run))
            .map_err(|_| anyhow!("a chunk-decoding thread stopped"))?;
        self.pending.push_back(w);
        Ok(())
    }

    /// Gives the oldest run's batch, then its broken chunk's error if any.
    fn take_oldest(
        &mut self,
        take: &mut impl FnMut(B) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let Some(w) = self.pending.pop_front() else {
            return Ok(());
        };
        let done = self.pool[w]
            .1
            .recv()
            .map_err(|_| anyhow!("a chunk-decoding thread stopped"))?;
        take(done.batch)?;
        match done.broken {
            None => Ok(()),
            Some((offset, why)) => bail!(
                "{}: broken MCAP: the chunk that ends at byte {offset}: {why}",
                self.name
            ),
        }
    }

    /// Gives the messages outside chunks read so far (all of them before the next chunk).
    fn flush_loose(
        &mut self,
        take: &mut impl FnMut(B) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let Some(loose) = self.loose.take() else {
            return Ok(());
        };
        self.drain(take)?;
        take(loose)
    }

    /// Takes every result still pending.
    fn drain(&mut self, take: &mut impl FnMut(B) -> anyhow::Result<()>) -> anyhow::Result<()> {
        while !self.pending.is_empty() {
            self.take_oldest(take)?;
        }
        Ok(())
    }
}

/// A worker: reads each run of chunks it is sent from `file` and decodes
/// it into one batch, reusing its buffers and one zstd context.
fn work<D: Decode>(
    file: &File,
    inbox: Receiver<Vec<ChunkAt>>,
    outbox: SyncSender<Done<D::Batch>>,
    decoder: &D,
) {
    let mut chunk_reader = ChunkReader::default();
    for run in inbox {
        let bytes: u64 = run.iter().map(records_bytes).sum();
        let mut batch = decoder.batch(bytes as usize);
        let mut broken = None;
        for chunk in &run {
            match chunk_reader.decode(file, chunk, decoder, &mut batch) {
                Ok(true) => {}
                Ok(false) => break,
                Err(why) => {
                    broken = Some((chunk.end, why));
                    break;
                }
            }
        }
        if outbox.send(Done { batch, broken }).is_err() {
            return;
        }
    }
}

/// The bytes of records `chunk` holds, as its header says (at most the
/// [`MAX_CHUNK`] read): what a run counts, and its batch makes room for.
fn records_bytes(chunk: &ChunkAt) -> u64 {
    chunk.header.uncompressed_size.min(MAX_CHUNK)
}

/// A worker's buffers: the chunk's stored data (or a window of it), its
/// decompressed records, one zstd context.
#[derive(Default)]
struct ChunkReader {
    stored: Vec<u8>,
    buffer: Vec<u8>,
    zstd: Option<zstd::bulk::Decompressor<'static>>,
}

impl ChunkReader {
    /// Reads the chunk at `chunk` from `file` and decodes its messages into
    /// `batch`: a window at a time where [`mcap_windows`] applies, else whole.
    fn decode<D: Decode>(
        &mut self,
        file: &File,
        chunk: &ChunkAt,
        decoder: &D,
        batch: &mut D::Batch,
    ) -> Ended {
        if mcap_windows::applies(&chunk.header) {
            return mcap_windows::decode(file, chunk, &mut self.stored, decoder, batch);
        }
        chunk.read(file, &mut self.stored)?;
        decode_chunk(
            &chunk.header,
            &self.stored,
            &mut self.buffer,
            &mut self.zstd,
            decoder,
            batch,
        )
    }
}

/// Decompresses a chunk (`stored`, as its header says) and decodes its
/// messages into `batch`.
pub(super) fn decode_chunk<D: Decode>(
    header: &ChunkHeader,
    stored: &[u8],
    buffer: &mut Vec<u8>,
    zstd: &mut Option<zstd::bulk::Decompressor<'static>>,
    decoder: &D,
    batch: &mut D::Batch,
) -> Ended {
    let mut rest = decompress(header, stored, buffer, zstd)?;
    while !rest.is_empty() {
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
    Ok(true)
}

/// The records of the chunk of `header` whose stored data is `stored`:
/// decompressed into `buffer` where compressed, its CRC (where the writer
/// gave one) checked before any record in it is parsed.
fn decompress<'a>(
    header: &ChunkHeader,
    stored: &'a [u8],
    buffer: &'a mut Vec<u8>,
    zstd: &mut Option<zstd::bulk::Decompressor<'static>>,
) -> Result<&'a [u8], String> {
    let h = header;
    if h.uncompressed_size > MAX_CHUNK {
        return Err(format!(
            "{} bytes decompressed, more than the {MAX_CHUNK} read",
            h.uncompressed_size
        ));
    }
    let size = h.uncompressed_size as usize;
    buffer.clear();
    let data: &[u8] = match h.compression.as_str() {
        "" => stored,
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
                .decompress_to_buffer(stored, buffer)
                .map_err(|e| format!("zstd: {e}"))?;
            buffer
        }
        "lz4" => {
            buffer.reserve(size);
            let mut decoder = lz4::Decoder::new(stored).map_err(|e| format!("lz4: {e}"))?;
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
    Ok(data)
}

/// The first record of `data`: (opcode, body, what follows).
#[inline]
pub(super) fn split_record(data: &[u8]) -> Result<(u8, &[u8], &[u8]), String> {
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
pub(super) fn message_fields(body: &[u8]) -> Result<(u16, u64, &[u8]), String> {
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

/// The wanted channels' messages, decoded.
impl Decode for Wanted {
    type Batch = Batch;

    fn message(&self, channel: u16, log_time: u64, data: &[u8], batch: &mut Batch) -> bool {
        decode(self, channel, log_time, data, batch);
        batch.undecodable.is_none()
    }
}

/// Whether `channel` is among `channels` (a list of one or two): a loop
/// the compiler inlines, where `slice::contains` on u16 calls its
/// out-of-line vector search once per message (4 % of `triad allan` on a
/// bag).
#[inline(always)]
#[allow(clippy::manual_contains)] // contains is the call this avoids
pub(crate) fn among(channels: &[u16], channel: u16) -> bool {
    channels.iter().any(|&c| c == channel)
}

/// Decodes the message `data` of channel `channel` into `batch` if it is wanted.
fn decode(wanted: &Wanted, channel: u16, log_time: u64, data: &[u8], batch: &mut Batch) {
    if among(&wanted.imu, channel) {
        match imu_msg::decode_cdr(data) {
            Ok(fields) => batch.messages.push(Decoded::Imu { fields, log_time }),
            Err(e) => {
                batch.undecodable = Some(Undecodable {
                    why: e.to_string(),
                    imu: true,
                })
            }
        }
    } else if among(&wanted.temperature, channel) {
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
        chunk_place(file, n).0
    }

    /// Of the `n`th chunk (from 1) of `file`: the middle byte of its
    /// compressed data, the byte after the chunk record, the log time of
    /// its first message.
    fn chunk_place(file: &[u8], n: usize) -> (usize, u64, u64) {
        let u64_at = |i: usize| u64::from_le_bytes(file[i..i + 8].try_into().unwrap());
        let mut at = 8; // the magic
        let mut seen = 0;
        loop {
            let (opcode, len) = (file[at], u64_at(at + 1));
            let body = at + 9;
            let end = body + len as usize;
            if opcode == op::CHUNK {
                seen += 1;
                if seen == n {
                    // start, end, uncompressed size, CRC, compression (u32 length + name), compressed size.
                    let name = u32::from_le_bytes(file[body + 28..body + 32].try_into().unwrap());
                    let data = body + 32 + name as usize + 8;
                    return ((data + end) / 2, end as u64, u64_at(body));
                }
            }
            at = end;
        }
    }

    /// Chunk records in `file`.
    fn chunk_count(file: &[u8]) -> usize {
        let mut at = 8;
        let mut seen = 0;
        while at + 9 <= file.len() {
            let len = u64::from_le_bytes(file[at + 1..at + 9].try_into().unwrap());
            seen += usize::from(file[at] == op::CHUNK);
            at += 9 + len as usize;
        }
        seen
    }

    /// Chunks sent to the workers in runs of several: a chunk broken in a
    /// later run gives every message of the chunks before it, in order,
    /// then the error naming that chunk (not the run).
    #[test]
    fn a_chunk_broken_inside_a_run_gives_the_messages_before_it_then_its_error() {
        // Uncompressed (so that the file's bytes are the runs' bytes), with
        // CRCs (so that the broken chunk gives none of its messages).
        let options = mcap::WriteOptions::new().compression(None);
        let good = file(16_000, options.chunk_size(Some(4096)));
        let chunks = chunk_count(&good);
        assert!(good.len() as u64 > 2 * RUN_BYTES, "{} bytes", good.len());
        let n = chunks * 2 / 3 + 1;
        let (middle, end, start_time) = chunk_place(&good, n);
        assert!(end > RUN_BYTES);
        let mut bad = good.clone();
        bad[middle] ^= 0x55;
        let path = std::env::temp_dir().join(format!("triad-mcap-runs-{}", std::process::id()));
        std::fs::write(&path, &bad).unwrap();
        let wanted = Wanted {
            imu: vec![1],
            temperature: vec![],
        };
        let mut given = Vec::new();
        let e = read(&path, "runs.mcap", &wanted, |batch| {
            given.extend(batch.messages.iter().map(|m| match m {
                Decoded::Imu { log_time, .. } => *log_time,
                Decoded::Temperature { .. } => u64::MAX,
            }));
            Ok(())
        })
        .unwrap_err()
        .to_string();
        let _ = std::fs::remove_file(&path);
        assert!(
            e.starts_with(&format!(
                "runs.mcap: broken MCAP: the chunk that ends at byte {end}: "
            )),
            "{e}"
        );
        // Every IMU message logged before the broken chunk's first message
        // (and the one at its time, which the chunk before may hold), in order.
        let want: Vec<u64> = (0..start_time / 10).map(|k| 10 * k).collect();
        assert!(
            given == want
                || given[..given.len() - 1] == want[..] && given.last() == Some(&start_time),
            "{} messages given, {} before the broken chunk",
            given.len(),
            want.len()
        );
    }

    /// A file without a summary (chunked, compressed or not, or not
    /// chunked): its schema and both channels, from the records in its chunks.
    #[test]
    fn definitions_are_found_in_chunks_and_outside_them() {
        let no_summary = || mcap::WriteOptions::new().emit_summary_records(false);
        for (what, options) in [
            ("zstd", no_summary().chunk_size(Some(4096))),
            ("none", no_summary().compression(None)),
            ("unchunked", no_summary().use_chunks(false)),
        ] {
            let path = std::env::temp_dir().join(format!(
                "triad-mcap-definitions-{}-{what}",
                std::process::id()
            ));
            std::fs::write(&path, file(50, options)).unwrap();
            let mut found = Vec::new();
            definitions(&path, what, |record| {
                found.push(match record {
                    Record::Schema { header, .. } => {
                        format!("schema {} {}", header.id, header.name)
                    }
                    Record::Channel(c) => format!("channel {} {} {}", c.id, c.topic, c.schema_id),
                    _ => "other".into(),
                });
                Ok(())
            })
            .unwrap();
            let _ = std::fs::remove_file(&path);
            found.dedup();
            assert_eq!(
                found,
                [
                    "schema 1 sensor_msgs/msg/Imu",
                    "channel 1 /imu 1",
                    "channel 2 /other 1"
                ],
                "{what}"
            );
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
