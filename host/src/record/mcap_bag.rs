//! MCAP (a ROS 2 bag's default storage, and what `triad convert` writes):
//! the `mcap` crate reads it, streaming; the channels come from its summary
//! (or, in a file without one, from a first pass), the samples from
//! sensor_msgs/msg/Imu in CDR on the chosen topic ([`mcap_chunks`] decodes
//! the chunks on every core), with the temperature of a
//! sensor_msgs/msg/Temperature topic `TOPIC/temperature` beside it (as
//! `triad convert` writes) where there is one.

use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

use anyhow::{anyhow, bail, Context};

use super::imu_msg::{self, ROS2_TYPE};
use super::mcap_chunks::{self, Decoded, Wanted, MAX_CHUNK, TEMPERATURE_TYPE};
use super::producer::{self, spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// Opens the MCAP file at `path`, its IMU topic chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let in_file = channels_of(path, &name)?;
    let mut all: Vec<(String, String)> = in_file
        .iter()
        .map(|c| (c.topic.clone(), c.schema.clone()))
        .collect();
    all.sort();
    all.dedup();
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
    if let Some(c) = in_file
        .iter()
        .find(|c| c.topic == topic && c.encoding != "cdr")
    {
        bail!(
            "{name}: topic {topic} is encoded as `{}`, not ROS 2's cdr",
            c.encoding
        );
    }
    let ids = |t: Option<&str>| -> Vec<u16> {
        in_file
            .iter()
            .filter(|c| Some(c.topic.as_str()) == t)
            .map(|c| c.id)
            .collect()
    };
    let wanted = Wanted {
        imu: ids(Some(&topic)),
        temperature: ids(temperature.as_deref()),
    };
    let (path_, name_, topic_) = (path.to_path_buf(), name.clone(), topic.clone());
    let reader = spawn(&name, move |sink| {
        read(&path_, &name_, &topic_, &wanted, time, sink)
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

/// A channel of the file.
struct Channel {
    id: u16,
    topic: String,
    /// Its schema's name ("" without one).
    schema: String,
    encoding: String,
}

impl Channel {
    fn of(c: &mcap::Channel<'_>) -> Channel {
        Channel {
            id: c.id,
            topic: c.topic.clone(),
            schema: c
                .schema
                .as_ref()
                .map_or("", |s| s.name.as_str())
                .to_string(),
            encoding: c.message_encoding.clone(),
        }
    }
}

/// The file's channels, from its summary (read with buffered reads and
/// seeks), else from a pass over the whole file.
fn channels_of(path: &Path, name: &str) -> anyhow::Result<Vec<Channel>> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let len = file.metadata().map_or(u64::MAX, |m| m.len());
    let options = mcap::sans_io::SummaryReaderOptions::default()
        .with_file_size(len)
        .with_record_length_limit(usize::try_from(len.min(MAX_CHUNK)).unwrap_or(usize::MAX));
    let mut summary = mcap::sans_io::SummaryReader::new_with_options(options);
    let mut file = BufReader::new(file);
    let mut read = || -> mcap::McapResult<Option<mcap::Summary>> {
        while let Some(event) = summary.next_event() {
            match event? {
                mcap::sans_io::SummaryReadEvent::ReadRequest(n) => {
                    let got = file.read(summary.insert(n))?;
                    summary.notify_read(got);
                }
                mcap::sans_io::SummaryReadEvent::SeekRequest(to) => {
                    let at = file.seek(to)?;
                    summary.notify_seeked(at);
                }
            }
        }
        Ok(None)
    };
    // A missing or unreadable summary (a recorder stopped early, a streamed
    // file): the first pass finds the channels, or where the file breaks.
    let found = read().ok().and_then(|_| summary.finish());
    match found {
        Some(s) if !s.channels.is_empty() => {
            Ok(s.channels.values().map(|c| Channel::of(c)).collect())
        }
        _ => producer::guarded(name, || scan(path, name)),
    }
}

/// Every channel, from a pass over the whole file.
fn scan(path: &Path, name: &str) -> anyhow::Result<Vec<Channel>> {
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let len = file.metadata().map_or(u64::MAX, |m| m.len());
    // No record is longer than the file, nor a chunk's decompressed records
    // than MAX_CHUNK; a chunk's CRC (where the writer gave one) is checked
    // before its records are parsed: the crate trusts the lengths inside a
    // chunk (mcap 0.26 overflows a subtraction on a corrupt one).
    let options = mcap::sans_io::LinearReaderOptions::default()
        .with_record_length_limit(usize::try_from(len.max(MAX_CHUNK)).unwrap_or(usize::MAX))
        .with_prevalidate_chunk_crcs(true);
    let mut file = BufReader::with_capacity(1 << 20, file);
    let mut reader = mcap::sans_io::MessageReader::new_with_options(options);
    let (mut channels, mut count, mut offset) = (Vec::<Channel>::new(), 0u64, 0u64);
    while let Some(event) = reader.next_event() {
        let broken = |e: &dyn std::fmt::Display| {
            anyhow!("{name}: broken MCAP after {count} message(s), within its first {offset} bytes: {e}")
        };
        match event.map_err(|e| broken(&e))? {
            mcap::sans_io::MessageReadEvent::ReadRequest(need) => {
                let into = reader.insert(mcap_chunks::read_size(need, offset, len));
                let n = loop {
                    match file.read(into) {
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                        n => break n.map_err(|e| broken(&e))?,
                    }
                };
                reader.notify_read(n);
                offset += n as u64;
            }
            mcap::sans_io::MessageReadEvent::Message(m) => {
                count += 1;
                if !channels.iter().any(|c| c.id == m.channel.id) {
                    channels.push(Channel::of(&m.channel));
                }
            }
        }
    }
    Ok(channels)
}

/// Reads the samples of the IMU topic into `sink`, each with the
/// temperature of the same stamp when there is a temperature topic (whose
/// message must follow its sample before the next one, as triad writes them).
fn read(
    path: &Path,
    name: &str,
    topic: &str,
    wanted: &Wanted,
    time: TimeSource,
    sink: &mut Sink,
) -> anyhow::Result<()> {
    let with_temperature = !wanted.temperature.is_empty();
    let mut index = 0u64;
    let mut pending: Option<(Sample, f64)> = None;
    mcap_chunks::read(path, name, wanted, |batch| {
        for m in batch.messages {
            match m {
                Decoded::Temperature { stamp, celsius } => {
                    let at = imu_msg::stamp_seconds(stamp.sec as i64, stamp.nanosec);
                    match pending.take() {
                        Some((mut s, t)) if t == at => {
                            s.temp = celsius;
                            sink.push(s)?;
                        }
                        _ => bail!(
                            "{name}, after message {index} of {topic}: a temperature at {at} s without the IMU sample of that stamp before it"
                        ),
                    }
                }
                Decoded::Imu { fields, log_time } => {
                    if let Some((s, _)) = pending.take() {
                        bail!(
                            "{name}, message {} of {topic}: no temperature after it",
                            s.at
                        );
                    }
                    index += 1;
                    let stamp =
                        imu_msg::stamp_seconds(fields.stamp.sec as i64, fields.stamp.nanosec);
                    let t = match time {
                        TimeSource::Header => stamp,
                        TimeSource::Receive => imu_msg::nanoseconds_to_seconds(log_time as i128),
                    };
                    let mut s = Sample::at(index, t);
                    s.gyro = fields.angular_velocity;
                    s.accel = fields.linear_acceleration;
                    if with_temperature {
                        pending = Some((s, stamp));
                    } else {
                        sink.push(s)?;
                    }
                }
            }
        }
        match batch.undecodable {
            Some(u) if u.imu => bail!(
                "{name}, message {} of {topic} ({ROS2_TYPE}): {}",
                index + 1,
                u.why
            ),
            Some(u) => bail!(
                "{name}, after message {index} of {topic}: {TEMPERATURE_TYPE}: {}",
                u.why
            ),
            None => Ok(()),
        }
    })?;
    if let Some((s, _)) = pending {
        bail!(
            "{name}, message {} of {topic}: no temperature after it",
            s.at
        );
    }
    Ok(())
}
