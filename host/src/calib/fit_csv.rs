//! Reading the records `triad calib fit` takes: CSV with a header naming the
//! columns (`triad sim` writes `t,ax,ay,az,gx,gy,gz,temp`, SI units); only
//! the columns a fit needs must be present, in any order. `-` reads
//! standard input; a byte-order mark before the header is ignored.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};

use crate::input::{self, strip_bom};
use crate::progress::{Progress, Unit};

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
    /// The sample rate from the time span (Hz), or an error naming the file.
    pub fn rate_hz(&self) -> anyhow::Result<f64> {
        let n = self.t.len();
        let span = if n >= 2 {
            self.t[n - 1] - self.t[0]
        } else {
            0.0
        };
        if span.is_nan() || span <= 0.0 {
            bail!(
                "{}: {n} sample(s) spanning {span} s: cannot tell the sample rate (t must increase)",
                input::name(&self.path)
            );
        }
        Ok((n - 1) as f64 / span)
    }

    /// The samples with `from ≤ t ≤ to`.
    pub fn between(&self, from: f64, to: f64) -> &[[f64; 3]] {
        let start = self.t.partition_point(|&t| t < from);
        let end = self.t.partition_point(|&t| t <= to);
        &self.samples[start..end.max(start)]
    }
}

/// Reads `t` and the three `columns` of each of `paths`.
pub fn read_all(paths: &[PathBuf], columns: [&str; 3]) -> anyhow::Result<Vec<Record>> {
    paths.iter().map(|p| read(p, columns)).collect()
}

/// Reads `t` and the three `columns` of `path`.
pub fn read(path: &Path, columns: [&str; 3]) -> anyhow::Result<Record> {
    parse(&read_text(path)?, path, columns)
}

/// The `temp` column (°C) of the CSV `text` read from `path`, in a record's
/// three channels; `needed_for` says why in the error when the header has
/// no such column.
pub fn parse_temperature(text: &str, path: &Path, needed_for: &str) -> anyhow::Result<Record> {
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
    parse(text, path, ["temp"; 3])
}

/// The text of `path` (`-`: standard input), with progress for large files.
pub fn read_text(path: &Path) -> anyhow::Result<String> {
    let mut opened = input::open(path, 1 << 20)?;
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

/// Parses `t` and the three `columns` of the CSV `text` read from `path`.
pub fn parse(text: &str, path: &Path, columns: [&str; 3]) -> anyhow::Result<Record> {
    let name = input::name(path);
    let mut lines = strip_bom(text)
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{name}: empty file, expected a header such as `t,ax,ay,az,gx,gy,gz,temp`");
    };
    let wanted = ["t", columns[0], columns[1], columns[2]];
    let (width, index) = header_indices(header, wanted).map_err(|e| anyhow!("{name}: {e}"))?;
    let mut record = Record {
        path: path.to_path_buf(),
        t: Vec::new(),
        samples: Vec::new(),
    };
    for (i, line) in lines {
        let at = Line {
            name: &name,
            number: i + 1,
        };
        let v = at.values(line, width, &index, wanted)?;
        if let Some(&last) = record.t.last() {
            if v[0] <= last {
                bail!(
                    "{name} line {}: t = {} does not increase (previous {last})",
                    i + 1,
                    v[0]
                );
            }
        }
        record.t.push(v[0]);
        record.samples.push([v[1], v[2], v[3]]);
    }
    if record.t.is_empty() {
        bail!("{name}: no samples after the header");
    }
    Ok(record)
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
        parse(text, Path::new("r.csv"), GYRO)
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
        assert_eq!(
            err("t,gx,gy,gz\n1,1,2,3\n\n1,1,2,3\n"),
            "r.csv line 4: t = 1 does not increase (previous 1)"
        );
        let one = record("t,gx,gy,gz\n1,1,2,3\n").unwrap();
        assert!(one
            .rate_hz()
            .unwrap_err()
            .to_string()
            .contains("cannot tell the sample rate"));
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
