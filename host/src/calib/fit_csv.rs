//! Reading the records `triad calib fit` takes: CSV with a header naming the
//! columns (`triad sim` writes `t,ax,ay,az,gx,gy,gz,temp`, SI units); only
//! the columns a fit needs must be present, in any order. `-` reads
//! standard input; a byte-order mark before the header is ignored. A
//! recording in another format (a bag, a ULog, EuRoC, imu_tk:
//! [`crate::record`]) is read natively: its samples, not the text of its
//! CSV, and its errors name the message (or line) and time of the sample.
//!
//! Times: the `t` stamps as loggers write them (repeated, jittered, out of
//! order, with gaps) are repaired by [`time_base::repair`], whose method
//! its documentation states; `--rate HZ` times the samples instead (and
//! then no `t` column is needed). Units: [`Reading`] converts columns in g,
//! °/s or a 16-bit chip's counts (at the configured range) to SI.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_lab::time_base::{self, TimeBase};

use super::Ranges;
use crate::plumbing::input::{self, strip_bom};
use crate::plumbing::progress::{Progress, Unit};
use crate::record;

/// The columns of one triad.
pub const ACCEL: [&str; 3] = ["ax", "ay", "az"];
/// The columns of one triad.
pub const GYRO: [&str; 3] = ["gx", "gy", "gz"];

/// A record: times and one triad's samples.
pub struct Record {
    /// Where it was read from.
    pub path: PathBuf,
    /// t, seconds.
    pub t: Vec<f64>,
    /// The triad's samples (SI).
    pub samples: Vec<[f64; 3]>,
}

impl Record {
    /// The sample rate (Hz): one over the median window period of the
    /// times ([`time_base::period`]: gaps do not bias it), or an error
    /// naming the file.
    pub fn rate_hz(&self) -> anyhow::Result<f64> {
        let n = self.t.len();
        let mut scratch = vec![0.0; n / time_base::WINDOW + 1];
        let period = if n >= 2 {
            time_base::period(&self.t, &mut scratch)
        } else {
            f64::NAN
        };
        if !(period > 0.0 && period.is_finite()) {
            bail!(
                "{}: {n} sample(s): cannot tell the sample rate (t must increase); pass --rate HZ",
                input::name(&self.path)
            );
        }
        Ok(1.0 / period)
    }

    /// The record's parts: split where the times step by more than
    /// [`time_base::GAP_PERIODS`] periods (a gap the logger left), each a
    /// sample range; no motion is integrated across a split.
    pub fn parts(&self) -> Vec<std::ops::Range<usize>> {
        let whole = 0..self.t.len();
        let Ok(rate) = self.rate_hz() else {
            return Vec::from([whole]);
        };
        let gap = time_base::GAP_PERIODS / rate;
        let mut parts = Vec::new();
        let mut start = 0;
        for i in 1..self.t.len() {
            if self.t[i] - self.t[i - 1] > gap {
                parts.push(start..i);
                start = i;
            }
        }
        parts.push(start..self.t.len());
        parts
    }

    /// The samples with `from ≤ t ≤ to`.
    pub fn between(&self, from: f64, to: f64) -> &[[f64; 3]] {
        let start = self.t.partition_point(|&t| t < from);
        let end = self.t.partition_point(|&t| t <= to);
        &self.samples[start..end.max(start)]
    }
}

/// The accelerometer and gyro records of one IMU's samples (t, f̂, ω̂),
/// named `path`, as `calib fit imu` takes them.
pub fn imu_records(
    path: &Path,
    samples: impl IntoIterator<Item = (f64, [f64; 3], [f64; 3])>,
) -> (Record, Record) {
    let (mut t, mut a, mut g) = (Vec::new(), Vec::new(), Vec::new());
    for (ti, ai, gi) in samples {
        t.push(ti);
        a.push(ai);
        g.push(gi);
    }
    let accel = Record {
        path: path.to_path_buf(),
        t: t.clone(),
        samples: a,
    };
    let gyro = Record {
        path: path.to_path_buf(),
        t,
        samples: g,
    };
    (accel, gyro)
}

/// How to read a record's columns: its rate when the stamps cannot say,
/// and the triads' units (what a user knows of the unit that logged it).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Reading {
    /// The sample rate, Hz: sample k is at k/HZ, the `t` column (if any)
    /// ignored. For records without stamps, or whose stamps cannot time them.
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub rate: Option<f64>,
    /// The unit of the ax,ay,az columns: m/s2, g, or counts (a 16-bit
    /// chip's, scaled by the nominal sensitivity of --accel-range-g).
    #[arg(long, default_value = "m/s2", value_parser = ["m/s2", "g", "counts"])]
    pub accel_unit: String,
    /// The unit of the gx,gy,gz columns: rad/s, deg/s, or counts (a 16-bit
    /// chip's, scaled by the nominal sensitivity of --gyro-range-dps).
    #[arg(long, default_value = "rad/s", value_parser = ["rad/s", "deg/s", "counts"])]
    pub gyro_unit: String,
}

impl Reading {
    /// SI per unit of the `columns` ([`ACCEL`] or [`GYRO`]) at `ranges`.
    pub fn scale(&self, columns: [&str; 3], ranges: &Ranges) -> f64 {
        let scale = ranges.scale_16_bit();
        if columns == ACCEL {
            match self.accel_unit.as_str() {
                "g" => STANDARD_GRAVITY,
                "counts" => scale.accel.si_per_lsb,
                _ => 1.0,
            }
        } else {
            match self.gyro_unit.as_str() {
                "deg/s" => deg_to_rad(1.0),
                "counts" => scale.gyro.si_per_lsb,
                _ => 1.0,
            }
        }
    }

    /// Reads the `columns` of `path` in SI, timed as this says, with what
    /// the time base found.
    pub fn read(
        &self,
        path: &Path,
        columns: [&str; 3],
        ranges: &Ranges,
    ) -> anyhow::Result<(Record, TimeBase)> {
        self.parse(&read_content(path)?, path, columns, ranges)
    }

    /// [`Self::read`] of each of `paths`, without the time bases.
    pub fn read_all(
        &self,
        paths: &[PathBuf],
        columns: [&str; 3],
        ranges: &Ranges,
    ) -> anyhow::Result<Vec<Record>> {
        paths
            .iter()
            .map(|p| self.read(p, columns, ranges).map(|(r, _)| r))
            .collect()
    }

    /// [`Self::read`] from the content already read.
    pub fn parse(
        &self,
        content: &Content,
        path: &Path,
        columns: [&str; 3],
        ranges: &Ranges,
    ) -> anyhow::Result<(Record, TimeBase)> {
        parse_timed(
            content,
            path,
            columns,
            self.rate,
            self.scale(columns, ranges),
        )
    }
}

/// One line saying how the times were made, for a fit's report (None when
/// the stamps were a clean straight line).
pub fn time_note(name: &str, base: &TimeBase, record: &Record) -> Option<String> {
    if base.from_rate {
        return Some(format!(
            "{name}: timed by --rate: {:.6} Hz, sample k at k/rate (stamps ignored)",
            1.0 / base.period
        ));
    }
    if !base.repaired() {
        return None;
    }
    let at = base.departure_at;
    Some(format!(
        "{name}: time stamps repaired (one straight line per part, period {:.6} s = the median of {}-sample windows): {} repeated, {} backwards, {} small gap(s), {} part(s) split at gaps over {} periods; largest departure {:.4} s at sample {} (t = {:.3} s)",
        base.period,
        time_base::WINDOW,
        base.repeated,
        base.backwards,
        base.small_gaps,
        base.parts,
        time_base::GAP_PERIODS,
        base.largest_departure,
        at + 1,
        record.t[at]
    ))
}

/// Reads `t` and the three `columns` of each of `paths`.
pub fn read_all(paths: &[PathBuf], columns: [&str; 3]) -> anyhow::Result<Vec<Record>> {
    paths.iter().map(|p| read(p, columns)).collect()
}

/// Reads `t` and the three `columns` of `path`.
pub fn read(path: &Path, columns: [&str; 3]) -> anyhow::Result<Record> {
    parse(&read_content(path)?, path, columns)
}

/// The `temp` column (°C) of the `content` read from `path`, in a
/// record's three channels; `needed_for` says why in the error when it has
/// no temperature.
pub fn parse_temperature(
    content: &Content,
    path: &Path,
    needed_for: &str,
) -> anyhow::Result<Record> {
    match content {
        Content::Text(text) => {
            let header = strip_bom(text)
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("");
            if !header.split(',').any(|c| c.trim() == "temp") {
                bail!(
                    "{}: no temperature column `temp` in the header `{}`: {needed_for}",
                    input::name(path),
                    header.trim()
                );
            }
        }
        Content::Samples(record) if !record.source.channels.temp => bail!(
            "{}: {} records carry no temperature: {needed_for}",
            input::name(path),
            record.source.format.name()
        ),
        Content::Samples(_) => {}
    }
    parse(content, path, ["temp"; 3])
}

/// What a record file holds, as read: a CSV's text, or the samples of a
/// recording in another format ([`crate::record`]), read natively.
pub enum Content {
    /// triad's CSV (or standard input).
    Text(String),
    /// A bag, a ULog, EuRoC, imu_tk: its samples (SI).
    Samples(crate::record::Record),
}

/// The content of `path` (`-`: standard input): a recording in another
/// format than triad's CSV as its samples, else the text.
pub fn read_content(path: &Path) -> anyhow::Result<Content> {
    let foreign = !input::is_stdin(path)
        && std::fs::metadata(path).is_ok()
        && record::detect::detect(path)?.is_container_or_foreign();
    if foreign {
        let record = record::read_all(path, &record::options::global())?;
        return Ok(Content::Samples(record));
    }
    read_text(path).map(Content::Text)
}

/// The text of `path` (`-`: standard input), with progress for large files.
pub fn read_text(path: &Path) -> anyhow::Result<String> {
    let mut opened = input::open_bytes(path, 1 << 20)?;
    let name = opened.name;
    let mut bytes = Vec::with_capacity(opened.size as usize);
    // About a second of reading and parsing: 64 MB.
    let progress = Progress::new(opened.size, 64 << 20, Unit::Bytes);
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        let n = match opened.reader.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e).with_context(|| format!("{name}: cannot read")),
        };
        bytes.extend_from_slice(&chunk[..n]);
        progress.update(bytes.len() as u64);
    }
    progress.finish();
    String::from_utf8(bytes).map_err(|e| {
        anyhow!(
            "{name}: not text (invalid UTF-8 at byte {})",
            e.utf8_error().valid_up_to()
        )
    })
}

/// Parses `t` and the three `columns` (SI) of the `content` read from
/// `path`, its stamps repaired by the time base.
pub fn parse(content: &Content, path: &Path, columns: [&str; 3]) -> anyhow::Result<Record> {
    parse_timed(content, path, columns, None, 1.0).map(|(r, _)| r)
}

/// Parses the three `columns` of the `content` read from `path`, each
/// value times `scale` (to SI); timed at `rate` Hz when given (no `t`
/// column needed), else by the repaired `t` stamps.
fn parse_timed(
    content: &Content,
    path: &Path,
    columns: [&str; 3],
    rate: Option<f64>,
    scale: f64,
) -> anyhow::Result<(Record, TimeBase)> {
    let name = input::name(path);
    let (stamps, samples) = match content {
        Content::Text(text) => text_columns(text, &name, columns, rate, scale)?,
        Content::Samples(record) => sample_columns(record, columns, scale)?,
    };
    let n = samples.len();
    let (t, base) = match rate {
        Some(hz) => {
            let mut t = vec![0.0; n];
            let base = time_base::from_rate(n, hz, &mut t).map_err(|e| anyhow!("{name}: {e}"))?;
            (t, base)
        }
        None => repaired_times(&name, &stamps)?,
    };
    let record = Record {
        path: path.to_path_buf(),
        t,
        samples,
    };
    Ok((record, base))
}

/// The stamps and the three `columns` (times `scale`) of a recording's
/// samples, each a finite number or an error naming the sample.
fn sample_columns(
    record: &crate::record::Record,
    columns: [&str; 3],
    scale: f64,
) -> anyhow::Result<(Vec<f64>, Vec<[f64; 3]>)> {
    let mut stamps = Vec::with_capacity(record.samples.len());
    let mut samples = Vec::with_capacity(record.samples.len());
    for s in &record.samples {
        let mut v = [0.0; 3];
        for (x, column) in v.iter_mut().zip(columns) {
            let value = match column {
                "ax" => s.accel[0],
                "ay" => s.accel[1],
                "az" => s.accel[2],
                "gx" => s.gyro[0],
                "gy" => s.gyro[1],
                "gz" => s.gyro[2],
                _ => s.temp,
            };
            if !value.is_finite() {
                bail!(
                    "{}: {column} = {value} is not a finite number",
                    record.source.where_is(s)
                );
            }
            *x = value * scale;
        }
        stamps.push(s.t);
        samples.push(v);
    }
    Ok((stamps, samples))
}

/// The stamps (zeros without a `t` column when `rate` times them) and the
/// three `columns` (times `scale`) of the CSV `text` of the record `name`.
fn text_columns(
    text: &str,
    name: &str,
    columns: [&str; 3],
    rate: Option<f64>,
    scale: f64,
) -> anyhow::Result<(Vec<f64>, Vec<[f64; 3]>)> {
    let mut lines = strip_bom(text)
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{name}: empty file, expected a header such as `t,ax,ay,az,gx,gy,gz,temp`");
    };
    let has_t = header.split(',').any(|c| c.trim() == "t");
    // Without --rate the stamps are needed; with it, a `t` column is read
    // (and checked) only when there is one.
    let wanted = if has_t || rate.is_none() {
        ["t", columns[0], columns[1], columns[2]]
    } else {
        [columns[0], columns[0], columns[1], columns[2]]
    };
    let (width, index) = header_indices(header, wanted).map_err(|e| {
        let hint = if has_t {
            ""
        } else {
            "; a record without time stamps needs --rate HZ"
        };
        anyhow!("{name}: {e}{hint}")
    })?;
    let mut stamps = Vec::new();
    let mut samples = Vec::new();
    for (i, line) in lines {
        let at = Line {
            name,
            number: i + 1,
        };
        let v = at.values(line, width, &index, wanted)?;
        stamps.push(v[0]);
        samples.push([v[1] * scale, v[2] * scale, v[3] * scale]);
    }
    if samples.is_empty() {
        bail!("{name}: no samples after the header");
    }
    Ok((stamps, samples))
}

/// The times every fit uses for the `stamps` of the record `name`:
/// [`time_base::repair`]'s straight line per part (the session's live
/// record goes through it too, so that refitting its file gives the same).
pub fn repaired_times(name: &str, stamps: &[f64]) -> anyhow::Result<(Vec<f64>, TimeBase)> {
    let n = stamps.len();
    let mut t = vec![0.0; n];
    let base =
        time_base::repair(stamps, &mut t, &mut vec![0; n]).map_err(|e| anyhow!("{name}: {e}"))?;
    Ok((t, base))
}

/// The header's column count and the cell index of each `wanted` column.
fn header_indices(header: &str, wanted: [&str; 4]) -> anyhow::Result<(usize, [usize; 4])> {
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let missing: Vec<String> = wanted
        .iter()
        .filter(|w| !names.contains(w))
        .map(|m| format!("`{m}`"))
        .collect();
    if !missing.is_empty() {
        bail!(
            "missing column(s) {} in the header `{}` (expected the columns `triad sim` writes: t,ax,ay,az,gx,gy,gz,temp)",
            missing.join(", "),
            header.trim()
        );
    }
    let index = wanted.map(|w| names.iter().position(|n| *n == w).unwrap_or(0));
    Ok((names.len(), index))
}

/// A line of a record, for messages: "FILE line N".
#[derive(Clone, Copy)]
struct Line<'a> {
    /// The record's name in messages ([`input::name`], made once per file).
    name: &'a str,
    number: usize,
}

impl Line<'_> {
    /// The `wanted` cells (at `index`) of `line`, which must have `width` cells.
    fn values(
        &self,
        line: &str,
        width: usize,
        index: &[usize; 4],
        wanted: [&str; 4],
    ) -> anyhow::Result<[f64; 4]> {
        let Line { name, number } = *self;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != width {
            bail!(
                "{name} line {number}: expected {width} columns as in the header, found {}",
                fields.len()
            );
        }
        let mut v = [0.0; 4];
        for (x, (&col, label)) in v.iter_mut().zip(index.iter().zip(wanted)) {
            let raw = fields[col];
            *x = raw
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    anyhow!(
                        "{name} line {number}, column {} ({label}): `{raw}` is not a finite number",
                        col + 1
                    )
                })?;
        }
        Ok(v)
    }
}

/// Parses `--segments 0-10,12-22.5` (seconds) into (from, to) pairs.
pub fn parse_segments(text: &str) -> anyhow::Result<Vec<(f64, f64)>> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|item| {
            let (a, b) = item.split_once('-').ok_or_else(|| {
                anyhow!("--segments: `{item}` is not FROM-TO in seconds (e.g. 0-10)")
            })?;
            let parse = |s: &str| -> anyhow::Result<f64> {
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x >= 0.0)
                    .ok_or_else(|| {
                        anyhow!(
                            "--segments: `{s}` in `{item}` is not a non-negative number of seconds"
                        )
                    })
            };
            let (from, to) = (parse(a)?, parse(b)?);
            if to <= from {
                bail!("--segments: `{item}` ends before it starts");
            }
            Ok((from, to))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(text: &str) -> anyhow::Result<Record> {
        parse(&Content::Text(text.into()), Path::new("r.csv"), GYRO)
    }

    #[test]
    fn the_columns_are_found_by_name_in_any_order() {
        let r = record("gz, t,gx,gy,ax\n\n3,0.0,1,2,9\n6,0.5,4,5,9\n").unwrap();
        assert_eq!(r.t, [0.0, 0.5]);
        assert_eq!(r.samples, [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(r.rate_hz().unwrap(), 2.0);
        assert_eq!(r.between(0.1, 1.0), &[[4.0, 5.0, 6.0]]);
        assert!(r.between(0.6, 1.0).is_empty());
    }

    #[test]
    fn a_byte_order_mark_is_not_part_of_the_first_name() {
        let r = record("\u{feff}t,gx,gy,gz\n0,1,2,3\n1,1,2,3\n").unwrap();
        assert_eq!(r.t, [0.0, 1.0]);
    }

    #[test]
    fn bad_records_are_named_by_line_and_column() {
        let err = |text: &str| record(text).err().unwrap().to_string();
        assert!(err("").starts_with("r.csv: empty file"));
        assert!(
            err("t,gx,gy\n").starts_with("r.csv: missing column(s) `gz` in the header `t,gx,gy`")
        );
        assert_eq!(err("t,gx,gy,gz\n"), "r.csv: no samples after the header");
        assert_eq!(
            err("t,gx,gy,gz\n0,1,2\n"),
            "r.csv line 2: expected 4 columns as in the header, found 3"
        );
        assert_eq!(
            err("t,gx,gy,gz\n0,1,x,3\n"),
            "r.csv line 2, column 3 (gy): `x` is not a finite number"
        );
        assert!(err("t,gx,gy,gz\n1,1,2,3\n\n1,1,2,3\n")
            .starts_with("r.csv: the 2 time stamps do not advance (first 1, last 1)"));
        assert!(err("t,gx,gy,gz\n1,1,2,3\n").contains("pass --rate HZ"));
    }

    #[test]
    fn repeated_stamps_are_repaired_and_a_rate_times_a_record_without_stamps() {
        // 200 Hz stamped at 10 ms: pairs share a stamp.
        let mut text = String::from("t,gx,gy,gz\n");
        for k in 0..100 {
            let t = 1672887159.71 + ((k as f64 * 0.005) / 0.01).floor() * 0.01;
            text += &format!("{t:.2},1,2,3\n");
        }
        let text = Content::Text(text);
        let (r, base) = parse_timed(&text, Path::new("r.csv"), GYRO, None, 1.0).unwrap();
        assert!((r.rate_hz().unwrap() - 200.0).abs() < 5.0, "{base:?}");
        assert!(r.t.windows(2).all(|w| w[1] > w[0]));
        let note = time_note("r.csv", &base, &r).unwrap();
        assert!(note.contains("50 repeated"), "{note}");
        let reading = Reading {
            rate: Some(100.0),
            accel_unit: "g".into(),
            gyro_unit: "counts".into(),
        };
        let ranges = Ranges {
            accel_range_g: 2.0,
            gyro_range_dps: 250.0,
        };
        let (r, _) = reading
            .parse(
                &Content::Text("ax,ay,az\n0,0,1\n0,0,-1\n".into()),
                Path::new("a.csv"),
                ACCEL,
                &ranges,
            )
            .unwrap();
        assert_eq!(r.t, [0.0, 0.01]);
        assert_eq!(r.samples[1], [0.0, 0.0, -STANDARD_GRAVITY]);
        let (g, _) = reading
            .parse(
                &Content::Text("gx,gy,gz\n131,0,0\n".into()),
                Path::new("g.csv"),
                GYRO,
                &ranges,
            )
            .unwrap();
        assert!((g.samples[0][0] - deg_to_rad(131.0 * 250.0 / 32768.0)).abs() < 1e-15);
        let err = record("ax,gx,gy,gz\n0,1,2,3\n").err().unwrap().to_string();
        assert!(
            err.ends_with("a record without time stamps needs --rate HZ"),
            "{err}"
        );
    }

    #[test]
    fn segments_are_from_to_pairs_in_seconds() {
        assert_eq!(
            parse_segments("0-10, 12-22.5,").unwrap(),
            [(0.0, 10.0), (12.0, 22.5)]
        );
        let err = |t: &str| parse_segments(t).unwrap_err().to_string();
        assert!(err("5").contains("`5` is not FROM-TO"));
        assert!(err("5-2").contains("`5-2` ends before it starts"));
        assert!(err("a-2").contains("`a` in `a-2` is not a non-negative number"));
    }
}
