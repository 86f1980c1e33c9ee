//! A ROS 1 bag (format 2.0; wiki.ros.org/Bags/Format/2.0): the connections
//! from its index section, the messages of the chosen topic's connections
//! from its chunks (bz2 and lz4 as well as plain), sensor_msgs/Imu in ROS 1's
//! serialisation ([`imu_msg::decode_ros1`]).
//!
//! Read here through a buffered file, record by record ([`records`]), not
//! with the `rosbag` crate: its only constructor maps the file into memory,
//! and a mapped file that shrinks while it is read (a bag still being
//! copied or rewritten) kills the process with SIGBUS, where a read gives an
//! error naming the byte; the crate also slices its map at the header's
//! index position unchecked. The format is four record kinds in one
//! framing; the chunks' compression is the `bzip2` and `lz4` crates'.

mod records;

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use anyhow::{anyhow, bail, Context};

use self::records::{text_field, time_field, u32_field, u64_field, Record, Records};
use super::imu_msg::{self, ROS1_TYPE};
use super::producer::{spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// The version line every bag 2.0 opens with.
const VERSION: &[u8; 13] = b"#ROSBAG V2.0\n";

/// Record kinds (the `op` field).
const OP_MESSAGE_DATA: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_CHUNK: u8 = 0x05;
const OP_CONNECTION: u8 = 0x07;

/// Opens the ROS 1 bag at `path`, its IMU topic chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let conns = connections(path, &name)?;
    let pairs: Vec<(String, String)> = {
        let mut p: Vec<(String, String)> =
            conns.iter().map(|c| (c.1.clone(), c.2.clone())).collect();
        p.sort();
        p.dedup();
        p
    };
    let topic = topics::choose(
        &name,
        &pairs,
        options.record_topic.as_deref(),
        imu_msg::is_imu,
    )?;
    let ids: Vec<u32> = conns.iter().filter(|c| c.1 == topic).map(|c| c.0).collect();
    let time = options.record_time;
    let (path_, name_, topic_) = (path.to_path_buf(), name.clone(), topic.clone());
    let reader = spawn(&name, move |sink| {
        read(&path_, &name_, &topic_, &ids, time, sink)
    });
    Ok(Opened {
        source: Source {
            name,
            format: Format::Ros1Bag,
            channels: Channels::IMU,
            place: Place::Message,
            topic: Some(topic),
        },
        reader: Box::new(reader),
    })
}

/// An open bag: where its chunks and its index lie.
struct Bag {
    file: BufReader<File>,
    /// The file's length.
    len: u64,
    /// The first record after the bag header.
    chunks_at: u64,
    /// The index section (connections, chunk infos) to the end.
    index_at: u64,
}

/// Opens the bag at `path`: its version line and header record, its index
/// position checked against its length.
fn bag(path: &Path, name: &str) -> anyhow::Result<Bag> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let len = file
        .metadata()
        .with_context(|| format!("{name}: cannot read"))?
        .len();
    let mut file = BufReader::with_capacity(1 << 16, file);
    let mut version = [0u8; 13];
    file.read_exact(&mut version)
        .ok()
        .filter(|_| &version == VERSION)
        .ok_or_else(|| anyhow!("{name}: not a ROS 1 bag of format 2.0 (no `#ROSBAG V2.0` line)"))?;
    let mut records = Records::new(&mut file, 13, len);
    let mut header = Record::default();
    let index_at = records
        .next_into(&mut header)
        .and_then(|more| {
            if more {
                header.op()
            } else {
                Err("it is missing".into())
            }
        })
        .and_then(|op| {
            if op == OP_BAG_HEADER {
                u64_field(&header.header, "index_pos")
            } else {
                Err(format!(
                    "its op is {op:#04x}, not the bag header's {OP_BAG_HEADER:#04x}"
                ))
            }
        })
        .map_err(|e| anyhow!("{name}: the bag header (at byte 13) is broken: {e}"))?;
    if index_at == 0 {
        bail!("{name}: the bag has no index (its recording did not finish): run `rosbag reindex` on it");
    }
    if index_at > len {
        bail!(
            "{name}: truncated: the index should start at byte {index_at} but the file has {len} bytes (run `rosbag reindex` on it)"
        );
    }
    let chunks_at = 13 + 8 + header.header.len() as u64 + header.data.len() as u64;
    Ok(Bag {
        file,
        len,
        chunks_at,
        index_at,
    })
}

/// A connection: (id, topic, type).
type Connection = (u32, String, String);

/// Every connection of the bag, from its index section.
fn connections(path: &Path, name: &str) -> anyhow::Result<Vec<Connection>> {
    let mut bag = bag(path, name)?;
    bag.file
        .seek(SeekFrom::Start(bag.index_at))
        .with_context(|| format!("{name}: cannot read"))?;
    let mut records = Records::new(&mut bag.file, bag.index_at, bag.len);
    let mut r = Record::default();
    let mut conns = Vec::new();
    for k in 1.. {
        let broken = |r: &Record, e: String| {
            anyhow!(
                "{name}: broken index at its record {k} (byte {}): {e}",
                r.offset
            )
        };
        if !records.next_into(&mut r).map_err(|e| broken(&r, e))? {
            break;
        }
        if r.op().map_err(|e| broken(&r, e))? != OP_CONNECTION {
            continue;
        }
        let conn = (|| {
            Ok::<_, String>((
                u32_field(&r.header, "conn")?,
                text_field(&r.header, "topic")?.to_string(),
                text_field(&r.data, "type")?.to_string(),
            ))
        })()
        .map_err(|e| broken(&r, format!("a connection record: {e}")))?;
        conns.push(conn);
    }
    Ok(conns)
}

/// Reads the messages of the connections `ids` into `sink`.
fn read(
    path: &Path,
    name: &str,
    topic: &str,
    ids: &[u32],
    time: TimeSource,
    sink: &mut Sink,
) -> anyhow::Result<()> {
    let mut bag = bag(path, name)?;
    bag.file
        .seek(SeekFrom::Start(bag.chunks_at))
        .with_context(|| format!("{name}: cannot read"))?;
    let mut records = Records::new(&mut bag.file, bag.chunks_at, bag.index_at);
    let (mut r, mut inner, mut plain) = (Record::default(), Record::default(), Vec::new());
    let mut index = 0u64;
    for c in 1u64.. {
        let broken = |at: u64, index: u64, e: String| {
            anyhow!(
                "{name}: broken at byte {at} (chunk {c}, after message {index} of {topic}): {e}"
            )
        };
        if !records
            .next_into(&mut r)
            .map_err(|e| broken(r.offset, index, e))?
        {
            break;
        }
        if r.op().map_err(|e| broken(r.offset, index, e))? != OP_CHUNK {
            continue;
        }
        decompress(&r, &mut plain).map_err(|e| broken(r.offset, index, e))?;
        // Offsets inside a chunk are named from the file's, at the chunk's data.
        let data_at = r.offset + 8 + r.header.len() as u64;
        let mut messages = Records::new(&plain[..], 0, plain.len() as u64);
        while messages
            .next_into(&mut inner)
            .map_err(|e| broken(data_at, index, format!("in its data: {e}")))?
        {
            let (seen, offset) = (index, inner.offset);
            let at = move |e: String| {
                broken(
                    data_at,
                    seen,
                    format!("its record at byte {offset} of its data: {e}"),
                )
            };
            if inner.op().map_err(at)? != OP_MESSAGE_DATA {
                continue;
            }
            if !ids.contains(&u32_field(&inner.header, "conn").map_err(at)?) {
                continue;
            }
            index += 1;
            let (stamp, gyro, accel) = imu_msg::decode_ros1(&inner.data)
                .map_err(|e| anyhow!("{name}, message {index} of {topic} ({ROS1_TYPE}): {e}"))?;
            let t = match time {
                TimeSource::Header => stamp,
                TimeSource::Receive => imu_msg::nanoseconds_to_seconds(
                    time_field(&inner.header, "time").map_err(at)? as i128,
                ),
            };
            let mut s = Sample::at(index, t);
            s.gyro = gyro;
            s.accel = accel;
            sink.push(s)?;
        }
    }
    Ok(())
}

/// The chunk record `r`'s data, decompressed into `plain` (its `size` checked).
fn decompress(r: &Record, plain: &mut Vec<u8>) -> Result<(), String> {
    let size = u32_field(&r.header, "size")? as u64;
    let compression = text_field(&r.header, "compression")?;
    plain.clear();
    // One byte more than the size allows, so that a longer stream shows.
    let read = match compression {
        "none" => {
            plain.extend_from_slice(&r.data);
            Ok(())
        }
        "bz2" => bzip2::read::BzDecoder::new(&r.data[..])
            .take(size + 1)
            .read_to_end(plain)
            .map(drop),
        "lz4" => lz4::Decoder::new(&r.data[..])
            .and_then(|d| d.take(size + 1).read_to_end(plain))
            .map(drop),
        other => return Err(format!("its compression `{other}` is not none, bz2 or lz4")),
    };
    read.map_err(|e| format!("its {compression} data do not decompress: {e}"))?;
    if plain.len() as u64 != size {
        return Err(format!(
            "its data decompress to {} bytes where its header says {size}",
            plain.len()
        ));
    }
    Ok(())
}
