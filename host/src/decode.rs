//! `triad decode`: the firmware's binary stream (docs/PROTOCOL.md) → CSV.
//!
//! Reads a serial port, a file or standard input with a fixed buffer and the
//! core's [`Decoder`], so memory stays constant however long the stream.
//! CSV goes to stdout (columns and number formats: docs/PROTOCOL.md §11);
//! rejected frames (with --verbose) and the final counters go to stderr.

use std::io::{self, ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use anyhow::{bail, Context};
use triad::stream::{DecodeError, Decoder, DecoderStats, Frame, TimestampUnwrapper};

use crate::input;
use crate::interrupt;
use crate::number::{positive, refused};
use crate::progress::{Progress, Unit};
use crate::row_writer::RowWriter;
use crate::stdio::{self, note, ReaderGone};

/// The CSV header (column order of every line).
pub const CSV_HEADER: &str = "seq,t,ax,ay,az,gx,gy,gz,temp,flags";

/// How long one read of a serial port waits before checking for Ctrl-C.
const PORT_POLL: Duration = Duration::from_millis(100);

/// Arguments of `triad decode`.
#[derive(clap::Args)]
pub struct DecodeArgs {
    /// Recorded stream to decode; `-` or nothing reads standard input.
    #[arg(value_name = "FILE", conflicts_with = "port")]
    pub input: Option<PathBuf>,
    /// Serial port to read (e.g. /dev/ttyACM0, COM3) until Ctrl-C or a limit.
    #[arg(long, value_name = "DEV")]
    pub port: Option<String>,
    /// Baud rate of --port (8N1).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 115_200,
        allow_negative_numbers = true
    )]
    pub baud: u32,
    /// Stop after N good frames.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub max_frames: Option<u64>,
    /// Stop after S seconds of stream time (by the frames' timestamps,
    /// counted from the first good frame).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Report every rejected frame on stderr, not only the totals.
    #[arg(long)]
    pub verbose: bool,
}

/// Bytes of CSV buffered before a write (a file or a pipe; a live port
/// flushes after every read).
const CSV_BUFFER: usize = 1 << 16;

/// Runs `triad decode`. The summary goes to stderr however decoding ends;
/// then a failed output is an error (the reader closing the pipe a quiet
/// one), and so is an input in which no frame decoded.
pub fn run(args: DecodeArgs) -> anyhow::Result<ExitCode> {
    let limits = Limits::from_args(&args)?;
    let interrupted = interrupt::flag();
    let source = open_source(&args)?;
    let mut csv = RowWriter::new(stdio::raw_stdout()?, CSV_BUFFER);
    let mut outcome = decode_stream(source, &mut csv, &limits, &interrupted, args.verbose)?;
    if outcome.failure.is_none() {
        if let Err(e) = stdio::sync_if_file(csv.get_ref()) {
            outcome.failure = Some(Failure::Output(format!("{e} (when syncing)")));
        }
    }
    note!("{}", summary(&outcome).trim_end());
    match outcome.failure {
        Some(Failure::ReaderGone) => return Err(ReaderGone.into()),
        Some(Failure::Output(e)) => bail!(
            "writing the CSV to standard output: {e}; {} rows stored",
            outcome.rows
        ),
        None => {}
    }
    if outcome.stats.frames == 0 && limits.max_frames != Some(0) {
        bail!(
            "no frame decoded from {} bytes: not a triad stream (docs/PROTOCOL.md), or the wrong port or baud rate",
            outcome.stats.bytes
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// When to stop before the end of the input.
struct Limits {
    max_frames: Option<u64>,
    max_elapsed_us: Option<u64>,
}

impl Limits {
    fn from_args(args: &DecodeArgs) -> anyhow::Result<Limits> {
        let max_elapsed_us = match args.seconds {
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
        if args.baud == 0 {
            bail!("--baud 0: the baud rate must be positive");
        }
        Ok(Limits {
            max_frames: args.max_frames,
            max_elapsed_us,
        })
    }
}

/// The input: the bytes, whether it is a live link (flushed line by line)
/// and its size (0 when unknown), for the progress.
struct Source {
    bytes: Box<dyn Read>,
    live: bool,
    size: u64,
}

/// The serial port of `--port`, else the file or standard input ([`input::open`]).
fn open_source(args: &DecodeArgs) -> anyhow::Result<Source> {
    if let Some(port) = &args.port {
        let serial = serialport::new(port.as_str(), args.baud)
            .timeout(PORT_POLL)
            .open()
            .with_context(|| format!("cannot open serial port {port} at {} baud", args.baud))?;
        return Ok(Source {
            bytes: Box::new(serial),
            live: true,
            size: 0,
        });
    }
    // No FILE is standard input, as `-` is.
    let path = args.input.as_deref().unwrap_or(Path::new("-"));
    let opened = input::open(path, 1 << 16)?;
    Ok(Source {
        bytes: Box::new(opened.reader),
        live: false,
        size: opened.size,
    })
}

/// Why decoding stopped, and what the decoder counted.
struct Outcome {
    stats: DecoderStats,
    /// Rows the output took whole.
    rows: u64,
    pending_bytes: u64,
    stop: Stop,
    /// Why the output failed, if it did.
    failure: Option<Failure>,
}

/// How the output failed.
#[derive(Debug, PartialEq, Eq)]
enum Failure {
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

#[derive(Debug, PartialEq, Eq)]
enum Stop {
    EndOfInput,
    MaxFrames,
    Seconds,
    Interrupted,
    OutputFailed,
    PortClosed(String),
}

/// EIO (5 on Linux and macOS) and the kinds that mean "the other end left".
fn is_port_gone(e: &io::Error) -> bool {
    const EIO: i32 = 5;
    e.raw_os_error() == Some(EIO)
        || matches!(
            e.kind(),
            ErrorKind::BrokenPipe | ErrorKind::UnexpectedEof | ErrorKind::ConnectionReset
        )
}

fn decode_stream<W: Write>(
    mut source: Source,
    csv: &mut RowWriter<W>,
    limits: &Limits,
    interrupted: &AtomicBool,
    verbose: bool,
) -> anyhow::Result<Outcome> {
    let mut decoder = Decoder::new();
    let mut sink = Sink {
        csv,
        limits,
        verbose,
        clock: TimestampUnwrapper::new(),
        first_us: None,
        formatted: 0,
        failure: None,
    };
    // About a second of reading: 64 MB.
    let progress = Progress::new(source.size, 64 << 20, Unit::Bytes);
    let mut buffer = [0u8; 4096];
    let mut stop = sink.start();
    while stop.is_none() {
        if interrupt::requested(interrupted) {
            stop = Some(Stop::Interrupted);
            break;
        }
        let n = match read_some(&mut *source.bytes, &mut buffer, source.live)? {
            Chunk::Bytes(n) => n,
            Chunk::Again => continue,
            Chunk::End(why) => {
                stop = Some(why);
                break;
            }
        };
        stop = sink.feed(&mut decoder, &buffer[..n]);
        if stop.is_none() && source.live {
            stop = sink.flush();
        }
        progress.update(decoder.stats().bytes);
    }
    if sink.failure.is_none() {
        if let Some(failed) = sink.flush() {
            stop = Some(failed);
        }
    }
    progress.finish();
    let failure = sink.failure.take();
    Ok(Outcome {
        stats: *decoder.stats(),
        // The header is not a row.
        rows: sink.csv.stored().saturating_sub(1),
        pending_bytes: decoder.pending_bytes(),
        stop: stop.unwrap_or(Stop::EndOfInput),
        failure,
    })
}

/// What one read of the source gave.
enum Chunk {
    /// Bytes to decode.
    Bytes(usize),
    /// Nothing yet (a port's poll timed out, a signal): read again.
    Again,
    /// The stream has ended.
    End(Stop),
}

fn read_some(source: &mut dyn Read, buffer: &mut [u8], live: bool) -> anyhow::Result<Chunk> {
    match source.read(buffer) {
        Ok(0) => Ok(Chunk::End(Stop::EndOfInput)),
        Ok(n) => Ok(Chunk::Bytes(n)),
        Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::Interrupted) => {
            Ok(Chunk::Again)
        }
        // A serial port that goes away (USB unplugged, pty closed) reads
        // as EIO on Unix: the stream has ended, the summary still counts.
        Err(e) if live && is_port_gone(&e) => Ok(Chunk::End(Stop::PortClosed(e.to_string()))),
        Err(e) => Err(e).context("reading the stream"),
    }
}

/// Where good frames go: the CSV, within the limits.
struct Sink<'a, W: Write> {
    csv: &'a mut RowWriter<W>,
    limits: &'a Limits,
    verbose: bool,
    clock: TimestampUnwrapper,
    /// The first good frame's time, µs.
    first_us: Option<u64>,
    /// Rows formatted (stored or still buffered).
    formatted: u64,
    failure: Option<Failure>,
}

impl<W: Write> Sink<'_, W> {
    /// Writes the header; stops at once when it cannot or no frame is wanted.
    fn start(&mut self) -> Option<Stop> {
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
    fn flush(&mut self) -> Option<Stop> {
        match self.csv.flush() {
            Ok(()) => None,
            Err(e) => Some(self.failed(&e)),
        }
    }

    /// Decodes `bytes` and writes each good frame; why to stop, if a limit
    /// is reached or the output failed.
    fn feed(&mut self, decoder: &mut Decoder, bytes: &[u8]) -> Option<Stop> {
        for result in decoder.feed(bytes) {
            match result {
                Ok(frame) => {
                    if let Some(stop) = self.frame(&frame) {
                        return Some(stop);
                    }
                }
                Err(error) if self.verbose => report_rejected(&error),
                Err(_) => {}
            }
        }
        None
    }

    /// One good frame: the time limit, the row, the frame limit.
    fn frame(&mut self, frame: &Frame) -> Option<Stop> {
        let t_us = self.clock.unwrap(frame.timestamp_us);
        let t0 = *self.first_us.get_or_insert(t_us);
        if self
            .limits
            .max_elapsed_us
            .is_some_and(|limit| t_us.saturating_sub(t0) >= limit)
        {
            return Some(Stop::Seconds);
        }
        if let Err(e) = write_frame(self.csv, frame, t_us) {
            return Some(self.failed(&e));
        }
        self.formatted += 1;
        self.limits
            .max_frames
            .is_some_and(|max| self.formatted >= max)
            .then_some(Stop::MaxFrames)
    }
}

/// One CSV line. `t` is printed exactly (integer µs as seconds with six
/// decimals); the values with `{:?}`, the shortest decimal that parses back
/// to the same f32 (exponent form for very large or small magnitudes).
fn write_frame<W: Write>(csv: &mut RowWriter<W>, f: &Frame, t_us: u64) -> io::Result<()> {
    let [ax, ay, az] = f.accel;
    let [gx, gy, gz] = f.gyro;
    csv.line(format_args!(
        "{},{}.{:06},{ax:?},{ay:?},{az:?},{gx:?},{gy:?},{gz:?},{:?},{}",
        f.sequence,
        t_us / 1_000_000,
        t_us % 1_000_000,
        f.temperature,
        f.flags.bits()
    ))
}

fn report_rejected(error: &DecodeError) {
    note!("triad decode: rejected frame: {error}");
}

/// Why decoding stopped and the decoder's counters, a line each.
fn summary(outcome: &Outcome) -> String {
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
        "triad decode: stopped at {why}\n\
         frames: {} ({} stored as CSV rows)\n\
         crc errors: {}\n\
         malformed: {}\n\
         sequence gaps: {} ({} frames lost)\n\
         sequence restarts: {}\n\
         bytes: {} ({} skipped)\n",
        s.frames,
        outcome.rows,
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
    use crate::fixtures::stream;

    fn decode(bytes: Vec<u8>, max_frames: Option<u64>, seconds: Option<f64>) -> (Outcome, String) {
        let limits = Limits {
            max_frames,
            max_elapsed_us: seconds.map(|s| (s * 1e6) as u64),
        };
        let mut csv = RowWriter::new(Vec::new(), 64);
        let source = Source {
            bytes: Box::new(io::Cursor::new(bytes)),
            live: false,
            size: 0,
        };
        let never = AtomicBool::new(false);
        let outcome = decode_stream(source, &mut csv, &limits, &never, false).unwrap();
        (outcome, String::from_utf8(csv.get_ref().clone()).unwrap())
    }

    #[test]
    fn every_frame_is_a_row_with_exact_time_and_values() {
        let (outcome, csv) = decode(stream(3), None, None);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], CSV_HEADER);
        assert_eq!(lines[1], "0,1.000000,0.5,-1.0,9.75,0.0,0.125,-2.0,25.5,0");
        assert_eq!(lines[3], "2,1.020000,0.5,-1.0,9.75,0.0,0.125,-2.0,25.5,0");
        assert_eq!((outcome.rows, outcome.stop), (3, Stop::EndOfInput));
        assert_eq!(outcome.stats.frames, 3);
    }

    #[test]
    fn the_limits_stop_the_stream() {
        let (outcome, csv) = decode(stream(10), Some(4), None);
        assert_eq!((outcome.rows, outcome.stop), (4, Stop::MaxFrames));
        assert_eq!(csv.lines().count(), 5);
        // 0.025 s from the first frame: frames at 0, 10 and 20 ms.
        let (outcome, _) = decode(stream(10), None, Some(0.025));
        assert_eq!((outcome.rows, outcome.stop), (3, Stop::Seconds));
        let (outcome, csv) = decode(stream(2), Some(0), None);
        assert_eq!(
            (outcome.rows, csv.as_str()),
            (0, "seq,t,ax,ay,az,gx,gy,gz,temp,flags\n")
        );
    }

    #[test]
    fn the_summary_says_why_and_counts() {
        let mut bytes = stream(2);
        bytes.extend_from_slice(&[1, 2, 3]);
        let (outcome, _) = decode(bytes, None, None);
        let text = summary(&outcome);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "triad decode: stopped at end of input");
        assert_eq!(lines[1], "frames: 2 (2 stored as CSV rows)");
        assert!(
            text.contains("incomplete frame at the end: 3 bytes\n"),
            "{text}"
        );
        assert!(lines
            .last()
            .unwrap()
            .starts_with("device reported: 0 overruns"));
    }

    #[test]
    fn seconds_must_be_positive_and_baud_non_zero() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            args: DecodeArgs,
        }
        let limits = |argv: &[&str]| {
            let cli = Cli::try_parse_from([&["decode"], argv].concat()).unwrap();
            Limits::from_args(&cli.args)
        };
        assert_eq!(
            limits(&["--seconds", "1.5"]).unwrap().max_elapsed_us,
            Some(1_500_000)
        );
        let err = limits(&["--seconds", "-1"]).err().unwrap().to_string();
        assert!(err.starts_with("--seconds -1: must be a positive"), "{err}");
        assert!(limits(&["--baud", "0"]).is_err());
    }
}
