//! `triad decode`: the firmware's binary stream (docs/PROTOCOL.md) → CSV.
//!
//! Reads a serial port, a file or standard input with a fixed buffer and the
//! core's [`Decoder`], so memory stays constant however long the stream.
//! Every packet of protocol version 2 is decoded: data frames and raw frames
//! become CSV rows ([`crate::decode::rows`]); replies and commands are counted.
//! CSV goes to stdout (columns and number formats: docs/PROTOCOL.md §11);
//! rejected frames (with --verbose) and the final counters go to stderr.

pub mod out;
pub mod rows;

use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use anyhow::{bail, Context};
use triad::protocol::Decoder;

use crate::decode::out::StreamOut;
use crate::decode::rows::{CsvSink, Failure, Limits, Outcome, Stop};
use crate::plumbing::distinct::named;
use crate::plumbing::input;
use crate::plumbing::interrupt;
use crate::plumbing::progress::{Progress, Unit};
use crate::plumbing::row_writer::RowWriter;
use crate::plumbing::serial;

pub use crate::decode::rows::CSV_HEADER;

/// How long one read of a serial port waits before checking for Ctrl-C.
const PORT_POLL: Duration = Duration::from_millis(100);

/// Arguments of `triad decode`.
#[derive(clap::Args)]
#[command(after_help = "\
Every frame is a CSV row with the columns seq,t,ax,ay,az,gx,gy,gz,temp,flags. \
A data frame's values are the device's corrected ones. A raw frame (protocol \
version 2, raw mode) becomes a row in the same columns: the chip's counts \
times the nominal scale the frame carries (m/s², rad/s, °C; computed in f32), \
its flags as received (the device sets RAW 0x40 and UNCALIBRATED 0x20). \
Replies and commands in the stream are counted in the summary, not printed.")]
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
    /// Stop after N good frames (data and raw).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub max_frames: Option<u64>,
    /// Stop after S seconds of stream time (by the frames' timestamps,
    /// counted from the first good frame).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Report every rejected frame on stderr, not only the totals.
    #[arg(long)]
    pub verbose: bool,
    /// Write the rows to FILE, whole or not at all, instead of standard
    /// output: the CSV, or for a name ending .mcap an MCAP (sensor_msgs/msg/Imu
    /// on /imu, the temperature on /imu/temperature, each frame's seq and
    /// flags on /imu/frame).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// Bytes of CSV buffered before a write (a file or a pipe; a live port
/// flushes after every read).
const CSV_BUFFER: usize = 1 << 16;

/// Runs `triad decode`. The summary goes to stderr however decoding ends;
/// then a failed output is an error (the reader closing the pipe a quiet
/// one), and so is an input in which no frame decoded.
pub fn run(args: DecodeArgs) -> anyhow::Result<ExitCode> {
    if args.baud == 0 {
        bail!("--baud 0: the baud rate must be positive");
    }
    let limits = Limits::new(args.max_frames, args.seconds)?;
    let interrupted = interrupt::flag();
    if let (Some(out), Some(input)) = (&args.out, &args.input) {
        crate::plumbing::distinct::check(&[named("input", input)], &[named("--out", out)])?;
    }
    let source = open_source(&args)?;
    let mut csv = RowWriter::new(StreamOut::open(args.out.as_deref())?, CSV_BUFFER);
    let mut outcome = decode_stream(source, &mut csv, limits, &interrupted, args.verbose)?;
    if outcome.failure.is_none() {
        if let Err(e) = csv.into_inner().finish() {
            outcome.failure = Some(Failure::Output(format!("{e:#}")));
        }
    }
    let outcome = outcome.report("triad decode")?;
    let s = &outcome.stats;
    if s.frames == 0 && s.raw_frames == 0 && s.batch_frames == 0 && limits.max_frames != Some(0) {
        bail!(
            "no frame decoded from {} bytes: not a triad stream (docs/PROTOCOL.md), or the wrong port or baud rate",
            s.bytes
        );
    }
    Ok(ExitCode::SUCCESS)
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
        let serial = serial::open(port, args.baud, PORT_POLL)?;
        return Ok(Source {
            bytes: Box::new(serial),
            live: true,
            size: 0,
        });
    }
    // No FILE is standard input, as `-` is.
    let path = args.input.as_deref().unwrap_or(Path::new("-"));
    // A stream of frames, not a record: its bytes as they are.
    let opened = input::open_bytes(path, 1 << 16)?;
    Ok(Source {
        bytes: Box::new(opened.reader),
        live: false,
        size: opened.size,
    })
}

fn decode_stream<W: Write>(
    mut source: Source,
    csv: &mut RowWriter<W>,
    limits: Limits,
    interrupted: &AtomicBool,
    verbose: bool,
) -> anyhow::Result<Outcome> {
    let mut decoder = Decoder::new();
    let mut sink = CsvSink::new(csv, limits, verbose, "triad decode");
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
        stop = decoder
            .feed_packets(&buffer[..n])
            .find_map(|decoded| sink.packet(&decoded));
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
        rows: sink.rows(),
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
        Err(e) if live && serial::is_port_gone(&e) => {
            Ok(Chunk::End(Stop::PortClosed(e.to_string())))
        }
        Err(e) => Err(e).context("reading the stream"),
    }
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
        use std::io;
        let mut csv = RowWriter::new(Vec::new(), 64);
        let source = Source {
            bytes: Box::new(io::Cursor::new(bytes)),
            live: false,
            size: 0,
        };
        let never = AtomicBool::new(false);
        let outcome = decode_stream(source, &mut csv, limits, &never, false).unwrap();
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
    fn raw_frames_are_rows_and_replies_are_counted() {
        use triad::protocol::Flags;
        use triad::protocol::{Payload, RawFrame, RawScale, Reply, Status, MAX_WIRE_LEN};
        let mut bytes = stream(1);
        let wire = |packet: triad::protocol::PacketBuf| {
            let mut out = [0u8; MAX_WIRE_LEN];
            let n = packet.to_wire(&mut out);
            out[..n].to_vec()
        };
        let reply = Reply {
            sequence: 9,
            command: 1,
            status: Status::Ok,
            payload: Payload::EMPTY,
        };
        bytes.extend(wire(reply.to_packet().unwrap()));
        let raw = RawFrame {
            sequence: 1,
            timestamp_us: 1_010_000,
            flags: Flags::RAW | Flags::UNCALIBRATED,
            accel: [100.0, -3.0, 2048.0],
            gyro: [7.0, 0.0, -1.0],
            temperature: -66.24,
            scale: RawScale {
                accel_si_per_lsb: 0.5,
                gyro_si_per_lsb: 0.25,
                temperature_per_lsb: 0.5,
                temperature_offset: 25.0,
            },
            ..RawFrame::default()
        };
        bytes.extend(wire(raw.to_packet().unwrap()));
        let (outcome, csv) = decode(bytes, None, None);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3, "{csv}");
        let temp = -66.24f32 * 0.5 + 25.0;
        assert_eq!(
            lines[2],
            format!("1,1.010000,50.0,-1.5,1024.0,1.75,0.0,-0.25,{temp:?},96")
        );
        let s = outcome.stats;
        assert_eq!((s.frames, s.raw_frames, s.messages), (1, 1, 1));
        assert_eq!((outcome.rows, s.sequence_gaps), (2, 0));
        let text = crate::decode::rows::summary(&outcome, "triad decode");
        assert!(
            text.contains("\nframes: 2 (2 stored as CSV rows)\n"),
            "{text}"
        );
        assert!(
            text.contains("\nraw frames: 1 (of those frames)\n"),
            "{text}"
        );
        assert!(text.contains("\nmessages: 1 (replies"), "{text}");
    }

    #[test]
    fn the_summary_says_why_and_counts() {
        let mut bytes = stream(2);
        bytes.extend_from_slice(&[1, 2, 3]);
        let (outcome, _) = decode(bytes, None, None);
        let text = crate::decode::rows::summary(&outcome, "triad decode");
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
        let args = |argv: &[&str]| Cli::try_parse_from([&["decode"], argv].concat()).unwrap();
        let limits = |argv: &[&str]| {
            let a = args(argv).args;
            Limits::new(a.max_frames, a.seconds)
        };
        assert_eq!(
            limits(&["--seconds", "1.5"]).unwrap().max_elapsed_us,
            Some(1_500_000)
        );
        let err = limits(&["--seconds", "-1"]).err().unwrap().to_string();
        assert!(err.starts_with("--seconds -1: must be a positive"), "{err}");
        let err = run(args(&["--baud", "0"]).args).unwrap_err().to_string();
        assert_eq!(err, "--baud 0: the baud rate must be positive");
    }
}
