//! A record as triad's CSV: `t` then the triads and temperature it has
//! (`t,ax,ay,az,gx,gy,gz,temp` at most), SI units, every number in the
//! shortest form that reads back to the same f64, so the CSV carries the
//! record exactly. [`CsvStream`] makes the text as it is read: the commands
//! whose parsers read CSV take any record through it.

use std::io::{self, Read, Write};

use super::{Channels, Opened, Reader, Sample};

/// The header line (without its line ending) of a record with `channels`.
pub fn header(channels: Channels) -> String {
    let mut names = vec!["t"];
    if channels.accel {
        names.extend(["ax", "ay", "az"]);
    }
    if channels.gyro {
        names.extend(["gx", "gy", "gz"]);
    }
    if channels.temp {
        names.push("temp");
    }
    names.join(",")
}

/// Writes the row of `s` (with its line ending).
pub fn row(out: &mut impl Write, channels: Channels, s: &Sample) -> io::Result<()> {
    write!(out, "{}", s.t)?;
    if channels.accel {
        write!(out, ",{},{},{}", s.accel[0], s.accel[1], s.accel[2])?;
    }
    if channels.gyro {
        write!(out, ",{},{},{}", s.gyro[0], s.gyro[1], s.gyro[2])?;
    }
    if channels.temp {
        write!(out, ",{}", s.temp)?;
    }
    out.write_all(b"\n")
}

/// The CSV text of a record, made as it is read.
pub struct CsvStream {
    channels: Channels,
    reader: Box<dyn Reader>,
    text: Vec<u8>,
    pos: usize,
    done: bool,
}

impl CsvStream {
    /// The CSV of `opened`, its header first.
    pub fn new(opened: Opened) -> CsvStream {
        let channels = opened.source.channels;
        CsvStream {
            channels,
            reader: opened.reader,
            text: format!("{}\n", header(channels)).into_bytes(),
            pos: 0,
            done: false,
        }
    }
}

impl Read for CsvStream {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        while self.pos == self.text.len() && !self.done {
            self.text.clear();
            self.pos = 0;
            match self.reader.next_chunk() {
                Ok(Some(chunk)) => {
                    for s in &chunk {
                        row(&mut self.text, self.channels, s)?;
                    }
                }
                Ok(None) => self.done = true,
                Err(e) => return Err(io::Error::other(format!("{e:#}"))),
            }
        }
        let n = buf.len().min(self.text.len() - self.pos);
        buf[..n].copy_from_slice(&self.text[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}
