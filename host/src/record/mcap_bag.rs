//! MCAP (a ROS 2 bag's default storage, and what `triad convert` writes):
//! the `mcap` crate reads it, streaming; the channels come from its summary
//! (or, in a file without one, from a first pass over its schema and
//! channel records), the samples from
//! sensor_msgs/msg/Imu in CDR on the chosen topic ([`mcap_chunks`] decodes
//! the chunks on every core), with the temperature of a
//! sensor_msgs/msg/Temperature topic `TOPIC/temperature` beside it (as
//! `triad convert` writes) where there is one.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

use anyhow::{bail, Context};
use mcap::records::Record;

use super::imu_msg::{self, ROS2_TYPE};
use super::mcap_chunks::{self, Decoded, Wanted, MAX_CHUNK, TEMPERATURE_TYPE};
use super::producer::{self, spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// Opens the MCAP file at `path`, its IMU topic chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let Chosen {
        source,
        wanted,
        time,
    } = choose(path, options)?;
    let (path, name, topic) = (
        path.to_path_buf(),
        source.name.clone(),
        source.topic.clone().unwrap_or_default(),
    );
    let reader = spawn(&source.name, move |sink| {
        read(&path, &name, &topic, &wanted, time, sink)
    });
    Ok(Opened {
        source,
        reader: Box::new(reader),
    })
}

/// An MCAP's IMU topic, chosen: what its record is and where it comes from.
pub struct Chosen {
    /// The record (its topic always given).
    pub source: Source,
    /// The channels of the topic and of its temperature.
    pub wanted: Wanted,
    /// Which time a sample gets.
    pub time: TimeSource,
}

/// Finds the channels of the MCAP file at `path` and chooses its IMU topic
/// by `options`, without reading its messages.
pub fn choose(path: &Path, options: &Options) -> anyhow::Result<Chosen> {
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
    Ok(Chosen {
        source: Source {
            name,
            format: Format::Mcap,
            channels,
            place: Place::Message,
            topic: Some(topic),
        },
        wanted,
        time: options.record_time,
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

/// Every channel, from a pass over the whole file: its Schema and Channel
/// records, those in chunks included ([`mcap_chunks::definitions`], which
/// bounds every record by its chunk).
fn scan(path: &Path, name: &str) -> anyhow::Result<Vec<Channel>> {
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: Vec<(Channel, u16)> = Vec::new();
    mcap_chunks::definitions(path, name, |record| {
        match record {
            Record::Schema { header, .. } => {
                schemas.insert(header.id, header.name);
            }
            Record::Channel(c) if !channels.iter().any(|(known, _)| known.id == c.id) => {
                let channel = Channel {
                    id: c.id,
                    topic: c.topic,
                    schema: String::new(),
                    encoding: c.message_encoding,
                };
                channels.push((channel, c.schema_id));
            }
            _ => {}
        }
        Ok(())
    })?;
    // Schema 0 is none; a schema the file does not define names none either.
    Ok(channels
        .into_iter()
        .map(|(mut c, schema)| {
            c.schema = schemas.get(&schema).cloned().unwrap_or_default();
            c
        })
        .collect())
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
                        TimeSource::Receive => imu_msg::log_time_seconds(log_time),
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
