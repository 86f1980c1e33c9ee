//! A ROS 1 bag (format 2.0), read with the `rosbag` crate: the connections
//! from its index, the messages of the chosen topic's connections from its
//! chunks (bz2 and lz4 as well as plain), sensor_msgs/Imu in ROS 1's
//! serialisation ([`imu_msg::decode_ros1`]).
//!
//! The crate slices its mapped file at the index position the bag header
//! gives; a bag cut short (or still being recorded: index position 0) would
//! make it panic, so that position is checked here first ([`index_pos`]).

use std::path::Path;

use anyhow::{anyhow, bail, Context};
use rosbag::{ChunkRecord, IndexRecord, MessageRecord, RosBag};

use super::imu_msg::{self, ROS1_TYPE};
use super::producer::{spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

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

/// The bag, its index position checked against its length.
fn bag(path: &Path, name: &str) -> anyhow::Result<RosBag> {
    let head = {
        use std::io::Read;
        let mut head = Vec::new();
        std::fs::File::open(path)
            .with_context(|| format!("{name}: cannot open"))?
            .take(4096)
            .read_to_end(&mut head)
            .with_context(|| format!("{name}: cannot read"))?;
        head
    };
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let pos =
        index_pos(&head).ok_or_else(|| anyhow!("{name}: the bag header (at byte 13) is broken"))?;
    if pos == 0 {
        bail!("{name}: the bag has no index (its recording did not finish): run `rosbag reindex` on it");
    }
    if pos > len {
        bail!(
            "{name}: truncated: the index should start at byte {pos} but the file has {len} bytes (run `rosbag reindex` on it)"
        );
    }
    RosBag::new(path).with_context(|| format!("{name}: not a readable ROS 1 bag"))
}

/// The `index_pos` field of the bag header record that follows the
/// 13-byte version line: fields of (u32 length, `name=value`).
fn index_pos(head: &[u8]) -> Option<u64> {
    let u32_at = |at: usize| {
        head.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let header_len = u32_at(13)?;
    let (mut at, end) = (17, 17 + header_len);
    while at + 4 <= end {
        let len = u32_at(at)?;
        let field = head.get(at + 4..at + 4 + len)?;
        if let Some(value) = field.strip_prefix(b"index_pos=") {
            return Some(u64::from_le_bytes(value.try_into().ok()?));
        }
        at += 4 + len;
    }
    None
}

/// A connection: (id, topic, type).
type Connection = (u32, String, String);

/// Every connection of the bag.
fn connections(path: &Path, name: &str) -> anyhow::Result<Vec<Connection>> {
    let bag = bag(path, name)?;
    let mut conns = Vec::new();
    for (k, record) in bag.index_records().enumerate() {
        match record.map_err(|e| anyhow!("{name}: broken index at its record {}: {e}", k + 1))? {
            IndexRecord::Connection(c) => conns.push((c.id, c.topic.to_string(), c.tp.to_string())),
            IndexRecord::IndexData(_) | IndexRecord::ChunkInfo(_) => {}
        }
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
    let bag = bag(path, name)?;
    let mut index = 0u64;
    for (c, record) in bag.chunk_records().enumerate() {
        let broken = |index: u64, e: rosbag::Error| {
            anyhow!(
                "{name}: broken at chunk {} (after message {index} of {topic}): {e}",
                c + 1
            )
        };
        let ChunkRecord::Chunk(chunk) = record.map_err(|e| broken(index, e))? else {
            continue;
        };
        for m in chunk.messages() {
            let MessageRecord::MessageData(m) = m.map_err(|e| broken(index, e))? else {
                continue;
            };
            if !ids.contains(&m.conn_id) {
                continue;
            }
            index += 1;
            let (stamp, gyro, accel) = imu_msg::decode_ros1(m.data)
                .map_err(|e| anyhow!("{name}, message {index} of {topic} ({ROS1_TYPE}): {e}"))?;
            let t = match time {
                TimeSource::Header => stamp,
                // The record time, in nanoseconds as the crate gives it.
                TimeSource::Receive => imu_msg::nanoseconds_to_seconds(m.time as i128),
            };
            let mut s = Sample::at(index, t);
            s.gyro = gyro;
            s.accel = accel;
            sink.push(s)?;
        }
    }
    Ok(())
}
