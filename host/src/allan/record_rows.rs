//! The rows of a recording in another format than triad's CSV (a bag, a
//! ULog, EuRoC, imu_tk: [`crate::record`]): its samples taken as the row
//! of the CSV it converts to (`t,ax,ay,az,gx,gy,gz[,temp]`, the header of
//! [`to_csv::header`]) straight from the reader's chunks, without making
//! and parsing that text: the same values (the CSV carries them exactly),
//! so the same Allan results, at the speed of the reader. Errors name the
//! file and the message (or line) and time of the sample.

use std::path::Path;

use anyhow::anyhow;

use crate::record::{self, to_csv, Reader, Sample, Source};

use super::columns::Layout;
use super::rows::{in_range, RowSource, MAX_MAGNITUDE};
use super::time::TimeCheck;

/// A recording opened: its CSV header, and the rows once a layout is known.
pub(crate) struct Opened {
    /// The header of the CSV it converts to.
    pub(crate) header: String,
    /// Its name in messages (with its format).
    pub(crate) name: String,
    source: Source,
    reader: Box<dyn Reader>,
}

/// The recording at `path` when it is one in another format than triad's
/// CSV (None: a CSV, standard input, or nothing there: the CSV path reads it).
pub(crate) fn open(path: &Path) -> anyhow::Result<Option<Opened>> {
    if crate::plumbing::input::is_stdin(path) || std::fs::metadata(path).is_err() {
        return Ok(None);
    }
    if !record::detect::detect(path)?.is_container_or_foreign() {
        return Ok(None);
    }
    let opened = record::open(path, &record::options::global())?;
    let source = opened.source;
    Ok(Some(Opened {
        header: to_csv::header(source.channels),
        name: format!("{} ({})", source.name, source.format.name()),
        source,
        reader: opened.reader,
    }))
}

/// The samples as rows of the values a layout wants.
pub(crate) struct RecordRows {
    source: Source,
    reader: Box<dyn Reader>,
    chunk: Vec<Sample>,
    next: usize,
    /// (index in the CSV row, slot), as the layout reads the header.
    cells: Vec<(usize, usize)>,
    names: Vec<String>,
    t_slot: Option<usize>,
    time: Option<TimeCheck>,
}

impl RecordRows {
    /// The rows of `opened` as `layout` reads them.
    pub(crate) fn new(opened: Opened, layout: &Layout) -> RecordRows {
        RecordRows {
            source: opened.source,
            reader: opened.reader,
            chunk: Vec::new(),
            next: 0,
            cells: layout.cells.clone(),
            names: layout.names.clone(),
            t_slot: layout.t_slot,
            time: None,
        }
    }

    /// The CSV row of `s`: t, then the channels the record has.
    fn row(&self, s: &Sample) -> [f64; 8] {
        let mut row = [0.0; 8];
        row[0] = s.t;
        let mut n = 1;
        let channels = self.source.channels;
        for (present, values) in [(channels.accel, s.accel), (channels.gyro, s.gyro)] {
            if present {
                row[n..n + 3].copy_from_slice(&values);
                n += 3;
            }
        }
        row[n] = s.temp;
        row
    }

    /// True when a sample is at hand (a new chunk taken if need be).
    fn at_hand(&mut self) -> anyhow::Result<bool> {
        while self.next == self.chunk.len() {
            match self.reader.next_chunk()? {
                Some(chunk) => (self.chunk, self.next) = (chunk, 0),
                None => return Ok(false),
            }
        }
        Ok(true)
    }

    /// The next sample of the chunk at hand into `values` (by slot), its
    /// values and t checked.
    #[inline]
    fn take(&mut self, values: &mut [f64]) -> anyhow::Result<()> {
        let s = self.chunk[self.next];
        self.next += 1;
        let row = self.row(&s);
        for &(cell, slot) in &self.cells {
            values[slot] = in_range(row[cell]).map_err(|why| {
                anyhow!(
                    "{}, column {}: {why}",
                    self.source.where_is(&s),
                    self.names[slot]
                )
            })?;
        }
        if let Some(slot) = self.t_slot {
            let t = values[slot];
            match &mut self.time {
                None => self.time = Some(TimeCheck::new(t)),
                Some(tc) => tc.next_at(t, || self.source.where_is(&s))?,
            }
        }
        Ok(())
    }
}

impl RecordRows {
    /// The next `n` samples of the chunk at hand appended to `block` as
    /// rows, as [`Self::take`] of each would: the values copied in one
    /// loop, checked in range in another and t checked in a third (the
    /// checks of a run without a bad value, the usual case, are then a few
    /// instructions a sample); the block keeps the rows before a sample
    /// that fails, and [`Self::take`] names that sample.
    fn take_run(
        &mut self,
        block: &mut Vec<f64>,
        values: &mut [f64],
        n: usize,
    ) -> anyhow::Result<()> {
        let width = values.len();
        let at = block.len();
        // Written in place (a slot no cell fills stays 0).
        block.resize(at + n * width, 0.0);
        let run = &self.chunk[self.next..self.next + n];
        for (s, out) in run.iter().zip(block[at..].chunks_exact_mut(width)) {
            let row = self.row(s);
            for &(cell, slot) in &self.cells {
                out[slot] = row[cell];
            }
        }
        // NaN and ±inf fail the comparison too.
        let in_range = |v: &f64| v.abs() <= MAX_MAGNITUDE;
        let good = block[at..]
            .chunks_exact(width)
            .position(|row| !row.iter().all(in_range))
            .unwrap_or(n);
        if let Some(slot) = self.t_slot {
            let run = &self.chunk[self.next..self.next + good];
            for (i, s) in run.iter().enumerate() {
                let t = block[at + i * width + slot];
                let checked = match &mut self.time {
                    None => {
                        self.time = Some(TimeCheck::new(t));
                        Ok(())
                    }
                    Some(tc) => tc.next_at(t, || self.source.where_is(s)),
                };
                if let Err(e) = checked {
                    block.truncate(at + i * width);
                    self.next += i + 1;
                    return Err(e);
                }
            }
        }
        if good < n {
            block.truncate(at + good * width);
            self.next += good;
            // Fails, naming the sample and the value; were it to pass, the
            // rest of the run is taken after it.
            self.take(values)?;
            block.extend_from_slice(values);
            return self.take_run(block, values, n - good - 1);
        }
        self.next += n;
        Ok(())
    }
}

impl RowSource for RecordRows {
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        if !self.at_hand()? {
            return Ok(false);
        }
        self.take(values)?;
        Ok(true)
    }

    /// The samples of each chunk taken a run at a time ([`Self::take_run`]).
    fn next_rows(
        &mut self,
        block: &mut Vec<f64>,
        values: &mut [f64],
        rows: usize,
    ) -> anyhow::Result<bool> {
        let mut left = rows;
        while left > 0 {
            if !self.at_hand()? {
                return Ok(false);
            }
            let here = left.min(self.chunk.len() - self.next);
            self.take_run(block, values, here)?;
            left -= here;
        }
        Ok(true)
    }

    fn width(&self) -> usize {
        self.names.len()
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
    use crate::record::{Channels, Format, Place};

    /// A reader giving `samples` in chunks of `chunk`.
    struct Chunks(Vec<Vec<Sample>>);

    impl Reader for Chunks {
        fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
            Ok((!self.0.is_empty()).then(|| self.0.remove(0)))
        }
    }

    fn rows_of(samples: &[Sample], chunk: usize) -> RecordRows {
        let channels = Channels::IMU;
        let header = to_csv::header(channels);
        let layout = Layout::new(&header, None, true).unwrap();
        let opened = Opened {
            header,
            name: "bag (MCAP)".into(),
            source: Source {
                name: "bag".into(),
                format: Format::Mcap,
                channels,
                place: Place::Message,
                topic: Some("/imu".into()),
            },
            reader: Box::new(Chunks(samples.chunks(chunk).map(<[_]>::to_vec).collect())),
        };
        RecordRows::new(opened, &layout)
    }

    /// Rows read a run at a time, and one at a time: the rows and, where a
    /// sample fails, the error.
    fn both_ways(samples: &[Sample]) -> [(Vec<f64>, Option<String>); 2] {
        let width = rows_of(samples, 1).names.len();
        let mut values = vec![0.0; width];
        let mut runs = rows_of(samples, 7);
        let mut by_runs = Vec::new();
        let mut failed = None;
        loop {
            match runs.next_rows(&mut by_runs, &mut values, 10) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => {
                    failed = Some(e.to_string());
                    break;
                }
            }
        }
        let mut one = rows_of(samples, 7);
        let mut by_one = Vec::new();
        let mut failed_one = None;
        loop {
            match one.next_row(&mut values) {
                Ok(true) => by_one.extend_from_slice(&values),
                Ok(false) => break,
                Err(e) => {
                    failed_one = Some(e.to_string());
                    break;
                }
            }
        }
        [(by_runs, failed), (by_one, failed_one)]
    }

    fn record(n: u64) -> Vec<Sample> {
        (1..=n)
            .map(|k| {
                let mut s = Sample::at(k, k as f64 * 0.01);
                s.accel = [k as f64, 0.5, 9.8];
                s.gyro = [0.1, -(k as f64), 0.0];
                s
            })
            .collect()
    }

    /// A run gives the rows one sample at a time gives, and at a bad value
    /// or t the same rows before it and the same error naming it.
    #[test]
    fn runs_give_the_rows_and_errors_of_one_sample_at_a_time() {
        let good = record(40);
        let [runs, one] = both_ways(&good);
        assert_eq!(runs, one);
        assert_eq!(runs.0.len(), 40 * 7);
        assert!(runs.1.is_none());
        for (k, bad) in [
            (23, f64::NAN),
            (0, f64::INFINITY),
            (39, 1e200),
            (12, -1e101),
        ] {
            let mut r = record(40);
            r[k].gyro[1] = bad;
            let [runs, one] = both_ways(&r);
            assert_eq!(runs, one, "a bad value at {k}");
            assert_eq!(runs.0.len(), k * 7);
            let e = runs.1.unwrap();
            assert!(e.starts_with(&format!("bag, message {} ", k + 1)), "{e}");
            assert!(e.contains("column gy"), "{e}");
        }
        let mut r = record(40);
        r[30].t += 0.5;
        let [runs, one] = both_ways(&r);
        assert_eq!(runs, one);
        assert_eq!(runs.0.len(), 30 * 7);
        assert!(runs.1.unwrap().contains("message 31 (t = 0.81 s)"));
    }
}
