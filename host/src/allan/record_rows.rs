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
use super::rows::{in_range, RowSource};
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

impl RowSource for RecordRows {
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        if !self.at_hand()? {
            return Ok(false);
        }
        self.take(values)?;
        Ok(true)
    }

    /// The samples of each chunk taken in one loop.
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
            for _ in 0..here {
                self.take(values)?;
                block.extend_from_slice(values);
            }
            left -= here;
        }
        Ok(true)
    }

    fn time(&self) -> Option<&TimeCheck> {
        self.time.as_ref()
    }

    fn bytes(&self) -> u64 {
        0
    }
}
