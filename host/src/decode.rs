//! `triad decode`: the firmware's binary stream (docs/PROTOCOL.md) → CSV.
//!
//! Reads a serial port, a file or standard input with a fixed buffer and the
//! core's [`Decoder`], so memory stays constant however long the stream.
//! CSV goes to stdout (columns and number formats: docs/PROTOCOL.md §11);
//! rejected frames (with --verbose) and the final counters go to stderr.

use std::fs::File;
use std::io::{self, BufWriter, ErrorKind, Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context};
use triad::stream::{DecodeError, Decoder, DecoderStats, Frame, TimestampUnwrapper};

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
    #[arg(long, value_name = "N", default_value_t = 115_200)]
    pub baud: u32,
    /// Stop after N good frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<u64>,
    /// Stop after S seconds of stream time (by the frames' timestamps,
    /// counted from the first good frame).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Report every rejected frame on stderr, not only the totals.
    #[arg(long)]
    pub verbose: bool,
}

/// Runs `triad decode`.
pub fn run(args: DecodeArgs) -> anyhow::Result<ExitCode> {
    let limits = Limits::from_args(&args)?;
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = Arc::clone(&interrupted);
        // If a handler cannot be installed, Ctrl-C still ends the program,
        // only without the summary: not worth refusing to decode.
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let (source, live) = open_source(&args)?;
    let stdout = io::stdout();
    let mut csv = BufWriter::new(stdout.lock());
    let outcome = decode_stream(source, live, &mut csv, &limits, &interrupted, args.verbose)?;
    print_summary(&outcome);
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
            Some(s) if s.is_finite() && s > 0.0 && s * 1e6 < u64::MAX as f64 => {
                Some((s * 1e6).round() as u64)
            }
            Some(s) => bail!("--seconds {s}: must be a positive, finite number of seconds"),
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

/// The input and whether it is a live link (flushed line by line).
fn open_source(args: &DecodeArgs) -> anyhow::Result<(Box<dyn Read>, bool)> {
    if let Some(port) = &args.port {
        let serial = serialport::new(port.as_str(), args.baud)
            .timeout(PORT_POLL)
            .open()
            .with_context(|| format!("cannot open serial port {port} at {} baud", args.baud))?;
        return Ok((Box::new(serial), true));
    }
    match &args.input {
        None => Ok((Box::new(io::stdin()), false)),
        Some(path) if path.as_os_str() == "-" => Ok((Box::new(io::stdin()), false)),
        Some(path) => {
            let file =
                File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
            Ok((Box::new(file), false))
        }
    }
}

/// Why decoding stopped, and what the decoder counted.
struct Outcome {
    stats: DecoderStats,
    rows: u64,
    pending_bytes: u64,
    stop: Stop,
}

#[derive(Debug, PartialEq, Eq)]
enum Stop {
    EndOfInput,
    MaxFrames,
    Seconds,
    Interrupted,
    OutputClosed,
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

fn decode_stream(
    mut source: Box<dyn Read>,
    live: bool,
    csv: &mut impl Write,
    limits: &Limits,
    interrupted: &AtomicBool,
    verbose: bool,
) -> anyhow::Result<Outcome> {
    let mut decoder = Decoder::new();
    let mut clock = TimestampUnwrapper::new();
    let mut first_us = None;
    let mut buffer = [0u8; 4096];
    let mut written = 0u64;
    let mut stop = write_line(csv, format_args!("{CSV_HEADER}"))
        .err()
        .map(|_| Stop::OutputClosed);
    if limits.max_frames == Some(0) {
        stop = stop.or(Some(Stop::MaxFrames));
    }
    'read: while stop.is_none() {
        if interrupted.load(Ordering::SeqCst) {
            stop = Some(Stop::Interrupted);
            break;
        }
        let n = match source.read(&mut buffer) {
            Ok(0) => {
                stop = Some(Stop::EndOfInput);
                break;
            }
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::Interrupted) => continue,
            // A serial port that goes away (USB unplugged, pty closed) reads
            // as EIO on Unix: the stream has ended, the summary still counts.
            Err(e) if live && is_port_gone(&e) => {
                stop = Some(Stop::PortClosed(e.to_string()));
                break;
            }
            Err(e) => return Err(e).context("reading the stream"),
        };
        for result in decoder.feed(&buffer[..n]) {
            let frame = match result {
                Ok(frame) => frame,
                Err(error) => {
                    if verbose {
                        report_rejected(&error);
                    }
                    continue;
                }
            };
            let t_us = clock.unwrap(frame.timestamp_us);
            let t0 = *first_us.get_or_insert(t_us);
            if limits
                .max_elapsed_us
                .is_some_and(|limit| t_us.saturating_sub(t0) >= limit)
            {
                stop = Some(Stop::Seconds);
                break 'read;
            }
            if write_frame(csv, &frame, t_us).is_err() {
                stop = Some(Stop::OutputClosed);
                break 'read;
            }
            written += 1;
            if limits.max_frames.is_some_and(|max| written >= max) {
                stop = Some(Stop::MaxFrames);
                break 'read;
            }
        }
        if live && csv.flush().is_err() {
            stop = Some(Stop::OutputClosed);
        }
    }
    if csv.flush().is_err() {
        stop = Some(Stop::OutputClosed);
    }
    Ok(Outcome {
        stats: *decoder.stats(),
        rows: written,
        pending_bytes: decoder.pending_bytes(),
        stop: stop.unwrap_or(Stop::EndOfInput),
    })
}

/// One CSV line. `t` is printed exactly (integer µs as seconds with six
/// decimals); the values with `{:?}`, the shortest decimal that parses back
/// to the same f32 (exponent form for very large or small magnitudes).
fn write_frame(csv: &mut impl Write, f: &Frame, t_us: u64) -> io::Result<()> {
    let [ax, ay, az] = f.accel;
    let [gx, gy, gz] = f.gyro;
    write_line(
        csv,
        format_args!(
            "{},{}.{:06},{ax:?},{ay:?},{az:?},{gx:?},{gy:?},{gz:?},{:?},{}",
            f.sequence,
            t_us / 1_000_000,
            t_us % 1_000_000,
            f.temperature,
            f.flags.bits()
        ),
    )
}

fn write_line(csv: &mut impl Write, line: std::fmt::Arguments<'_>) -> io::Result<()> {
    csv.write_fmt(line)?;
    csv.write_all(b"\n")
}

fn report_rejected(error: &DecodeError) {
    eprintln!("triad decode: rejected frame: {error}");
}

fn print_summary(outcome: &Outcome) {
    let s = &outcome.stats;
    let why = match &outcome.stop {
        Stop::EndOfInput => "end of input".to_string(),
        Stop::MaxFrames => "--max-frames reached".to_string(),
        Stop::Seconds => "--seconds reached".to_string(),
        Stop::Interrupted => "interrupted".to_string(),
        Stop::OutputClosed => "output closed".to_string(),
        Stop::PortClosed(reason) => format!("port closed ({reason})"),
    };
    eprintln!("triad decode: stopped at {why}");
    eprintln!(
        "frames: {} ({} written as CSV rows)",
        s.frames, outcome.rows
    );
    eprintln!("crc errors: {}", s.crc_errors);
    eprintln!("malformed: {}", s.malformed);
    eprintln!(
        "sequence gaps: {} ({} frames lost)",
        s.sequence_gaps, s.frames_lost
    );
    eprintln!("sequence restarts: {}", s.sequence_restarts);
    eprintln!("bytes: {} ({} skipped)", s.bytes, s.bytes_skipped);
    if outcome.pending_bytes > 0 {
        eprintln!(
            "incomplete frame at the end: {} bytes",
            outcome.pending_bytes
        );
    }
    eprintln!(
        "device reported: {} overruns, {} frames dropped",
        s.device_overruns, s.device_dropped
    );
}
