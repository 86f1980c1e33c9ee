//! The text formats' common reading: lines counted from 1, a byte-order
//! mark dropped, blank lines skipped, each other line parsed by the format
//! into a sample (or skipped, for a comment).

use std::io::BufRead;
use std::path::Path;

use anyhow::{anyhow, Context};

use super::{Reader, Sample, CHUNK};
use crate::plumbing::input::{self, strip_bom};

/// Parses one line (trimmed, not blank) numbered `line` into a sample, or
/// None to skip it; the error says what is wrong (the file and line are added).
pub type ParseLine = Box<dyn FnMut(&str, u64) -> anyhow::Result<Option<Sample>> + Send>;

/// A text record being read.
pub struct TextLines {
    name: String,
    reader: Box<dyn BufRead + Send>,
    line: String,
    number: u64,
    parse: ParseLine,
}

/// The first non-blank line of `path` (its header) and the reader after it,
/// with the line number reached; `name` in messages.
pub fn open_with_header(
    path: &Path,
) -> anyhow::Result<(String, String, Box<dyn BufRead + Send>, u64)> {
    let opened = input::open_bytes(path, 1 << 20)?;
    let mut reader = opened.reader;
    let mut line = String::new();
    let mut number = 0;
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .with_context(|| format!("{}: cannot read", opened.name))?;
        number += 1;
        if n == 0 {
            anyhow::bail!("{}: empty file (no header)", opened.name);
        }
        let header = strip_bom(&line).trim();
        if !header.is_empty() {
            return Ok((opened.name, header.to_string(), reader, number));
        }
    }
}

impl TextLines {
    /// Reads the lines of `reader` after line `number` with `parse`.
    pub fn new(
        name: String,
        reader: Box<dyn BufRead + Send>,
        number: u64,
        parse: ParseLine,
    ) -> Self {
        TextLines {
            name,
            reader,
            line: String::new(),
            number,
            parse,
        }
    }
}

impl Reader for TextLines {
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>> {
        let mut chunk = Vec::with_capacity(CHUNK);
        while chunk.len() < CHUNK {
            self.line.clear();
            let n = self.reader.read_line(&mut self.line).map_err(|e| {
                anyhow!("{}: cannot read after line {}: {e}", self.name, self.number)
            })?;
            if n == 0 {
                break;
            }
            self.number += 1;
            let text = strip_bom(&self.line).trim();
            if text.is_empty() {
                continue;
            }
            let at = self.number;
            if let Some(s) =
                (self.parse)(text, at).map_err(|e| anyhow!("{}, line {at}: {e}", self.name))?
            {
                chunk.push(s);
            }
        }
        Ok((!chunk.is_empty()).then_some(chunk))
    }
}

/// A cell's finite number; the error names the column and the cell.
pub fn number(cell: &str, column: &str) -> anyhow::Result<f64> {
    cell.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| anyhow!("column {column}: `{}` is not a finite number", cell.trim()))
}
