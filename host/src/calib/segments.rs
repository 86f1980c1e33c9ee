//! The segments a fit averages: given as `--segments FROM-TO,…` or detected
//! as the static stretches of a record, each with its mean and the
//! standard error of that mean.

use anyhow::{anyhow, bail};
use triad_lab::calib_fit::poses::{self, Detection};
use triad_lab::calib_fit::static_segments::{DropReason, Dropped};

use super::fit_csv::{self, Record};

/// One segment's samples, where they came from and their statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct Stat {
    /// Index of the file among the inputs.
    pub file: usize,
    /// First sample's time, s.
    pub from: f64,
    /// Last sample's time, s.
    pub to: f64,
    /// Mean per axis.
    pub mean: [f64; 3],
    /// Standard error of the mean per axis (white noise: s/√n).
    pub standard_error: [f64; 3],
    /// Samples.
    pub count: usize,
}

/// `--gravity` and `--min-static` of the commands that detect static poses,
/// each positive, or an error naming it.
pub fn check_pose_options(gravity: f64, min_static: f64) -> anyhow::Result<()> {
    crate::plumbing::number::positive("--gravity", gravity, "must be a positive number of m/s²")?;
    crate::plumbing::number::positive(
        "--min-static",
        min_static,
        "must be a positive number of seconds",
    )?;
    Ok(())
}

/// The statistics of `record`'s samples `range` (file number `file`).
pub fn stat(record: &Record, file: usize, range: std::ops::Range<usize>) -> Stat {
    let s = poses::statistics(&record.samples[range.clone()]);
    Stat {
        file,
        from: record.t[range.start],
        to: record.t[range.end - 1],
        mean: s.mean,
        standard_error: s.standard_error,
        count: s.count,
    }
}

/// The segments FROM-TO of `--segments` in `record`.
pub fn given(record: &Record, text: &str) -> anyhow::Result<Vec<Stat>> {
    fit_csv::parse_segments(text)?
        .into_iter()
        .map(|(from, to)| {
            let start = record.t.partition_point(|&t| t < from);
            let n = record.between(from, to).len();
            if n < 2 {
                bail!(
                    "--segments {from}-{to}: {n} sample(s) of {} in that time range, need at least 2",
                    crate::plumbing::input::name(&record.path)
                );
            }
            Ok(stat(record, 0, start..start + n))
        })
        .collect()
}

/// The `--segments` of the single file of `records`, else `otherwise`
/// (`flag` names the files' option in the message).
pub fn given_or(
    records: &[Record],
    segments: Option<&str>,
    flag: &str,
    otherwise: impl FnOnce() -> anyhow::Result<Vec<Stat>>,
) -> anyhow::Result<Vec<Stat>> {
    match segments {
        Some(text) => {
            if records.len() != 1 {
                bail!(
                    "--segments applies to a single {flag} file; {} were given",
                    records.len()
                );
            }
            given(&records[0], text)
        }
        None => otherwise(),
    }
}

/// One line per candidate detection dropped in `record`, naming its times and samples.
pub fn dropped_lines(dropped: &[Dropped], record: &Record, min_static: f64) -> Vec<String> {
    dropped
        .iter()
        .map(|d| {
            let why = match d.reason {
                DropReason::TooShort => format!("shorter than --min-static {min_static} s"),
                DropReason::Held => {
                    "its samples repeat one value while the record's noise shows elsewhere \
                     (held samples, e.g. a logger repeating over lost frames): not a pose"
                        .to_string()
                }
            };
            format!(
                "candidate t = {:.2}..{:.2} s (samples {}..{}) dropped: {why}",
                record.t[d.start],
                record.t[d.end.max(d.start + 1) - 1],
                d.start + 1,
                d.end
            )
        })
        .collect()
}

/// The static segments of `record` (at least `min_static` s each), found in
/// each of its parts ([`Record::parts`]: no segment spans a gap).
pub fn detect(record: &Record, min_static: f64) -> anyhow::Result<Detection> {
    let detector = poses::detector(record.rate_hz()?, min_static);
    poses::detect(&detector, &record.samples, &record.parts())
        .map_err(|e| anyhow!("{}: {e}", crate::plumbing::input::name(&record.path)))
}

/// The static segments of every record, in order.
pub fn detected(records: &[Record], min_static: f64) -> anyhow::Result<Vec<Stat>> {
    detected_saying(records, min_static, |_| {})
}

/// [`detected`], each dropped candidate said to `say` (naming its file).
pub fn detected_saying(
    records: &[Record],
    min_static: f64,
    mut say: impl FnMut(String),
) -> anyhow::Result<Vec<Stat>> {
    let mut stats = Vec::new();
    for (file, record) in records.iter().enumerate() {
        let found = detect(record, min_static)?;
        let name = crate::plumbing::input::name(&record.path);
        for line in dropped_lines(&found.dropped, record, min_static) {
            say(format!("{name}: {line}"));
        }
        stats.extend(
            found
                .segments
                .iter()
                .map(|s| stat(record, file, s.start..s.end)),
        );
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// 0, 0.1, … 1.9 s; x alternates 1 ± 0.5, y = t, z = 0.
    fn record() -> Record {
        let t: Vec<f64> = (0..20).map(|i| i as f64 / 10.0).collect();
        let samples = t
            .iter()
            .enumerate()
            .map(|(i, &t)| [if i % 2 == 0 { 1.5 } else { 0.5 }, t, 0.0])
            .collect();
        Record {
            path: PathBuf::from("r.csv"),
            t,
            samples,
        }
    }

    #[test]
    fn a_segment_has_its_mean_and_standard_error() {
        let s = stat(&record(), 2, 0..4);
        assert_eq!((s.file, s.from, s.to, s.count), (2, 0.0, 0.3, 4));
        assert_eq!(s.mean[0], 1.0);
        assert_eq!(s.mean[2], 0.0);
        let sd = triad_lab::calib_fit::static_segments::standard_deviation(&record().samples[0..4]);
        assert_eq!(s.standard_error[0], sd[0] / 2.0);
    }

    #[test]
    fn given_segments_are_cut_by_time() {
        let stats = given(&record(), "0-0.35, 1-1.9").unwrap();
        assert_eq!(stats.len(), 2);
        assert_eq!(stats[0].count, 4);
        assert_eq!((stats[1].from, stats[1].count), (1.0, 10));
        let err = given(&record(), "5-6").unwrap_err().to_string();
        assert!(
            err.starts_with("--segments 5-6: 0 sample(s) of r.csv"),
            "{err}"
        );
        let two = [record(), record()];
        let err = given_or(&two, Some("0-1"), "--positions", || Ok(Vec::new()));
        assert!(err
            .unwrap_err()
            .to_string()
            .contains("single --positions file; 2 were given"));
        assert!(given_or(&two, None, "--positions", || Ok(Vec::new()))
            .unwrap()
            .is_empty());
    }
}
