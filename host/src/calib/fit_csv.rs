//! Reading the records `triad calib fit` takes: CSV with a header naming the
//! columns (`triad sim` writes `t,ax,ay,az,gx,gy,gz,temp`, SI units); only
//! the columns a fit needs must be present, in any order.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};

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
                self.path.display()
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

/// Reads `t` and the three `columns` of `path`.
pub fn read(path: &Path, columns: [&str; 3]) -> anyhow::Result<Record> {
    let name = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("{name}: cannot read"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{name}: empty file, expected a header such as `t,ax,ay,az,gx,gy,gz,temp`");
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let wanted = ["t", columns[0], columns[1], columns[2]];
    let missing: Vec<&str> = wanted
        .iter()
        .copied()
        .filter(|w| !names.contains(w))
        .collect();
    if !missing.is_empty() {
        bail!(
            "{name}: missing column(s) {} in the header `{}` (expected the columns `triad sim` writes: t,ax,ay,az,gx,gy,gz,temp)",
            missing.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(", "),
            header.trim()
        );
    }
    let index: Vec<usize> = wanted
        .iter()
        .map(|w| names.iter().position(|n| n == w).unwrap_or(0))
        .collect();
    let mut record = Record {
        path: path.to_path_buf(),
        t: Vec::new(),
        samples: Vec::new(),
    };
    for (i, line) in lines {
        let number = i + 1;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            bail!(
                "{name} line {number}: expected {} columns as in the header, found {}",
                names.len(),
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
        if let Some(&last) = record.t.last() {
            if v[0] <= last {
                bail!(
                    "{name} line {number}: t = {} does not increase (previous {last})",
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
