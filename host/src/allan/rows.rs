//! The rows of the CSV after its header: reading lines, splitting and
//! parsing the cells a [`Layout`] wants, and checking the `t` column as it
//! goes. Errors name the file, the line, the column and the cell.

use std::io::BufRead;
use std::path::Path;

use anyhow::{anyhow, bail, Context};

use crate::plumbing::input::{self, strip_bom_bytes};

use super::columns::Layout;
use super::compute::BLOCK_ROWS;
use super::time::TimeCheck;

/// Parses the cells a layout wants out of one CSV line.
pub(crate) struct RowParser {
    /// (cell index, output slot), sorted by cell index.
    pub(crate) cells: Vec<(usize, usize)>,
    /// The name of each slot.
    pub(crate) names: Vec<String>,
}

impl RowParser {
    /// Splits `line` and parses the wanted cells into `values` (by slot).
    pub(crate) fn parse(
        &self,
        line: &[u8],
        line_no: u64,
        values: &mut [f64],
    ) -> anyhow::Result<()> {
        let mut want = self.cells.iter().peekable();
        let (mut col, mut start) = (0usize, 0usize);
        while let Some(&&(target, slot)) = want.peek() {
            let end = line[start..]
                .iter()
                .position(|&b| b == b',')
                .map_or(line.len(), |i| start + i);
            if col == target {
                values[slot] = self.cell(&line[start..end], line_no, slot)?;
                want.next();
            }
            if end >= line.len() {
                if let Some(&&(_, slot)) = want.peek() {
                    bail!(
                        "line {line_no}: {} cells, no column {}",
                        col + 1,
                        self.names[slot]
                    );
                }
                break;
            }
            start = end + 1;
            col += 1;
        }
        Ok(())
    }

    fn cell(&self, cell: &[u8], line_no: u64, slot: usize) -> anyhow::Result<f64> {
        let v = parse_cell(cell).ok_or_else(|| {
            anyhow!(
                "line {line_no}, column {}: \"{}\" is not a finite number",
                self.names[slot],
                String::from_utf8_lossy(cell).trim()
            )
        })?;
        in_range(v).map_err(|why| anyhow!("line {line_no}, column {}: {why}", self.names[slot]))
    }
}

/// `v` when it is a number the Allan sums can take, else why not.
pub(crate) fn in_range(v: f64) -> Result<f64, String> {
    if !v.is_finite() {
        return Err(format!("{v} is not a finite number"));
    }
    if v.abs() > MAX_MAGNITUDE {
        return Err(format!(
            "{v:e} is too large (|value| above {MAX_MAGNITUDE:e}: the Allan sums of its squares would overflow)"
        ));
    }
    Ok(v)
}

/// Where the rows come from: the CSV's lines ([`Rows`]) or a recording's
/// samples (`super::record_rows`).
pub(crate) trait RowSource: Send {
    /// Reads the next row into `values` (by slot); false at the end.
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool>;
    /// Appends up to `rows` rows to `block`, `values` (a row's length) the
    /// scratch row; false when the rows ended first. On an error the rows
    /// before it are in `block`.
    fn next_rows(
        &mut self,
        block: &mut Vec<f64>,
        values: &mut [f64],
        rows: usize,
    ) -> anyhow::Result<bool> {
        for _ in 0..rows {
            if !self.next_row(values)? {
                return Ok(false);
            }
            block.extend_from_slice(values);
        }
        Ok(true)
    }
    /// The next block of rows (at most [`BLOCK_ROWS`] of them where read
    /// here; a source that reads ahead gives its own), None at the end.
    fn next_block(&mut self) -> anyhow::Result<Option<Vec<f64>>> {
        let width = self.width();
        let mut values = vec![0.0; width];
        let mut block = Vec::with_capacity(BLOCK_ROWS * width);
        self.next_rows(&mut block, &mut values, BLOCK_ROWS)?;
        Ok((!block.is_empty()).then_some(block))
    }
    /// True when the rows are read and checked on threads of their own
    /// ([`Self::next_block`] then only waits for them); else the Allan
    /// side reads them on a thread it starts.
    const READS_AHEAD: bool = false;
    /// Values per row.
    fn width(&self) -> usize;
    /// The t column's check, from its first row on.
    fn time(&self) -> Option<&TimeCheck>;
    /// Bytes read so far (0: not counted).
    fn bytes(&self) -> u64;
}

impl RowSource for Rows {
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        Rows::next_row(self, values)
    }

    fn width(&self) -> usize {
        self.parser.names.len()
    }

    fn time(&self) -> Option<&TimeCheck> {
        self.time.as_ref()
    }

    fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// The largest |value| analysed: a second difference of sums of up to 2^40
/// samples, squared and summed 2^40 times, stays far below f64's 1.8e308
/// (2^92·(1e100)² = 5e227); no sensor reads anywhere near it.
pub(crate) const MAX_MAGNITUDE: f64 = 1e100;

/// A cell's finite number, spaces around it allowed.
fn parse_cell(cell: &[u8]) -> Option<f64> {
    let s = std::str::from_utf8(cell).ok()?.trim();
    let v: f64 = s.parse().ok()?;
    v.is_finite().then_some(v)
}

/// The line without its line ending.
fn trim_line(line: &[u8]) -> &[u8] {
    let mut end = line.len();
    while end > 0 && (line[end - 1] == b'\n' || line[end - 1] == b'\r') {
        end -= 1;
    }
    &line[..end]
}

/// The CSV opened: its header line, its size, and the reader after the header.
pub(crate) struct Opened {
    /// Its name in messages (a recording read as CSV says so).
    pub(crate) name: String,
    /// The header, trimmed.
    pub(crate) header: String,
    /// The file's size in bytes (0 when unknown).
    pub(crate) size: u64,
    reader: Box<dyn BufRead + Send>,
    header_bytes: u64,
}

/// Opens the CSV at `path` (`-`: standard input; `name` in messages) and
/// reads its header (a byte-order mark before it dropped).
pub(crate) fn open(path: &Path, name: &str) -> anyhow::Result<Opened> {
    let opened = input::open(path, 1 << 20)?;
    let mut reader = opened.reader;
    let mut line = Vec::with_capacity(256);
    let header_bytes = reader
        .read_until(b'\n', &mut line)
        .with_context(|| format!("{name}: cannot read"))?;
    if header_bytes == 0 {
        bail!("{name}: empty file (no header)");
    }
    Ok(Opened {
        name: opened.name,
        header: String::from_utf8_lossy(strip_bom_bytes(&line))
            .trim()
            .to_string(),
        size: opened.size,
        reader,
        header_bytes: header_bytes as u64,
    })
}

/// The rows after the header: line splitting, parsing, the t check.
pub(crate) struct Rows {
    name: String,
    reader: Box<dyn BufRead + Send>,
    line: Vec<u8>,
    line_no: u64,
    parser: RowParser,
    /// Slot of t in a row, when the rate comes from t.
    t_slot: Option<usize>,
    /// The t column's check, from its first row on.
    pub(crate) time: Option<TimeCheck>,
    /// Bytes read so far, header included.
    pub(crate) bytes: u64,
}

impl Rows {
    /// The rows of `opened` as `layout` reads them (`name` in messages).
    pub(crate) fn new(opened: Opened, layout: &Layout, name: &str) -> Rows {
        Rows {
            name: name.to_string(),
            reader: opened.reader,
            line: Vec::with_capacity(256),
            line_no: 1,
            parser: RowParser {
                cells: layout.cells.clone(),
                names: layout.names.clone(),
            },
            t_slot: layout.t_slot,
            time: None,
            bytes: opened.header_bytes,
        }
    }

    /// Reads the next non-empty row into `values`; false at the end.
    pub(crate) fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        loop {
            self.line.clear();
            let n = self.reader.read_until(b'\n', &mut self.line)?;
            if n == 0 {
                return Ok(false);
            }
            self.bytes += n as u64;
            self.line_no += 1;
            let trimmed = trim_line(&self.line);
            if trimmed.is_empty() {
                continue;
            }
            let name = &self.name;
            self.parser
                .parse(trimmed, self.line_no, values)
                .map_err(|e| anyhow!("{name}: {e}"))?;
            if let Some(slot) = self.t_slot {
                self.check_time(values[slot])?;
            }
            return Ok(true);
        }
    }

    fn check_time(&mut self, t: f64) -> anyhow::Result<()> {
        match &mut self.time {
            None => self.time = Some(TimeCheck::new(t)),
            Some(tc) => tc
                .next(t, self.line_no)
                .map_err(|e| anyhow!("{}: {e}", self.name))?,
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parser() -> RowParser {
        // Cells 0 (t, slot 2), 2 (ay, slot 0) and 4 (gx, slot 1).
        RowParser {
            cells: vec![(0, 2), (2, 0), (4, 1)],
            names: vec!["ay".into(), "gx".into(), "t".into()],
        }
    }

    #[test]
    fn the_wanted_cells_land_in_their_slots() {
        let mut v = [0.0; 3];
        parser().parse(b"0.5,1,2.5, -3e-2 ,4", 2, &mut v).unwrap();
        assert_eq!(v, [2.5, 4.0, 0.5]);
        // Cells after the last wanted one are not looked at.
        parser()
            .parse(b"1,x,2,y,3,not a number", 2, &mut v)
            .unwrap();
        assert_eq!(v, [2.0, 3.0, 1.0]);
    }

    #[test]
    fn a_bad_or_missing_cell_names_line_and_column() {
        let mut v = [0.0; 3];
        let err = parser().parse(b"0,1,nan,3,4", 7, &mut v).unwrap_err();
        assert_eq!(
            err.to_string(),
            "line 7, column ay: \"nan\" is not a finite number"
        );
        let err = parser().parse(b"0,1,2", 9, &mut v).unwrap_err();
        assert_eq!(err.to_string(), "line 9: 3 cells, no column gx");
    }

    #[test]
    fn line_endings_are_trimmed_and_cells_parsed_strictly() {
        assert_eq!(trim_line(b"1,2\r\n"), b"1,2");
        assert_eq!(trim_line(b"\n"), b"");
        assert_eq!(parse_cell(b" 1.5 "), Some(1.5));
        assert_eq!(parse_cell(b"inf"), None);
        assert_eq!(parse_cell(b""), None);
    }
}
