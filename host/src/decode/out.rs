//! Where `triad decode` and `triad device stream` put their rows: standard
//! output (the CSV, as before), or `--out FILE`, written whole or not at
//! all: the CSV, or for a name ending `.mcap` an MCAP
//! ([`crate::record::mcap_out`]) whose messages are made from the rows as they are
//! written (the same numbers the CSV would carry, each frame's sequence
//! number and flags on their own topic).

use std::fs::File;
use std::io::{self, Write};
use std::path::Path;

use anyhow::anyhow;

use crate::decode::rows::CSV_HEADER;
use crate::plumbing::outfile::OutFile;
use crate::plumbing::stdio;
use crate::record::mcap_out::McapWriter;
use crate::record::Sample;

/// The rows' destination.
pub enum StreamOut {
    /// Standard output.
    Stdout(File),
    /// A CSV file.
    Csv(OutFile),
    /// An MCAP file, fed the CSV's lines.
    Mcap(Box<McapRows>),
}

impl StreamOut {
    /// `--out PATH` (`.mcap`: MCAP), else standard output.
    pub fn open(out: Option<&Path>) -> anyhow::Result<StreamOut> {
        let Some(path) = out.filter(|p| !crate::plumbing::outfile::is_stdout(p)) else {
            return Ok(StreamOut::Stdout(stdio::raw_stdout()?));
        };
        let file = OutFile::create(path)?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
        {
            let writer = McapWriter::with_frames(file)?;
            Ok(StreamOut::Mcap(Box::new(McapRows {
                writer,
                line: Vec::new(),
                lines: 0,
            })))
        } else {
            Ok(StreamOut::Csv(file))
        }
    }

    /// Ends the output: standard output synced where it is a file; a file
    /// (its MCAP summary written) put in place.
    pub fn finish(self) -> anyhow::Result<()> {
        match self {
            StreamOut::Stdout(f) => {
                stdio::sync_if_file(&f).map_err(|e| anyhow!("{e} (when syncing)"))
            }
            StreamOut::Csv(f) => f.commit(),
            StreamOut::Mcap(m) => m.writer.finish()?.commit(),
        }
    }
}

impl Write for StreamOut {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            StreamOut::Stdout(f) => f.write(buf),
            StreamOut::Csv(f) => f.write(buf),
            StreamOut::Mcap(m) => m.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self {
            StreamOut::Stdout(f) => f.flush(),
            StreamOut::Csv(f) => f.flush(),
            StreamOut::Mcap(_) => Ok(()),
        }
    }
}

/// The CSV's lines (`seq,t,ax,ay,az,gx,gy,gz,temp,flags`) as MCAP messages.
pub struct McapRows {
    writer: McapWriter<OutFile>,
    line: Vec<u8>,
    lines: u64,
}

impl McapRows {
    /// Writes the message of one line (the header is checked, not written).
    fn line(&mut self, line: &str) -> anyhow::Result<()> {
        self.lines += 1;
        if self.lines == 1 {
            if line != CSV_HEADER {
                return Err(anyhow!("unexpected header `{line}`"));
            }
            return Ok(());
        }
        let cells: Vec<&str> = line.split(',').collect();
        let [seq, t, ax, ay, az, gx, gy, gz, temp, flags] = cells[..] else {
            return Err(anyhow!("row {}: {} cells, not 10", self.lines, cells.len()));
        };
        let f = |c: &str| {
            c.parse::<f64>()
                .map_err(|_| anyhow!("row {}: `{c}` is not a number", self.lines))
        };
        let mut s = Sample::at(self.lines, f(t)?);
        s.accel = [f(ax)?, f(ay)?, f(az)?];
        s.gyro = [f(gx)?, f(gy)?, f(gz)?];
        s.temp = f(temp)?;
        let seq = seq
            .parse()
            .map_err(|_| anyhow!("row {}: seq `{seq}`", self.lines))?;
        let flags = flags
            .parse()
            .map_err(|_| anyhow!("row {}: flags `{flags}`", self.lines))?;
        self.writer.write_frame(&s, seq, flags)
    }
}

impl Write for McapRows {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            if b == b'\n' {
                let line = String::from_utf8_lossy(&self.line).into_owned();
                self.line.clear();
                self.line(&line)
                    .map_err(|e| io::Error::other(format!("{e:#}")))?;
            } else {
                self.line.push(b);
            }
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
