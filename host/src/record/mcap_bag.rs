//! MCAP (a ROS 2 bag's default storage, and what `triad convert` writes):
//! the `mcap` crate reads it, streaming; the topics come from its summary
//! (or, in a file without one, from a first pass), the samples from
//! sensor_msgs/msg/Imu in CDR on the chosen topic, with the temperature of a
//! sensor_msgs/msg/Temperature topic `TOPIC/temperature` beside it (as
//! `triad convert` writes) where there is one.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context};

use super::imu_msg::{self, ROS2_TYPE};
use super::producer::{spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// The largest decompressed chunk read.
const MAX_CHUNK: u64 = 256 << 20;

/// The type of the temperature topic read beside an IMU topic.
const TEMPERATURE_TYPE: &str = "sensor_msgs/msg/Temperature";

/// Opens the MCAP file at `path`, its IMU topic chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let all = topics_of(path, &name)?;
    let topic = topics::choose(
        &name,
        &all,
        options.record_topic.as_deref(),
        imu_msg::is_imu,
    )?;
    let time = options.record_time;
    let beside = format!("{topic}/temperature");
    let temperature = all
        .iter()
        .any(|(n, ty)| *n == beside && ty == TEMPERATURE_TYPE)
        .then_some(beside);
    let channels = Channels {
        temp: temperature.is_some(),
        ..Channels::IMU
    };
    let (path_, name_, topic_) = (path.to_path_buf(), name.clone(), topic.clone());
    let reader = spawn(&name, move |sink| {
        let topics = Topics {
            imu: &topic_,
            temperature: temperature.as_deref(),
        };
        read(&path_, &name_, topics, time, sink)
    });
    Ok(Opened {
        source: Source {
            name,
            format: Format::Mcap,
            channels,
            place: Place::Message,
            topic: Some(topic),
        },
        reader: Box::new(reader),
    })
}

/// The file's (topic, schema name) pairs.
fn topics_of(path: &Path, name: &str) -> anyhow::Result<Vec<(String, String)>> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    // SAFETY: the map is only read; a file changed under it while triad
    // reads is the user's race, as with any reader of a growing log.
    let map =
        unsafe { memmap2::Mmap::map(&file) }.with_context(|| format!("{name}: cannot map"))?;
    let mut pairs: Vec<(String, String)> = match mcap::Summary::read(&map) {
        Ok(Some(summary)) => summary.channels.values().map(|c| pair(c)).collect(),
        // No summary (a recorder stopped early, or a streamed file): a first pass.
        _ => scan(path, name)?,
    };
    pairs.sort();
    pairs.dedup();
    Ok(pairs)
}

/// (topic, schema name) of a channel.
fn pair(c: &mcap::Channel<'_>) -> (String, String) {
    let schema = c.schema.as_ref().map_or("", |s| s.name.as_str());
    (c.topic.clone(), schema.to_string())
}

/// Every channel's pair, from a pass over the whole file.
fn scan(path: &Path, name: &str) -> anyhow::Result<Vec<(String, String)>> {
    let (mut messages, offset) = messages(path, name)?;
    let mut pairs = Vec::new();
    for (count, m) in (&mut messages).enumerate() {
        let m = m.map_err(|e| broken(name, &offset, count as u64, e))?;
        let p = pair(&m.channel);
        if !pairs.contains(&p) {
            pairs.push(p);
        }
    }
    Ok(pairs)
}

/// A reader of the file counting the bytes it has read.
struct Counting<R> {
    inner: R,
    read: Arc<AtomicU64>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

type Messages = mcap::io::MessageReader<Counting<BufReader<File>>>;

/// The messages of the file and the count of bytes read so far.
fn messages(path: &Path, name: &str) -> anyhow::Result<(Messages, Arc<AtomicU64>)> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    // No record is longer than the file, nor a chunk's decompressed records
    // than 256 MiB (writers' chunks are a few MiB): a corrupt length is then
    // an error, not an allocation the size of the length. A chunk's CRC (where the
    // writer gave one) is checked before its records are parsed: the crate
    // trusts the lengths inside a chunk (mcap 0.26 overflows a subtraction
    // on a corrupt one).
    let len = file
        .metadata()
        .map(|m| m.len().max(MAX_CHUNK))
        .unwrap_or(u64::MAX);
    let options = mcap::sans_io::LinearReaderOptions::default()
        .with_record_length_limit(usize::try_from(len).unwrap_or(usize::MAX))
        .with_prevalidate_chunk_crcs(true);
    let read = Arc::new(AtomicU64::new(0));
    let counting = Counting {
        inner: BufReader::with_capacity(1 << 20, file),
        read: read.clone(),
    };
    Ok((
        mcap::io::MessageReader::new_with_options(counting, options),
        read,
    ))
}

/// The error of a file that broke after `count` messages.
fn broken(name: &str, offset: &AtomicU64, count: u64, e: mcap::McapError) -> anyhow::Error {
    anyhow!(
        "{name}: broken MCAP after {count} message(s), within its first {} bytes: {e}",
        offset.load(Ordering::Relaxed)
    )
}

/// The topics read.
#[derive(Clone, Copy)]
struct Topics<'a> {
    imu: &'a str,
    temperature: Option<&'a str>,
}

/// sensor_msgs/msg/Temperature.
#[derive(serde::Deserialize)]
struct Temperature {
    header: imu_msg::Header,
    temperature: f64,
    #[allow(dead_code)]
    variance: f64,
}

/// The stamp of a header in seconds.
fn stamp(h: &imu_msg::Header) -> f64 {
    imu_msg::stamp_seconds(h.stamp.sec as i64, h.stamp.nanosec)
}

/// Reads the samples of the IMU topic into `sink`, each with the
/// temperature of the same stamp when there is a temperature topic (whose
/// message must follow its sample before the next one, as triad writes them).
fn read(
    path: &Path,
    name: &str,
    topics: Topics<'_>,
    time: TimeSource,
    sink: &mut Sink,
) -> anyhow::Result<()> {
    let topic = topics.imu;
    let (mut messages, offset) = messages(path, name)?;
    let mut index = 0u64;
    let mut pending: Option<(Sample, f64)> = None;
    for (count, m) in (&mut messages).enumerate() {
        let m = m.map_err(|e| broken(name, &offset, count as u64, e))?;
        if Some(m.channel.topic.as_str()) == topics.temperature {
            let t: Temperature = cdr::deserialize(&m.data)
                .map_err(|e| anyhow!("{name}, message {} ({TEMPERATURE_TYPE}): {e}", count + 1))?;
            match pending.take() {
                Some((mut s, at)) if at == stamp(&t.header) => {
                    s.temp = t.temperature;
                    sink.push(s)?;
                }
                _ => bail!(
                    "{name}, message {}: a temperature at {} s without the IMU sample of that stamp before it",
                    count + 1,
                    stamp(&t.header)
                ),
            }
            continue;
        }
        if m.channel.topic != topic {
            continue;
        }
        if let Some((s, _)) = pending.take() {
            bail!(
                "{name}, message {} of {topic}: no temperature after it",
                s.at
            );
        }
        index += 1;
        if m.channel.message_encoding != "cdr" {
            bail!(
                "{name}: topic {topic} is encoded as `{}`, not ROS 2's cdr",
                m.channel.message_encoding
            );
        }
        let imu = imu_msg::decode_cdr(&m.data)
            .map_err(|e| anyhow!("{name}, message {index} of {topic} ({ROS2_TYPE}): {e}"))?;
        let t = match time {
            TimeSource::Header => stamp(&imu.header),
            TimeSource::Receive => imu_msg::nanoseconds_to_seconds(m.log_time as i128),
        };
        let mut s = Sample::at(index, t);
        s.gyro = imu.angular_velocity;
        s.accel = imu.linear_acceleration;
        match topics.temperature {
            Some(_) => pending = Some((s, stamp(&imu.header))),
            None => sink.push(s)?,
        }
    }
    if let Some((s, _)) = pending {
        bail!(
            "{name}, message {} of {topic}: no temperature after it",
            s.at
        );
    }
    Ok(())
}
