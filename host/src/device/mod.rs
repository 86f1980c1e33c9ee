//! `triad device`: drive a board running triad firmware over its serial
//! port (protocol version 2, docs/PROTOCOL.md): who it is, what it streams,
//! its calibration (upload, read back, save, erase), its counters, its
//! self-test, and its stream as CSV.
//!
//! Every subcommand first sends identify, which checks that a triad device
//! answers on the port (and says clearly when none does). Commands go
//! through [`link::Link`]: numbered, retried with the same number and
//! bytes when a reply is lost, frames streaming meanwhile skipped.

pub mod info;
pub mod link;
pub mod self_test;
pub mod transfer;

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{anyhow, bail};
use triad::model::{blob, Orientation};
use triad::protocol::bytes::Reader;
use triad::protocol::{Command, DeviceInfo, Mode};

use crate::calib::file as calib_file;
use crate::decode::out::StreamOut;
use crate::decode::rows::{CsvSink, Failure, Limits, Outcome, Stop};
use crate::plumbing::interrupt;
use crate::plumbing::outfile;
use crate::plumbing::row_writer::RowWriter;
use crate::plumbing::serial;
use crate::plumbing::stdio::{self, note};
use link::{Link, LinkError, Settings};

/// Arguments of `triad device`.
#[derive(clap::Args)]
#[command(after_help = "\
Each command is numbered; the reply naming its number is awaited for \
--timeout-ms, skipping the frames streamed meanwhile, and the command is sent \
again (same number, same bytes: the device does not apply it twice) up to \
--tries times in all.")]
pub struct DeviceArgs {
    /// The device's serial port (e.g. /dev/ttyACM0, COM3, or the pseudo-terminal
    /// `cargo xtask serve` prints).
    #[arg(long, value_name = "DEV", global = true)]
    pub port: Option<String>,
    /// Baud rate of --port (8N1); both boards run at 921600.
    #[arg(long, value_name = "N", default_value_t = 921_600, global = true)]
    pub baud: u32,
    /// How long each try waits for the reply, ms.
    #[arg(long, value_name = "MS", default_value_t = 500, global = true)]
    pub timeout_ms: u64,
    /// Tries per command, the first included.
    #[arg(long, value_name = "N", default_value_t = 3, global = true)]
    pub tries: u32,
    #[command(subcommand)]
    command: DeviceCommand,
}

/// The `triad device` subcommands.
#[derive(clap::Subcommand)]
enum DeviceCommand {
    /// Who the device is and what it does: firmware, board, chip, rate,
    /// mode, calibration, storage, uptime, counters, scale.
    Info,
    /// Stream raw frames (the chip's counts and its nominal scale), for calibration.
    Raw,
    /// Stream corrected samples (data frames).
    Calibrated,
    /// Average N samples per streamed frame.
    Decimation {
        /// Samples per frame, 1 to 65535.
        #[arg(value_parser = clap::value_parser!(u16).range(1..))]
        n: u16,
    },
    /// Upload a calibration file (TOML, as `triad calib` reads); the device
    /// checks it as `triad calib check` does and applies it, or keeps the old one.
    Upload {
        /// The calibration file, or a shipped calibration's name.
        file: PathBuf,
    },
    /// Read back the active calibration into a calibration file (TOML).
    Download {
        /// Where to write it (`-`: standard output).
        #[arg(short, long, value_name = "CAL.toml")]
        output: PathBuf,
    },
    /// Store the active calibration in the device's flash.
    Save,
    /// Erase the stored calibration (the active one runs until restart).
    Erase,
    /// Zero the device's counters.
    ResetCounters,
    /// Run the chip's self-test and print the result.
    Selftest,
    /// The device's frames as CSV, exactly as `triad decode` prints them.
    Stream {
        /// Stop after S seconds of stream time (by the frames' timestamps).
        #[arg(long, value_name = "S", allow_negative_numbers = true)]
        seconds: Option<f64>,
        /// Stop after N frames.
        #[arg(long, value_name = "N")]
        max_frames: Option<u64>,
        /// Report every rejected frame on stderr, not only the totals.
        #[arg(long)]
        verbose: bool,
        /// Write the rows to FILE, whole or not at all, instead of standard
        /// output: the CSV, or for a name ending .mcap an MCAP (as `triad decode --out`).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
}

/// The self-test pauses sampling while the chip runs its procedure, which
/// takes longer than a plain command: each try waits at least this long.
const SELF_TEST_TIMEOUT: Duration = Duration::from_secs(5);

/// How long one read of the port waits at most (a deadline or Ctrl-C is
/// checked between reads).
const PORT_POLL: Duration = Duration::from_millis(50);

/// Runs `triad device`.
pub fn run(args: DeviceArgs) -> anyhow::Result<ExitCode> {
    let port = args
        .port
        .as_deref()
        .ok_or_else(|| anyhow!("--port DEV is required: the device's serial port"))?;
    if args.baud == 0 {
        bail!("--baud 0: the baud rate must be positive");
    }
    if args.timeout_ms == 0 {
        bail!("--timeout-ms 0: a reply needs some time");
    }
    if args.tries == 0 {
        bail!("--tries 0: a command is sent at least once");
    }
    let limits = match &args.command {
        DeviceCommand::Stream {
            seconds,
            max_frames,
            ..
        } => Limits::new(*max_frames, *seconds)?,
        _ => Limits::default(),
    };
    let timeout = Duration::from_millis(args.timeout_ms);
    let opened = serial::open(port, args.baud, timeout.min(PORT_POLL))?;
    let settings = Settings {
        timeout,
        tries: args.tries,
    };
    let place = format!("at {} baud on {port}", args.baud);
    let mut link = Link::new(opened, settings, place, first_sequence());
    let info = identify(&mut link)?;
    match args.command {
        DeviceCommand::Info => stdio::print(info::render(&info, link.place()))?,
        DeviceCommand::Raw => set_mode(&mut link, Mode::Raw)?,
        DeviceCommand::Calibrated => set_mode(&mut link, Mode::Calibrated)?,
        DeviceCommand::Decimation { n } => {
            link.command(&Command::SetDecimation(n))?;
            let rate = f64::from(info.sample_rate_hz) / f64::from(n);
            stdio::print(format!(
                "decimation: {n} ({} frames/s)\n",
                crate::plumbing::number::readable(rate)
            ))?;
        }
        DeviceCommand::Upload { file } => upload(&mut link, &file)?,
        DeviceCommand::Download { output } => download(&mut link, &info, &output)?,
        DeviceCommand::Save => save(&mut link, &info)?,
        DeviceCommand::Erase => {
            link.command(&Command::Erase)?;
            stdio::print(format!(
                "erased the stored calibration (calibration {:#010x} stays active until restart)\n",
                info.calibration_id
            ))?;
        }
        DeviceCommand::ResetCounters => {
            link.command(&Command::ResetCounters)?;
            stdio::print("counters reset\n")?;
        }
        DeviceCommand::Selftest => {
            let reply = link.exchange(&Command::SelfTest, timeout.max(SELF_TEST_TIMEOUT))?;
            let (text, passed) = self_test::render(&reply);
            stdio::print(text)?;
            if !passed {
                return Ok(ExitCode::FAILURE);
            }
        }
        DeviceCommand::Stream { verbose, out, .. } => {
            stream(&mut link, limits, verbose, out.as_deref())?
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The first command's sequence number, from the clock: a new run does not
/// repeat the number of the last command the device answered (which it
/// would answer again from its last reply, without applying the command).
pub fn first_sequence() -> u16 {
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    let mixed = now.subsec_nanos() ^ (now.as_secs() as u32) ^ std::process::id();
    (mixed ^ (mixed >> 16)) as u16
}

/// Identify: who answers on the port.
pub fn identify<P: Read + Write>(link: &mut Link<P>) -> Result<DeviceInfo, LinkError> {
    let reply = link.command(&Command::Identify)?;
    info::parse(&reply)
}

fn set_mode<P: Read + Write>(link: &mut Link<P>, mode: Mode) -> anyhow::Result<()> {
    link.command(&Command::SetMode(mode))?;
    let what = match mode {
        Mode::Raw => "raw frames: the chip's counts and its nominal scale",
        Mode::Calibrated => "data frames: corrected samples",
    };
    stdio::print(format!("mode: {mode} (the device streams {what})\n"))
}

/// `upload FILE`: the file's blob, as `triad calib pack` makes it, checked
/// and applied by the device.
fn upload<P: Read + Write>(link: &mut Link<P>, file: &Path) -> anyhow::Result<()> {
    let cal = calib_file::load(file)?;
    if cal.orientation != Orientation::RotationNone {
        note!(
            "triad device: {}: orientation {} is not sent (a calibration blob carries none): \
             the device applies its board's mounting",
            cal.path.display(),
            cal.orientation
        );
    }
    let bytes = blob::encode(&cal.calibration);
    let id = transfer::upload(link, &bytes)?;
    stdio::print(format!(
        "{}: calibration {id:#010x} active (uploaded, not saved: `triad device save` keeps it across restarts)\n",
        cal.path.display()
    ))
}

/// `download -o FILE`: the active calibration as a file `triad calib` reads.
fn download<P: Read + Write>(
    link: &mut Link<P>,
    info: &DeviceInfo,
    output: &Path,
) -> anyhow::Result<()> {
    outfile::probe(output)?;
    let bytes = transfer::download(link)?.ok_or_else(|| {
        anyhow!(
            "the device runs no calibration (the identity, its frames flagged UNCALIBRATED): nothing to read back"
        )
    })?;
    let cal = blob::decode(&bytes).map_err(|e| anyhow!("the blob read back: {e}"))?;
    let header = format!(
        "Read back by `triad device download` {}:\n\
         board {}, chip {}, calibration {:#010x} ({}).\n\
         A calibration blob carries no mounting orientation: the device applies its board's.",
        link.place(),
        info.board,
        info.chip,
        cal.id,
        info.calibration_source
    );
    // The id is written when it is not the parameters' CRC (the default),
    // so the file reads back to the same identity.
    let mut extra = toml::Table::new();
    if cal.id != blob::parameter_id(&cal) {
        extra.insert("id".into(), toml::Value::Integer(i64::from(cal.id)));
    }
    let text = calib_file::render(&cal, Orientation::RotationNone, &header, extra)?;
    outfile::write_whole(output, text.as_bytes())?;
    note!(
        "{}: calibration {:#010x} read back ({} bytes of blob)",
        output.display(),
        cal.id,
        bytes.len()
    );
    Ok(())
}

/// `save`: where the record went.
fn save<P: Read + Write>(link: &mut Link<P>, info: &DeviceInfo) -> anyhow::Result<()> {
    let reply = link.command(&Command::Save)?;
    let mut r = Reader::new(reply.payload.as_slice());
    let (generation, slot) = (r.u32(), r.u8());
    let place = if r.ran_short() {
        String::new()
    } else {
        format!(" (generation {generation}, slot {slot})")
    };
    stdio::print(format!(
        "saved calibration {:#010x} to flash{place}\n",
        info.calibration_id
    ))
}

/// `stream`: the frames as CSV until a limit, Ctrl-C or the port closing;
/// the summary on stderr.
fn stream<P: Read + Write>(
    link: &mut Link<P>,
    limits: Limits,
    verbose: bool,
    out: Option<&Path>,
) -> anyhow::Result<()> {
    let interrupted = interrupt::flag();
    let mut csv = RowWriter::new(StreamOut::open(out)?, 1 << 16);
    let mut sink = CsvSink::new(&mut csv, limits, verbose, "triad device stream");
    let mut stop = sink.start();
    while stop.is_none() {
        if interrupt::requested(&interrupted) {
            stop = Some(Stop::Interrupted);
            break;
        }
        match link.next_packet(Instant::now() + PORT_POLL) {
            Ok(Some(decoded)) => stop = sink.packet(&decoded),
            Ok(None) => {}
            Err(LinkError::Closed { reason, .. }) => stop = Some(Stop::PortClosed(reason)),
            Err(e) => return Err(e.into()),
        }
        // A live link: rows go out as they come.
        if stop.is_none() && !link.buffered() {
            stop = sink.flush();
        }
    }
    if sink.failure.is_none() {
        if let Some(failed) = sink.flush() {
            stop = Some(failed);
        }
    }
    let mut failure = sink.failure.take();
    let rows = sink.rows();
    if failure.is_none() {
        if let Err(e) = csv.into_inner().finish() {
            failure = Some(Failure::Output(format!("{e:#}")));
        }
    }
    Outcome {
        stats: *link.stats(),
        rows,
        pending_bytes: link.pending_bytes(),
        stop: stop.unwrap_or(Stop::EndOfInput),
        failure,
    }
    .report("triad device stream")?;
    Ok(())
}
