//! The stream's packets as CSV rows, within limits, and the summary of what
//! the decoder counted: what `triad decode` and `triad device stream` print
//! (columns and number formats: docs/PROTOCOL.md §11).
//!
//! A data frame's row carries its corrected values; a raw frame's row the
//! chip's counts times the frame's nominal scale
//! ([`RawFrame::to_si`](triad::protocol::RawFrame::to_si), in `f32`), with its
//! flags as received (the device sets RAW and UNCALIBRATED). Replies and
//! commands are counted, not printed.

use std::io::{self, ErrorKind, Write};

use anyhow::bail;
use triad::protocol::{BatchFrame, Packet, RawFrame};
use triad::protocol::{DecodeError, DecoderStats, Flags, Frame, TimestampUnwrapper};

use crate::plumbing::number::{positive, refused};
use crate::plumbing::row_writer::RowWriter;
use crate::plumbing::stdio::note;

/// The CSV header (column order of every line).
pub const CSV_HEADER: &str = "seq,t,ax,ay,az,gx,gy,gz,temp,flags";

/// When to stop before the end of the input.
#[derive(Clone, Copy, Debug, Default)]
pub struct Limits {
    /// Stop after this many rows.
    pub max_frames: Option<u64>,
    /// Stop at this much stream time from the first frame, µs.
    pub max_elapsed_us: Option<u64>,
}

impl Limits {
    /// The limits of `--max-frames` and `--seconds` (positive and finite).
    pub fn new(max_frames: Option<u64>, seconds: Option<f64>) -> anyhow::Result<Limits> {
        let max_elapsed_us = match seconds {
            None => None,
            Some(s) => {
                let words = "must be a positive, finite number of seconds";
                let us = positive("--seconds", s, words)? * 1e6;
                // Beyond u64 µs (585 000 years) is no finite limit either.
                if us >= u64::MAX as f64 {
                    return Err(refused("--seconds", s, words));
                }
                Some(us.round() as u64)
            }
        };
        Ok(Limits {
            max_frames,
            max_elapsed_us,
        })
    }
}

/// Why the rows stopped.
#[derive(Debug, PartialEq, Eq)]
pub enum Stop {
    /// The input ended.
    EndOfInput,
    /// `--max-frames` rows were written.
    MaxFrames,
    /// `--seconds` of stream time went by.
    Seconds,
    /// Ctrl-C.
    Interrupted,
    /// The output failed (see [`Failure`]).
    OutputFailed,
    /// The serial port went away, with the system's reason.
    PortClosed(String),
}

/// How the output failed.
#[derive(Debug, PartialEq, Eq)]
pub enum Failure {
    /// The reader closed the pipe.
    ReaderGone,
    /// Any other write error (a full disk).
    Output(String),
}

impl Failure {
    fn of(e: &io::Error) -> Failure {
        if e.kind() == ErrorKind::BrokenPipe {
            Failure::ReaderGone
        } else {
            Failure::Output(e.to_string())
        }
    }
}

/// Where decoded packets go: the CSV, within the limits.
pub struct CsvSink<'a, W: Write> {
    csv: &'a mut RowWriter<W>,
    limits: Limits,
    verbose: bool,
    clock: TimestampUnwrapper,
    /// The first good frame's time, µs.
    first_us: Option<u64>,
    /// Rows formatted (stored or still buffered).
    formatted: u64,
    /// Why the output failed, if it did.
    pub failure: Option<Failure>,
    /// The name rejected frames are reported under (`triad decode`).
    command: &'static str,
}

impl<'a, W: Write> CsvSink<'a, W> {
    /// A sink writing to `csv` until `limits`; with `verbose`, each
    /// rejected frame is reported on stderr under `command`'s name.
    pub fn new(
        csv: &'a mut RowWriter<W>,
        limits: Limits,
        verbose: bool,
        command: &'static str,
    ) -> Self {
        Self {
            csv,
            limits,
            verbose,
            clock: TimestampUnwrapper::new(),
            first_us: None,
            formatted: 0,
            failure: None,
            command,
        }
    }

    /// Writes the header; stops at once when it cannot or no frame is wanted.
    pub fn start(&mut self) -> Option<Stop> {
        if let Err(e) = self.csv.line(format_args!("{CSV_HEADER}")) {
            return Some(self.failed(&e));
        }
        (self.limits.max_frames == Some(0)).then_some(Stop::MaxFrames)
    }

    /// Records why the output failed.
    fn failed(&mut self, e: &io::Error) -> Stop {
        self.failure = Some(Failure::of(e));
        Stop::OutputFailed
    }

    /// Writes what is buffered; why to stop if the output failed.
    pub fn flush(&mut self) -> Option<Stop> {
        match self.csv.flush() {
            Ok(()) => None,
            Err(e) => Some(self.failed(&e)),
        }
    }

    /// Rows the output took whole (the header is not a row).
    pub fn rows(&self) -> u64 {
        self.csv.stored().saturating_sub(1)
    }

    /// The output.
    pub fn output(&self) -> &W {
        self.csv.get_ref()
    }

    /// One decoded packet (or rejected frame): a row for a data or raw
    /// frame; why to stop, if a limit is reached or the output failed.
    pub fn packet(&mut self, decoded: &Result<Packet, DecodeError>) -> Option<Stop> {
        match decoded {
            Ok(Packet::Data(frame)) => self.row(&Row::of_frame(frame)),
            Ok(Packet::Raw(raw)) => self.row(&Row::of_raw(raw)),
            // One row per sample; the rows of a batch share its sequence number.
            Ok(Packet::Batch(batch)) => {
                (0..usize::from(batch.count)).find_map(|i| self.row(&Row::of_batch(batch, i)))
            }
            // Counted by the decoder, not printed.
            Ok(Packet::Reply(_) | Packet::Command(_)) => None,
            Err(error) => {
                if self.verbose {
                    note!("{}: rejected frame: {error}", self.command);
                }
                None
            }
        }
    }

    /// One row: the time limit, the row, the frame limit.
    fn row(&mut self, row: &Row) -> Option<Stop> {
        let t_us = self.clock.unwrap(row.timestamp_us);
        let t0 = *self.first_us.get_or_insert(t_us);
        if self
            .limits
            .max_elapsed_us
            .is_some_and(|limit| t_us.saturating_sub(t0) >= limit)
        {
            return Some(Stop::Seconds);
        }
        if let Err(e) = write_row(self.csv, row, t_us) {
            return Some(self.failed(&e));
        }
        self.formatted += 1;
        self.limits
            .max_frames
            .is_some_and(|max| self.formatted >= max)
            .then_some(Stop::MaxFrames)
    }
}

/// What a row shows of a frame.
struct Row {
    sequence: u32,
    timestamp_us: u32,
    accel: [f32; 3],
    gyro: [f32; 3],
    temperature: f32,
    flags: Flags,
}

impl Row {
    fn of_frame(f: &Frame) -> Row {
        Row {
            sequence: f.sequence,
            timestamp_us: f.timestamp_us,
            accel: f.accel,
            gyro: f.gyro,
            temperature: f.temperature,
            flags: f.flags,
        }
    }

    /// Sample `i` of a batch: its fixed point × the batch's LSBs, at the
    /// first sample's time plus i periods (rounded to the µs).
    fn of_batch(b: &BatchFrame, i: usize) -> Row {
        let (accel, gyro) = b.sample_si(i).unwrap_or_default();
        let offset_us = (u64::from(b.period_ns) * i as u64 + 500) / 1000;
        Row {
            sequence: b.sequence,
            timestamp_us: b.timestamp_us.wrapping_add(offset_us as u32),
            accel,
            gyro,
            temperature: b.temperature,
            flags: b.flags,
        }
    }

    /// Counts × the frame's nominal scale, flags as received.
    fn of_raw(f: &RawFrame) -> Row {
        let (accel, gyro, temperature) = f.to_si();
        Row {
            sequence: f.sequence,
            timestamp_us: f.timestamp_us,
            accel,
            gyro,
            temperature,
            flags: f.flags,
        }
    }
}

/// One CSV line. `t` is printed exactly (integer µs as seconds with six
/// decimals); the values with `{:?}`, the shortest decimal that parses back
/// to the same f32 (exponent form for very large or small magnitudes).
fn write_row<W: Write>(csv: &mut RowWriter<W>, r: &Row, t_us: u64) -> io::Result<()> {
    let [ax, ay, az] = r.accel;
    let [gx, gy, gz] = r.gyro;
    csv.line(format_args!(
        "{},{}.{:06},{ax:?},{ay:?},{az:?},{gx:?},{gy:?},{gz:?},{:?},{}",
        r.sequence,
        t_us / 1_000_000,
        t_us % 1_000_000,
        r.temperature,
        r.flags.bits()
    ))
}

/// Why decoding stopped, and what the decoder counted.
pub struct Outcome {
    /// The decoder's counters.
    pub stats: DecoderStats,
    /// Rows the output took whole.
    pub rows: u64,
    /// Bytes of a frame left incomplete at the end.
    pub pending_bytes: u64,
    /// Why it stopped.
    pub stop: Stop,
    /// Why the output failed, if it did.
    pub failure: Option<Failure>,
}

impl Outcome {
    /// The summary on stderr, then the output's failure as an error (the
    /// reader closing the pipe as [`crate::plumbing::stdio::ReaderGone`]).
    pub fn report(self, command: &str) -> anyhow::Result<Outcome> {
        note!("{}", summary(&self, command).trim_end());
        match &self.failure {
            Some(Failure::ReaderGone) => Err(crate::plumbing::stdio::ReaderGone.into()),
            Some(Failure::Output(e)) => bail!(
                "writing the CSV to standard output: {e}; {} rows stored",
                self.rows
            ),
            None => Ok(self),
        }
    }
}

/// Why decoding stopped and the decoder's counters, a line each, headed by
/// `command` (`triad decode`).
pub fn summary(outcome: &Outcome, command: &str) -> String {
    let s = &outcome.stats;
    let why = match &outcome.stop {
        Stop::EndOfInput => "end of input".to_string(),
        Stop::MaxFrames => "--max-frames reached".to_string(),
        Stop::Seconds => "--seconds reached".to_string(),
        Stop::Interrupted => "interrupted".to_string(),
        Stop::OutputFailed => match &outcome.failure {
            Some(Failure::ReaderGone) => "the reader closing standard output".to_string(),
            Some(Failure::Output(e)) => format!("an output error ({e})"),
            None => "an output error".to_string(),
        },
        Stop::PortClosed(reason) => format!("port closed ({reason})"),
    };
    let mut text = format!(
        "{command}: stopped at {why}\n\
         frames: {} ({} stored as CSV rows)\n\
         raw frames: {} (of those frames)\n\
         batch frames: {} (of those frames; {} samples)\n\
         messages: {} (replies and commands: counted, not printed)\n\
         crc errors: {}\n\
         malformed: {}\n\
         sequence gaps: {} ({} frames lost)\n\
         sequence restarts: {}\n\
         bytes: {} ({} skipped)\n",
        s.frames
            .saturating_add(s.raw_frames)
            .saturating_add(s.batch_frames),
        outcome.rows,
        s.raw_frames,
        s.batch_frames,
        s.batch_samples,
        s.messages,
        s.crc_errors,
        s.malformed,
        s.sequence_gaps,
        s.frames_lost,
        s.sequence_restarts,
        s.bytes,
        s.bytes_skipped
    );
    if outcome.pending_bytes > 0 {
        text += &format!(
            "incomplete frame at the end: {} bytes\n",
            outcome.pending_bytes
        );
    }
    text += &format!(
        "device reported: {} overruns, {} frames dropped\n",
        s.device_overruns, s.device_dropped
    );
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::protocol::RawScale;

    fn rows_of(packets: &[Packet]) -> String {
        let mut csv = RowWriter::new(Vec::new(), 64);
        let mut sink = CsvSink::new(&mut csv, Limits::default(), false, "test");
        assert_eq!(sink.start(), None);
        for p in packets {
            assert_eq!(sink.packet(&Ok(p.clone())), None);
        }
        assert_eq!(sink.flush(), None);
        String::from_utf8(csv.get_ref().clone()).unwrap()
    }

    #[test]
    fn a_raw_frame_is_a_row_of_counts_times_its_scale_with_its_flags() {
        let raw = RawFrame {
            sequence: 4,
            timestamp_us: 2_500_000,
            flags: Flags::RAW | Flags::UNCALIBRATED | Flags::GYRO_CLIPPED,
            accel: [2048.0, -1.0, 0.5],
            gyro: [16.0, 0.0, -32768.0],
            temperature: 132.48,
            scale: RawScale {
                accel_si_per_lsb: 0.25,
                gyro_si_per_lsb: 2.0,
                temperature_per_lsb: 0.5,
                temperature_offset: 25.0,
            },
            ..RawFrame::default()
        };
        let csv = rows_of(&[Packet::Raw(raw)]);
        let row = csv.lines().nth(1).unwrap();
        // 132.48 × 0.5 + 25 in f32, the flags' bits 0x62.
        let temp = 132.48f32 * 0.5 + 25.0;
        assert_eq!(
            row,
            format!("4,2.500000,512.0,-0.25,0.125,32.0,0.0,-65536.0,{temp:?},98")
        );
    }

    #[test]
    fn a_batch_samples_time_is_rounded_to_the_microsecond_halves_up() {
        // PROTOCOL.md §11: timestamp_us + ⌊(i · period_ns + 500) / 1000⌋.
        let mut batch = BatchFrame::new(1.0, 1.0);
        batch.timestamp_us = 1_000_000;
        batch.period_ns = 1_250; // 800 kHz: offsets 0, 1.25, 2.5, 3.75 µs
        batch.count = 4;
        let csv = rows_of(&[Packet::Batch(batch)]);
        let times: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|row| row.split(',').nth(1).unwrap())
            .collect();
        assert_eq!(times, ["1.000000", "1.000001", "1.000003", "1.000004"]);
    }

    #[test]
    fn replies_are_not_rows() {
        let reply = triad::protocol::Reply {
            sequence: 1,
            command: 1,
            status: triad::protocol::Status::Ok,
            payload: triad::protocol::Payload::EMPTY,
        };
        assert_eq!(rows_of(&[Packet::Reply(reply)]), format!("{CSV_HEADER}\n"));
    }
}
