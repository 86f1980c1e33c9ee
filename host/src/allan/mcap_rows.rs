//! The rows of an MCAP bag's IMU topic, made where its chunks are decoded:
//! each chunk worker ([`mcap_chunks`], a run of chunks at a time) turns its sensor_msgs/msg/Imu
//! messages straight into rows of the values a layout wants (the CSV row
//! `t,ax,ay,az,gx,gy,gz` of each sample, as [`record_rows`](super::record_rows)
//! takes it) and checks them (values in range, time increasing within the
//! run); the reading thread checks, in the file's order, the time from
//! one run to the next and hands each run's rows on whole; the Allan
//! side checks the t column's step as each block arrives. The same values
//! and checks as the record's samples through `record_rows`, so the same
//! results and errors, with no sample made and no row copied between the
//! decoding and the sums (and one thread fewer in between). A bag with a temperature topic beside its IMU
//! one is read through `record_rows` (the generic reader pairs the two).

use std::path::Path;
use std::sync::mpsc::SyncSender;

use anyhow::{anyhow, bail};

use crate::record::imu_msg::{self, ROS2_TYPE};
use crate::record::mcap_bag::{self, Chosen};
use crate::record::mcap_chunks::{self, Decode};
use crate::record::producer::{self, Fed};
use crate::record::{self, to_csv, Format, Sample, Source, TimeSource};

use super::columns::Layout;
use super::rows::{in_range, RowSource, MAX_MAGNITUDE};
use super::time::TimeCheck;

/// Blocks (a run of chunks' rows each) queued between the reading thread and the Allan threads.
const QUEUED: usize = 4;

/// An MCAP whose IMU topic is read this way: its CSV header, once a layout is known its rows.
pub(crate) struct Opened {
    /// The header of the CSV it converts to.
    pub(crate) header: String,
    /// Its name in messages (with its format).
    pub(crate) name: String,
    path: std::path::PathBuf,
    chosen: Chosen,
}

/// The MCAP at `path` when its IMU topic is read this way (None: not an
/// MCAP file, or one with a temperature topic beside its IMU one).
pub(crate) fn open(path: &Path) -> anyhow::Result<Option<Opened>> {
    if crate::plumbing::input::is_stdin(path) || !path.is_file() {
        return Ok(None);
    }
    if record::detect::detect(path)? != Format::Mcap {
        return Ok(None);
    }
    let chosen = mcap_bag::choose(path, &record::options::global())?;
    if !chosen.wanted.temperature.is_empty() {
        return Ok(None);
    }
    let source = &chosen.source;
    Ok(Some(Opened {
        header: to_csv::header(source.channels),
        name: format!("{} ({})", source.name, source.format.name()),
        path: path.to_path_buf(),
        chosen,
    }))
}

/// What a chunk worker makes of the IMU messages: rows of `width` values,
/// cell `c` of a sample's CSV row at slot `s` for each `(c, s)` of `cells`.
struct ImuRows {
    imu: Vec<u16>,
    time: TimeSource,
    cells: Vec<(usize, usize)>,
    /// The cell of each slot of a row, in the row's order.
    slots: Vec<usize>,
    /// Whether each cell of the CSV row is taken.
    taken: [bool; 7],
    width: usize,
    /// The record, for [`record::time::check`].
    source: Source,
}

/// A run of chunks' rows, up to the message that stops them.
#[derive(Default)]
struct Block {
    rows: Vec<f64>,
    /// The time of the run's first IMU message that decoded (its place
    /// in time is checked in the file's order, against the run before).
    first_t: Option<f64>,
    /// The time of its last row.
    last_t: f64,
    /// Why the rows stop before the run's end: at the message after them.
    fault: Option<Fault>,
}

/// What is wrong with the message after a block's rows.
enum Fault {
    /// Its time, `t`, fails [`record::time::check`] after `previous`.
    Time { t: f64, previous: f64 },
    /// The value at `slot` is out of range ([`in_range`]).
    Range { t: f64, slot: usize, value: f64 },
    /// It does not decode, for this reason.
    Undecodable(String),
}

/// The fewest bytes an IMU message that decodes takes in a chunk: the
/// record's opcode and length (9), its header (22), and the CDR of
/// sensor_msgs/msg/Imu with an empty frame_id (encapsulation 4, stamp 8,
/// the frame_id's length 4 and its bytes padded to 8, then 37 f64s: 316).
const SMALLEST_IMU_RECORD: usize = 9 + 22 + 316;

impl Decode for ImuRows {
    type Batch = Block;

    /// Room for as many rows as the run can hold IMU messages: no copy as they come.
    fn batch(&self, bytes: usize) -> Block {
        Block {
            rows: Vec::with_capacity((bytes / SMALLEST_IMU_RECORD + 1) * self.width),
            ..Block::default()
        }
    }

    fn message(&self, channel: u16, log_time: u64, data: &[u8], b: &mut Block) -> bool {
        if !mcap_chunks::among(&self.imu, channel) {
            return true;
        }
        let fields = match imu_msg::decode_cdr(data) {
            Ok(fields) => fields,
            Err(e) => {
                b.fault = Some(Fault::Undecodable(e.to_string()));
                return false;
            }
        };
        let t = match self.time {
            TimeSource::Header => {
                imu_msg::stamp_seconds(fields.stamp.sec as i64, fields.stamp.nanosec)
            }
            TimeSource::Receive => imu_msg::log_time_seconds(log_time),
        };
        if b.first_t.is_none() {
            b.first_t = Some(t);
        } else if !(t.is_finite() && t > b.last_t) {
            // What record::time::check refuses (it words the error, in order).
            b.fault = Some(Fault::Time {
                t,
                previous: b.last_t,
            });
            return false;
        }
        let (a, g) = (fields.linear_acceleration, fields.angular_velocity);
        let csv = [t, a[0], a[1], a[2], g[0], g[1], g[2]];
        // NaN and ±inf fail the comparison too. The cells taken, tested all
        // at once; where one fails, the first in the CSV's order is named.
        let within = |v: f64| v.abs() <= MAX_MAGNITUDE;
        let out_of_range = (0..7).any(|c| self.taken[c] & !within(csv[c]));
        if out_of_range {
            if let Some(&(cell, slot)) = self.cells.iter().find(|&&(cell, _)| !within(csv[cell])) {
                let value = csv[cell];
                b.fault = Some(Fault::Range { t, slot, value });
                return false;
            }
        }
        // One value at a time, in the row's order: each stored from a register.
        for &cell in &self.slots {
            b.rows.push(csv[cell]);
        }
        b.last_t = t;
        true
    }
}

/// The cell of the CSV row that goes to each slot of a row of `layout`.
fn slot_cells(layout: &Layout) -> Vec<usize> {
    let mut slots = vec![0; layout.width()];
    for &(cell, slot) in &layout.cells {
        slots[slot] = cell;
    }
    slots
}

/// The rows of an MCAP's IMU topic, read on threads of their own.
pub(crate) struct McapRows {
    source: Source,
    /// The reading thread's blocks.
    blocks: Fed<Vec<f64>>,
    width: usize,
    t_slot: Option<usize>,
    /// The block at hand, and its rows served one at a time so far.
    block: Vec<f64>,
    served: usize,
    /// Rows received so far.
    received: u64,
    time: Option<TimeCheck>,
}

impl McapRows {
    /// The rows of `opened` as `layout` reads them; the reading starts here.
    pub(crate) fn new(opened: Opened, layout: &Layout) -> McapRows {
        let Chosen {
            source,
            wanted,
            time,
        } = opened.chosen;
        let decoder = ImuRows {
            imu: wanted.imu,
            time,
            cells: layout.cells.clone(),
            slots: slot_cells(layout),
            taken: std::array::from_fn(|c| layout.cells.iter().any(|&(cell, _)| cell == c)),
            width: layout.width(),
            source: source.clone(),
        };
        let path = opened.path;
        let names = layout.names.clone();
        let blocks = producer::feed(&source.name, QUEUED, move |tx| {
            read(&path, &decoder, &names, tx)
        });
        McapRows {
            source,
            blocks,
            width: layout.width(),
            t_slot: layout.t_slot,
            block: Vec::new(),
            served: 0,
            received: 0,
            time: None,
        }
    }

    /// The next block from the reading thread, its t column checked; None at the end.
    fn receive(&mut self) -> anyhow::Result<Option<Vec<f64>>> {
        let Some(block) = self.blocks.take()? else {
            return Ok(None);
        };
        if let Some(slot) = self.t_slot {
            for (i, row) in block.chunks_exact(self.width).enumerate() {
                let t = row[slot];
                match &mut self.time {
                    None => self.time = Some(TimeCheck::new(t)),
                    Some(tc) => {
                        let at = self.received + i as u64 + 1;
                        tc.next_at(t, || self.source.where_is(&Sample::at(at, t)))?
                    }
                }
            }
        }
        self.received += (block.len() / self.width) as u64;
        Ok(Some(block))
    }
}

/// The reading thread: the runs' rows in the file's order, the time
/// from one run to the next checked, each block sent whole; a fault's
/// error after the rows before it.
fn read(
    path: &Path,
    decoder: &ImuRows,
    names: &[String],
    tx: &SyncSender<anyhow::Result<Vec<f64>>>,
) -> anyhow::Result<()> {
    let source = &decoder.source;
    let name = &source.name;
    let topic = source.topic.as_deref().unwrap_or_default();
    let mut before = 0u64;
    let mut last: Option<f64> = None;
    mcap_chunks::read(path, name, decoder, |b: Block| {
        let rows = (b.rows.len() / decoder.width) as u64;
        if let Some(t) = b.first_t {
            record::time::check(source, last, &Sample::at(before + 1, t))?;
        }
        if rows > 0 {
            last = Some(b.last_t);
            tx.send(Ok(b.rows))
                .map_err(|_| anyhow!("the Allan threads stopped"))?;
        }
        before += rows;
        let at = before + 1;
        match b.fault {
            None => Ok(()),
            Some(Fault::Time { t, previous }) => {
                record::time::check(source, Some(previous), &Sample::at(at, t))?;
                bail!("{name}, message {at} of {topic}: its time {t} s failed a check that passes here")
            }
            Some(Fault::Range { t, slot, value }) => {
                let why = in_range(value).err().unwrap_or_default();
                bail!(
                    "{}, column {}: {why}",
                    source.where_is(&Sample::at(at, t)),
                    names[slot]
                )
            }
            Some(Fault::Undecodable(why)) => {
                bail!("{name}, message {at} of {topic} ({ROS2_TYPE}): {why}")
            }
        }
    })
}

impl RowSource for McapRows {
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        while self.served * self.width == self.block.len() {
            match self.receive()? {
                Some(block) => (self.block, self.served) = (block, 0),
                None => return Ok(false),
            }
        }
        let at = self.served * self.width;
        values.copy_from_slice(&self.block[at..at + self.width]);
        self.served += 1;
        Ok(true)
    }

    /// Each run's rows as they come (the rest of one partly served first).
    fn next_block(&mut self) -> anyhow::Result<Option<Vec<f64>>> {
        let rest = self.block.split_off(self.served * self.width);
        self.served = 0;
        self.block.clear();
        if !rest.is_empty() {
            return Ok(Some(rest));
        }
        self.receive()
    }

    const READS_AHEAD: bool = true;

    fn width(&self) -> usize {
        self.width
    }

    fn time(&self) -> Option<&TimeCheck> {
        self.time.as_ref()
    }

    fn bytes(&self) -> u64 {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::record_rows::{self, RecordRows};
    use crate::record::imu_msg::{encode_cdr, Header, Imu};

    /// `n` samples at 100 Hz as an MCAP of uncompressed chunks of 756
    /// messages, `spoil` changing them first; its path.
    fn bag(name: &str, n: u64, spoil: impl Fn(&mut [Sample])) -> std::path::PathBuf {
        let mut samples: Vec<Sample> = (1..=n)
            .map(|k| {
                let mut s = Sample::at(k, 1000.0 + k as f64 * 0.01);
                s.accel = [k as f64 * 1e-3, 0.5, 9.8];
                s.gyro = [0.1, -(k as f64) * 1e-4, 0.0];
                s
            })
            .collect();
        spoil(&mut samples);
        let path = std::env::temp_dir().join(format!(
            "triad-mcap-rows-{}-{name}.mcap",
            std::process::id()
        ));
        let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .chunk_size(Some(256 << 10))
            .create(file)
            .unwrap();
        let schema = w.add_schema(ROS2_TYPE, "ros2msg", b"").unwrap();
        let imu = w
            .add_channel(schema, "/imu", "cdr", &Default::default())
            .unwrap();
        for s in &samples {
            let msg = Imu {
                header: Header {
                    stamp: imu_msg::stamp_of(s.t),
                    frame_id: "imu".into(),
                },
                angular_velocity: s.gyro,
                linear_acceleration: s.accel,
                ..Imu::default()
            };
            let header = mcap::records::MessageHeader {
                channel_id: imu,
                sequence: s.at as u32,
                log_time: (s.t * 1e9) as u64,
                publish_time: 0,
            };
            w.write_to_known_channel(&header, &encode_cdr(&msg))
                .unwrap();
        }
        w.finish().unwrap();
        path
    }

    /// Every row and the error, if any, of a source read as the Allan side
    /// reads it (a first few rows one at a time, then blocks; or, not
    /// `by_blocks`, runs of rows, which keep those before an error).
    fn read_all(mut rows: impl RowSource, by_blocks: bool) -> (Vec<f64>, Option<String>) {
        let mut values = vec![0.0; rows.width()];
        let mut all = Vec::new();
        for _ in 0..100 {
            match rows.next_row(&mut values) {
                Ok(true) => all.extend_from_slice(&values),
                Ok(false) => return (all, None),
                Err(e) => return (all, Some(e.to_string())),
            }
        }
        if !by_blocks {
            loop {
                match rows.next_rows(&mut all, &mut values, 333) {
                    Ok(true) => {}
                    Ok(false) => return (all, None),
                    Err(e) => return (all, Some(e.to_string())),
                }
            }
        }
        loop {
            match rows.next_block() {
                Ok(Some(block)) => all.extend_from_slice(&block),
                Ok(None) => return (all, None),
                Err(e) => return (all, Some(e.to_string())),
            }
        }
    }

    /// The rows made as the chunks are decoded are the record's samples'
    /// rows, and where a sample fails a check the error is the one that
    /// path gives: a value out of range, a time
    /// that goes back, a gap in t, a message that does not decode, at
    /// places within and at the edges of chunks.
    #[test]
    fn rows_and_errors_are_those_of_the_records_samples() {
        let n = 7000;
        let mut cases: Vec<(String, std::path::PathBuf)> =
            vec![("good".into(), bag("good", n, |_| {}))];
        // Chunks of 756 messages of 347 bytes: places at their edges too.
        let edges = (754..=758).chain(1510..=1514);
        for k in [0usize, 1, 150, 2000, 4321, 6999].into_iter().chain(edges) {
            let name = format!("nan-{k}");
            cases.push((name.clone(), bag(&name, n, |s| s[k].gyro[1] = f64::NAN)));
            let name = format!("huge-{k}");
            cases.push((name.clone(), bag(&name, n, |s| s[k].accel[0] = -1e101)));
            if k > 1 {
                let name = format!("back-{k}");
                cases.push((name.clone(), bag(&name, n, |s| s[k].t = s[k - 2].t)));
                let name = format!("gap-{k}");
                cases.push((
                    name.clone(),
                    bag(&name, n, |s| {
                        for x in &mut s[k..] {
                            x.t += 0.5;
                        }
                    }),
                ));
            }
        }
        let good = std::fs::read(&cases[0].1).unwrap();
        // The second and third chunks start among the edges (sample k at 1000 + (k + 1)/100 s).
        let summary = mcap::Summary::read(&good).unwrap().unwrap();
        let starts: Vec<u64> = summary
            .chunk_indexes
            .iter()
            .map(|c| ((c.message_start_time as f64 / 1e9 - 1000.0) * 100.0).round() as u64 - 1)
            .collect();
        assert!((755..=758).contains(&starts[1]), "{starts:?}");
        assert!((1511..=1514).contains(&starts[2]), "{starts:?}");
        // The messages' frame_id length made absurd, one at a time.
        let frames: Vec<usize> = good
            .windows(4)
            .enumerate()
            .filter(|(_, w)| *w == b"imu\0")
            .map(|(at, _)| at - 4)
            .collect();
        for k in [0, 1, 2999, 5000] {
            let mut bytes = good.clone();
            bytes[frames[k]..frames[k] + 4].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
            let path = std::env::temp_dir().join(format!(
                "triad-mcap-rows-{}-cdr-{k}.mcap",
                std::process::id()
            ));
            std::fs::write(&path, bytes).unwrap();
            cases.push((format!("cdr-{k}"), path));
        }
        let mut chunked = 0;
        for (what, path) in &cases {
            for rate_from_t in [true, false] {
                let opened = open(path).unwrap().unwrap();
                let layout = Layout::new(&opened.header, None, rate_from_t).unwrap();
                let fast = read_all(McapRows::new(opened, &layout), true);
                let opened = record_rows::open(path).unwrap().unwrap();
                let slow = read_all(RecordRows::new(opened, &layout), false);
                assert_eq!(fast.1, slow.1, "{what}");
                // Before an error each path gives the rows of the blocks it
                // has checked whole (the analysis stops at the error
                // either way): the same rows, as far as both go.
                if fast.1.is_none() {
                    assert_eq!(fast.0.len(), slow.0.len(), "{what}");
                }
                assert!(
                    fast.0
                        .iter()
                        .zip(&slow.0)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{what}"
                );
                if what == "good" {
                    assert_eq!(fast.0.len(), n as usize * layout.width());
                    assert!(fast.1.is_none());
                } else if rate_from_t || !what.starts_with("gap") {
                    assert!(fast.1.is_some(), "{what}");
                }
            }
            chunked += 1;
            let _ = std::fs::remove_file(path);
        }
        assert!(chunked > 20);
    }
}
