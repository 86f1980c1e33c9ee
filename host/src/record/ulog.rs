//! PX4 ULog, read with the `px4-ulog` crate's streaming parser: either
//! `sensor_combined` (gyro_rad, accelerometer_m_s2; its `timestamp` is the
//! gyro's sample time) or `sensor_accel` + `sensor_gyro` (instance 0; x, y,
//! z and temperature, which PX4's thermal calibration reads), each gyro
//! sample paired with the accel sample nearest in time and carrying the
//! gyro's temperature. Times are µs; `--time header` uses `timestamp_sample`
//! where the message has one, `--time receive` `timestamp`.

use std::cell::RefCell;
use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::Read;
use std::path::Path;

use anyhow::{anyhow, bail, Context};
use px4_ulog::stream_parser::model::{DataMessage, FieldParser};
use px4_ulog::stream_parser::LogParser;

use super::producer::{self, spawn, Sink};
use super::ulog_bounds::Bounds;
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// The two IMU choices of a ULog.
const COMBINED: &str = "sensor_combined";
const PAIR: &str = "sensor_accel+sensor_gyro";

/// Bytes of the data section looked at to list the messages a log has.
const LOOK_AHEAD: u64 = 16 << 20;

/// Opens the ULog at `path`, its IMU message chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let mut seen: Vec<String> = Vec::new();
    producer::guarded(&name, || {
        pass(path, &name, Some(LOOK_AHEAD), &mut |m| {
            let n = m.flattened_format.message_name();
            if !seen.iter().any(|s| s == n) {
                seen.push(n.to_string());
            }
        })
    })?;
    let mut pairs: Vec<(String, String)> = seen
        .iter()
        .filter(|n| *n != "sensor_accel" && *n != "sensor_gyro")
        .map(|n| (n.clone(), n.clone()))
        .collect();
    if seen.iter().any(|n| n == "sensor_accel") && seen.iter().any(|n| n == "sensor_gyro") {
        pairs.push((PAIR.to_string(), PAIR.to_string()));
    }
    pairs.sort();
    let topic = topics::choose(&name, &pairs, options.record_topic.as_deref(), |t| {
        t == COMBINED || t == PAIR
    })?;
    let channels = Channels {
        accel: true,
        gyro: true,
        temp: topic == PAIR,
    };
    let time = options.record_time;
    let (path_, name_, pair_) = (path.to_path_buf(), name.clone(), topic == PAIR);
    let reader = spawn(&name, move |sink| read(&path_, &name_, pair_, time, sink));
    Ok(Opened {
        source: Source {
            name,
            format: Format::ULog,
            channels,
            place: Place::Message,
            topic: Some(topic),
        },
        reader: Box::new(reader),
    })
}

/// Feeds the file (up to `limit` bytes of its data section) through the
/// parser, each data message to `on_data`; a broken or truncated file is an
/// error naming where. Each read is checked first for the bounds the
/// parser does not check ([`Bounds`]): it never sees a message that would
/// take it past its end.
fn pass(
    path: &Path,
    name: &str,
    limit: Option<u64>,
    on_data: &mut dyn FnMut(&DataMessage),
) -> anyhow::Result<()> {
    let mut file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let mut parser = LogParser::default();
    let mut callback = |m: &DataMessage| on_data(m);
    parser.set_data_message_callback(&mut callback);
    let mut buf = vec![0u8; 1 << 16];
    let mut bounds = Bounds::default();
    let (mut fed, mut data_start) = (0u64, None);
    loop {
        let n = match file.read(&mut buf) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                return Err(e).with_context(|| format!("{name}: cannot read after byte {fed}"))
            }
        };
        if n == 0 {
            break;
        }
        bounds.feed(&buf[..n]).map_err(|e| {
            anyhow!(
                "{name}: cannot read this ULog: at byte {}, {}",
                e.offset,
                e.reason
            )
        })?;
        parser.consume_bytes(&buf[..n]).map_err(|e| {
            anyhow!(
                "{name}: broken ULog within bytes {fed}..{}: {}",
                fed + n as u64,
                e.description
            )
        })?;
        fed += n as u64;
        if parser.in_data() && data_start.is_none() {
            data_start = Some(fed);
        }
        if let (Some(limit), Some(start)) = (limit, data_start) {
            if fed - start >= limit {
                return Ok(());
            }
        }
    }
    if !parser.in_data() {
        bail!("{name}: truncated ULog: its {fed} bytes end before the data section");
    }
    if parser.has_leftover() {
        bail!("{name}: truncated ULog: its {fed} bytes end inside a message");
    }
    Ok(())
}

/// The field parsers of one message format.
struct Fields {
    timestamp: FieldParser<u64>,
    sample_time: Option<FieldParser<u64>>,
    xyz: [FieldParser<f32>; 3],
    /// sensor_combined's second triad (the accelerometer).
    accel: Option<[FieldParser<f32>; 3]>,
    temp: Option<FieldParser<f32>>,
}

/// The parsers of `m`'s format, for the message kinds read.
fn fields(m: &DataMessage) -> Option<Fields> {
    let f = m.flattened_format;
    let p = |n: &str| f.get_field_parser::<f32>(n).ok();
    let xyz = |a: &str, b: &str, c: &str| Some([p(a)?, p(b)?, p(c)?]);
    let timestamp = f.get_field_parser::<u64>("timestamp").ok()?;
    match f.message_name() {
        COMBINED => Some(Fields {
            timestamp,
            sample_time: None,
            xyz: xyz("gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]")?,
            accel: Some(xyz(
                "accelerometer_m_s2[0]",
                "accelerometer_m_s2[1]",
                "accelerometer_m_s2[2]",
            )?),
            temp: None,
        }),
        "sensor_accel" | "sensor_gyro" => Some(Fields {
            timestamp,
            sample_time: f.get_field_parser::<u64>("timestamp_sample").ok(),
            xyz: xyz("x", "y", "z")?,
            accel: None,
            temp: p("temperature"),
        }),
        _ => None,
    }
}

/// One triad's reading from a message.
#[derive(Clone, Copy)]
struct Reading {
    t: f64,
    v: [f64; 3],
    temp: f64,
}

/// Reads the samples into `sink`.
fn read(
    path: &Path,
    name: &str,
    pair: bool,
    time: TimeSource,
    sink: &mut Sink,
) -> anyhow::Result<()> {
    let parsers: RefCell<HashMap<u16, Option<Fields>>> = RefCell::default();
    let state = RefCell::new(Aligner::default());
    let out: RefCell<Vec<Sample>> = RefCell::default();
    let mut index = 0u64;
    let mut on_data = |m: &DataMessage| {
        if m.multi_id.value() != 0 {
            return;
        }
        let kind = m.flattened_format.message_name();
        let wanted = if pair {
            kind == "sensor_accel" || kind == "sensor_gyro"
        } else {
            kind == COMBINED
        };
        if !wanted {
            return;
        }
        let mut parsers = parsers.borrow_mut();
        let Some(f) = parsers.entry(m.msg_id).or_insert_with(|| fields(m)) else {
            return;
        };
        let d = m.data;
        let stamp = match (&f.sample_time, time) {
            (Some(s), TimeSource::Header) => s.parse(d),
            _ => f.timestamp.parse(d),
        };
        let reading = Reading {
            t: stamp as f64 / 1e6,
            v: f.xyz.each_ref().map(|p| p.parse(d) as f64),
            temp: f.temp.as_ref().map_or(f64::NAN, |p| p.parse(d) as f64),
        };
        index += 1;
        match (&f.accel, kind) {
            (Some(a), _) => {
                let mut s = Sample::at(index, reading.t);
                s.gyro = reading.v;
                s.accel = a.each_ref().map(|p| p.parse(d) as f64);
                out.borrow_mut().push(s);
            }
            (None, "sensor_accel") => state.borrow_mut().accel(reading, &mut out.borrow_mut()),
            (None, _) => state
                .borrow_mut()
                .gyro(reading, index, &mut out.borrow_mut()),
        }
    };
    // The parse runs to the end; samples go to the sink as the callback makes them.
    let mut failure = None;
    let mut forward = |m: &DataMessage| {
        on_data(m);
        if failure.is_none() {
            for s in out.borrow_mut().drain(..) {
                if let Err(e) = sink.push(s) {
                    failure = Some(e);
                    break;
                }
            }
        }
    };
    pass(path, name, None, &mut forward)?;
    if let Some(e) = failure {
        return Err(e.into());
    }
    state.borrow_mut().finish(&mut out.borrow_mut());
    for s in out.borrow_mut().drain(..) {
        sink.push(s)?;
    }
    Ok(())
}

/// Pairs each gyro reading with the accel reading nearest in time.
#[derive(Default)]
struct Aligner {
    before: Option<Reading>,
    last: Option<Reading>,
    waiting: VecDeque<(Reading, u64)>,
}

impl Aligner {
    fn accel(&mut self, a: Reading, out: &mut Vec<Sample>) {
        self.before = self.last.replace(a);
        while let Some(&(g, at)) = self.waiting.front() {
            if g.t > a.t {
                break;
            }
            self.waiting.pop_front();
            out.push(self.paired(g, at));
        }
    }

    fn gyro(&mut self, g: Reading, at: u64, out: &mut Vec<Sample>) {
        match self.last {
            Some(a) if g.t <= a.t => out.push(self.paired(g, at)),
            _ => self.waiting.push_back((g, at)),
        }
    }

    /// The gyro readings after the last accel one: paired with it.
    fn finish(&mut self, out: &mut Vec<Sample>) {
        while let Some((g, at)) = self.waiting.pop_front() {
            if self.last.is_some() {
                out.push(self.paired(g, at));
            }
        }
    }

    fn paired(&self, g: Reading, at: u64) -> Sample {
        let a = match (self.before, self.last) {
            (Some(b), Some(l)) if (g.t - b.t).abs() < (g.t - l.t).abs() => b,
            (_, Some(l)) => l,
            (Some(b), None) => b,
            (None, None) => g,
        };
        let mut s = Sample::at(at, g.t);
        s.gyro = g.v;
        s.accel = a.v;
        s.temp = g.temp;
        s
    }
}
