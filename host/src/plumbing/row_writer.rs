//! A buffered writer of whole lines that knows how many lines the output
//! took: `triad decode` reports rows stored, not rows formatted, when the
//! output fails midway (a full disk accepts part of a buffer, then refuses).

use std::io::{self, Write};

/// Lines buffered, then written; counts the lines the output accepted whole.
pub struct RowWriter<W: Write> {
    out: W,
    buffer: Vec<u8>,
    /// End offset in `buffer` of each line it holds, in order.
    ends: Vec<usize>,
    /// Lines the output took whole.
    stored: u64,
    capacity: usize,
}

impl<W: Write> RowWriter<W> {
    /// A writer to `out` flushing every `capacity` bytes.
    pub fn new(out: W, capacity: usize) -> Self {
        Self {
            out,
            buffer: Vec::with_capacity(capacity + 256),
            ends: Vec::new(),
            stored: 0,
            capacity,
        }
    }

    /// Appends one line (a newline added); writes the buffer when full.
    pub fn line(&mut self, text: std::fmt::Arguments<'_>) -> io::Result<()> {
        self.buffer.write_fmt(text)?;
        self.buffer.push(b'\n');
        self.ends.push(self.buffer.len());
        if self.buffer.len() >= self.capacity {
            self.flush()?;
        }
        Ok(())
    }

    /// Lines the output has taken whole.
    pub fn stored(&self) -> u64 {
        self.stored
    }

    /// The output.
    pub fn get_ref(&self) -> &W {
        &self.out
    }

    /// The output, once flushed (what is still buffered is dropped).
    pub fn into_inner(self) -> W {
        self.out
    }

    /// Writes what is buffered, counting each line as it is taken; on an
    /// error the lines not taken stay buffered (and uncounted).
    pub fn flush(&mut self) -> io::Result<()> {
        let mut written = 0;
        let result = loop {
            if written == self.buffer.len() {
                break self.out.flush();
            }
            match self.out.write(&self.buffer[written..]) {
                Ok(0) => break Err(io::Error::from(io::ErrorKind::WriteZero)),
                Ok(n) => written += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break Err(e),
            }
        };
        let whole = self.ends.partition_point(|&end| end <= written);
        self.stored += whole as u64;
        self.ends.drain(..whole);
        self.buffer.drain(..written);
        for end in &mut self.ends {
            *end -= written;
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Takes `room` bytes, then reports a full disk.
    struct Full {
        room: usize,
        taken: Vec<u8>,
    }

    impl Write for Full {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::from_raw_os_error(28));
            }
            let n = buf.len().min(self.room);
            self.room -= n;
            self.taken.extend_from_slice(&buf[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn only_lines_taken_whole_are_counted() {
        // "row 0\n" is 6 bytes: 20 bytes of room take 3 lines and part of a 4th.
        let mut w = RowWriter::new(
            Full {
                room: 20,
                taken: Vec::new(),
            },
            1 << 16,
        );
        for i in 0..10 {
            w.line(format_args!("row {i}")).unwrap();
        }
        assert_eq!(w.stored(), 0);
        assert!(w.flush().is_err());
        assert_eq!(w.stored(), 3);
        assert_eq!(w.get_ref().taken.len(), 20);
    }

    #[test]
    fn a_full_buffer_is_written_and_counted() {
        let mut w = RowWriter::new(Vec::new(), 10);
        w.line(format_args!("12345")).unwrap();
        assert_eq!(w.stored(), 0);
        w.line(format_args!("67890")).unwrap();
        assert_eq!(w.stored(), 2);
        w.line(format_args!("x")).unwrap();
        w.flush().unwrap();
        assert_eq!(
            (w.stored(), w.get_ref().as_slice()),
            (3, &b"12345\n67890\nx\n"[..])
        );
    }
}
