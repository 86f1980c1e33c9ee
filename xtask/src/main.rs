//! `cargo xtask`: the two commands of the README and the jobs behind them.
//!
//! - `cargo xtask run`: set up, build the firmware for a board, chip and bus,
//!   run it (QEMU by default) and print the decoded, calibrated samples as CSV.
//! - `cargo xtask test`: every host test, the first-run checks, every board's
//!   firmware build, and the end-to-end tests on QEMU.
//! - `cargo xtask serve`: the emulated board served like hardware, its link
//!   on a pseudo-terminal for `triad device --port`.
//! - `cargo xtask man DIR`: the `triad` man pages, from its argument definitions.
//! - `cargo xtask bench`: the benchmark firmware on emulated cores; writes
//!   docs/BENCHMARKS.md; `cargo xtask bench --allan`: Allan at the scale of
//!   real recordings beside allantools.

use clap::{Parser, Subcommand};

/// A line on stderr; a failure to write it (stderr closed, full, or a pipe
/// whose reader left) is ignored: `eprintln!` would panic, and stderr is
/// the last place to report anything. xtask's progress and the firmware's
/// log go there; they are never its result.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        // The whole line in one write: QEMU shares this stderr, and a line
        // written a piece at a time (stderr is unbuffered) can be cut by
        // QEMU's own (its "waiting for connection" when the link was a socket), which a script
        // reading "link is PORT" then takes for the port.
        let mut line = format!($($arg)*);
        line.push('\n');
        let _ = std::io::stderr().write_all(line.as_bytes());
    }};
}

mod bench;
mod board;
mod cmd;
mod defmt_log;
mod elf_facts;
mod embedded_checks;
mod first_run;
mod hil;
mod pty;
mod qemu;
mod qemu_link;
mod serve;
mod setup;
mod size;
mod test;

#[derive(Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build and run the firmware; print decoded, calibrated samples as CSV on stdout.
    Run(RunArgs),
    /// Run every host test, build every board × chip × bus, run the end-to-end tests on QEMU.
    Test {
        /// Only the firmware builds and the end-to-end tests on QEMU.
        #[arg(long, conflicts_with = "first_run_only")]
        e2e_only: bool,
        /// Only the first-run checks: `cargo xtask run`'s stdout is CSV alone, and
        /// `triad` installed by `cargo install --path host` runs a shipped scene
        /// outside the checkout.
        #[arg(long)]
        first_run_only: bool,
        /// Only the end-to-end tests on QEMU of each chip with its
        /// accelerometer and gyroscope at different rates.
        #[arg(long, conflicts_with_all = ["e2e_only", "first_run_only"])]
        rates_only: bool,
        /// Only the end-to-end test on QEMU of the ICM-42688-P's
        /// high-resolution FIFO.
        #[arg(long, conflicts_with_all = ["e2e_only", "first_run_only", "rates_only"])]
        high_resolution_only: bool,
    },
    /// Benchmark every variant on the emulated cores; write docs/BENCHMARKS.md.
    Bench {
        /// Print the rows as a JSON array instead of a table.
        #[arg(long)]
        json: bool,
        /// Only the whole firmware (every rate and watermark, and the long
        /// run): print its section, leave docs/BENCHMARKS.md as it is.
        #[arg(long, conflicts_with = "json")]
        whole_firmware: bool,
        /// With --whole-firmware: only this sample rate and `--watermark`'s
        /// build (its row alone, no long run).
        #[arg(long, requires_all = ["whole_firmware", "watermark"])]
        rate: Option<u32>,
        /// With --whole-firmware and --rate: the FIFO watermark W.
        #[arg(long, requires = "rate")]
        watermark: Option<u16>,
        /// With --whole-firmware, --rate and --watermark: the ICM-42688-P's
        /// high-resolution FIFO; prints the noise floors of both FIFO formats too.
        #[arg(long, requires = "watermark")]
        high_resolution: bool,
        /// Only the long mutation run of the parsers that take outside
        /// bytes (10⁷ inputs each; fuzz/examples/bench_fuzz.rs), then the
        /// coverage-guided targets of fuzz/ under AFL++ (`--afl-seconds` each).
        #[arg(long, conflicts_with_all = ["json", "whole_firmware"])]
        fuzz: bool,
        /// Seconds AFL++ fuzzes each target (with --fuzz, or in the whole benchmark).
        #[arg(long, conflicts_with = "whole_firmware", default_value_t = bench::AFL_SECONDS)]
        afl_seconds: u64,
        /// Inputs per parser of the mutation run (with --fuzz, or in the whole benchmark).
        #[arg(long, conflicts_with = "whole_firmware", default_value_t = bench::MUTATIONS)]
        mutations: u64,
        /// Only Allan at scale: an 8-hour 400 Hz six-axis record through
        /// `triad allan` beside allantools (installed in a venv under target/).
        #[arg(long, conflicts_with_all = ["json", "whole_firmware", "fuzz"])]
        allan: bool,
        /// With --allan: the 24-hour, 2 kHz record too (streamed from a generator).
        #[arg(long, requires = "allan")]
        long: bool,
        /// Only the soak: the emulated board at 1 kHz for 24 h of device time
        /// (`--soak-seconds`), a command storm every 5 s, a sensor fault every
        /// hour (`--fault-every`); every counter checked (host/examples/bench_soak.rs).
        #[arg(long, conflicts_with_all = ["json", "whole_firmware", "fuzz", "allan"])]
        soak: bool,
        /// With --soak: seconds of device time.
        #[arg(long, requires = "soak", default_value_t = 86_400.0)]
        soak_seconds: f64,
        /// With --soak: seconds of device time between two sensor faults.
        #[arg(long, requires = "soak", default_value_t = 3_600.0)]
        fault_every: f64,
        /// With --soak: stop at this much wall time if the device time is
        /// not reached first (the figures are then of the time reached).
        #[arg(long, requires = "soak")]
        soak_wall_seconds: Option<f64>,
        /// With --soak: the FIFO watermark W (1..=32): samples per interrupt,
        /// streamed in batch frames of up to 16 (16, the default: 3.6 times
        /// fewer link bytes; 24 h took 1.1 h on a 2-core machine); 1 streams
        /// a data frame per sample (slower: more link bytes per sample).
        #[arg(long, requires = "soak", default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=32))]
        soak_watermark: u16,
    },
    /// Serve the emulated board like hardware: QEMU in real time, its link on
    /// a pseudo-terminal whose path is the first line on stdout; runs until killed.
    Serve(ServeArgs),
    /// The hardware-in-the-loop procedure: build, load, identify, stream at
    /// each sampling setting, the calibration's life (upload, save, reset,
    /// bad upload, erase) and the self-test; writes a report.
    Hil(hil::HilArgs),
    /// Flash and RAM of each firmware build, per board and per bus: prints
    /// the table and writes docs/FIRMWARE_SIZE.md.
    Size,
    /// Install what the project needs (rustup targets, QEMU) and exit.
    Setup,
    /// Write the man pages of `triad` (triad.1, triad-sim.1, ...) into DIR.
    Man {
        /// The directory to write them into (made if missing).
        dir: std::path::PathBuf,
    },
    /// Decode a captured defmt log (e.g. QEMU's stdout) with the firmware ELF.
    Log {
        /// The firmware ELF whose defmt table decodes the log.
        elf: std::path::PathBuf,
        /// The captured binary log.
        log: std::path::PathBuf,
    },
}

/// What firmware to build for the emulated board or a hardware one.
#[derive(clap::Args)]
pub struct FirmwareArgs {
    /// The board: `qemu` (emulated, the default) or `nucleo-f401re` (hardware via probe-rs).
    #[arg(long, default_value = "qemu", value_parser = board::Board::parse)]
    board: board::Board,
    /// The emulated board's chip model (the firmware finds it on the bus, as
    /// it finds the chip fitted to a hardware board).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(triad::sensor::CHIP_NAMES))]
    sensor: Option<String>,
    /// The bus between the microcontroller and the chip (cargo feature `bus-*`).
    #[arg(long, default_value = "spi")]
    bus: board::Bus,
    /// Calibration file (TOML) to embed; default calibrations/default.toml.
    #[arg(long)]
    calib: Option<std::path::PathBuf>,
    /// Feed the emulated board's chip model with this scene (a scenes/ name
    /// or a TOML file) simulated at the chip's rate, instead of the demo motion.
    #[arg(long, value_name = "NAME|FILE")]
    scene: Option<String>,
    /// Feed the chip model with this simulated unit (a scenes/units name or
    /// a unit file: one sensor and its turn-on errors) doing --script.
    #[arg(
        long,
        value_name = "NAME|FILE",
        requires = "script",
        conflicts_with = "scene"
    )]
    unit: Option<String>,
    /// What the --unit does (a scenes/scripts name or a script file), e.g.
    /// hand-rotations for `triad calib session`.
    #[arg(long, value_name = "NAME|FILE", requires = "unit")]
    script: Option<String>,
    /// Seed of the scene's random streams (with --scene), or of the
    /// unit's record's noise (with --unit: `triad sim --record-seed`).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The chip's output data rate, Hz (one the chip has, e.g. 1000, 8000
    /// for the ICM-42688-P); default the driver's. With --accel-rate or
    /// --gyro-rate, the faster sensor's: the stream's rate.
    #[arg(long, value_name = "HZ")]
    rate: Option<u32>,
    /// The accelerometer at this lower output data rate, Hz (the gyroscope
    /// at --rate): samples still stream at --rate, the accelerometer's
    /// latest value held between its own (docs/PROTOCOL.md §22).
    #[arg(long, value_name = "HZ", conflicts_with = "gyro_rate")]
    accel_rate: Option<u32>,
    /// The gyroscope at this lower output data rate, Hz (the accelerometer at --rate).
    #[arg(long, value_name = "HZ")]
    gyro_rate: Option<u32>,
    /// Samples per interrupt from the chip's FIFO (1..=32), streamed in batch
    /// frames; default 1 (FIFO off, one data frame per sample).
    #[arg(long, value_name = "W", value_parser = clap::value_parser!(u16).range(1..=32))]
    watermark: Option<u16>,
    /// The chip's high-resolution FIFO format (the ICM-42688-P's 20-bit
    /// packets: ±16 g and ±2000 °/s at 4 and 8 times the 16-bit resolution,
    /// DS-000347 §6.1); needs --watermark 2 or more.
    #[arg(long)]
    high_resolution: bool,
}

/// Arguments of `cargo xtask run`.
#[derive(clap::Args)]
pub struct RunArgs {
    #[command(flatten)]
    firmware: FirmwareArgs,
    /// Stop after this many seconds of streamed (emulated) time.
    #[arg(long, default_value_t = 2.0)]
    seconds: f64,
    /// Serial port of the hardware board's stream (nucleo-f401re only).
    #[arg(long, default_value = "/dev/ttyACM0")]
    port: String,
}

/// Arguments of `cargo xtask serve`.
#[derive(clap::Args)]
pub struct ServeArgs {
    #[command(flatten)]
    firmware: FirmwareArgs,
    /// The emulated board's calibration flash: this file (created, erased,
    /// when missing), so a saved calibration persists across runs. Without
    /// it the board has no storage.
    #[arg(long, value_name = "FILE")]
    storage: Option<std::path::PathBuf>,
    /// Serve this already built firmware ELF instead of building one (the
    /// end-to-end tests; the firmware options are then ignored).
    #[arg(long, hide = true)]
    elf: Option<std::path::PathBuf>,
    /// Power-cut test: end the run at this write or erase operation of the flash.
    #[arg(long, hide = true, requires = "storage")]
    storage_cut_after: Option<u32>,
    /// Run QEMU with `-icount` (one instruction per virtual nanosecond, idle
    /// time skipped) instead of in real time: no overrun from the host's
    /// load, and the chip model's samples replayable on the host (the
    /// end-to-end tests of the link). `triad calib session` needs it on a
    /// busy machine: a board that misses sample steps during a turn makes
    /// the fit refuse ("too fast for the sample rate").
    #[arg(long)]
    deterministic: bool,
    /// A fault the emulated board shows, in seconds of its time:
    /// `KIND@START[+DURATION]` (no duration: to the end), KIND one of
    /// vanish, drdy-high, drdy-silent, stop, brownout; or `nack@START*COUNT`
    /// (COUNT bus transactions fail). Repeat for more (at most 8).
    #[arg(long = "fault", value_name = "SPEC", value_parser = serve::fault_entry)]
    faults: Vec<String>,
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(args),
        Command::Serve(args) => serve_command(args),
        Command::Test {
            e2e_only,
            first_run_only,
            rates_only,
            high_resolution_only,
        } => test::run(match (e2e_only, first_run_only, rates_only) {
            (true, _, _) => test::Scope::EndToEnd,
            (_, true, _) => test::Scope::FirstRun,
            (_, _, true) => test::Scope::DifferentRates,
            _ if high_resolution_only => test::Scope::HighResolution,
            _ => test::Scope::All,
        }),
        Command::Bench {
            allan: true, long, ..
        } => bench::allan::run(long),
        Command::Bench {
            soak: true,
            soak_seconds,
            fault_every,
            soak_wall_seconds,
            soak_watermark,
            ..
        } => bench::soak::run(soak_seconds, fault_every, soak_wall_seconds, soak_watermark),
        Command::Bench {
            json,
            whole_firmware,
            fuzz,
            afl_seconds,
            mutations,
            rate,
            watermark,
            high_resolution,
            ..
        } => match fuzz {
            true => bench::run_fuzz(mutations, afl_seconds),
            false => {
                setup::ensure_all().and_then(|()| match (whole_firmware, rate.zip(watermark)) {
                    (true, Some((rate, watermark))) => {
                        bench::run_whole_firmware_one(rate, watermark, high_resolution)
                    }
                    (true, None) => bench::run_whole_firmware(),
                    (false, _) => bench::run(json, mutations, afl_seconds),
                })
            }
        },
        Command::Hil(args) => hil::run(args),
        Command::Size => size::run(),
        Command::Setup => setup::ensure_all(),
        Command::Man { dir } => man(&dir),
        Command::Log { elf, log } => defmt_log::print_file(&elf, &log),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            note!("xtask: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// `triad`'s exit status when the reader of its stdout left: 128 + SIGPIPE.
const READER_GONE_STATUS: i32 = 141;

fn run(args: RunArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.seconds.is_finite() && args.seconds > 0.0,
        "--seconds {}: must be a positive number of seconds",
        args.seconds
    );
    let (elf, triad) = build(&args.firmware)?;
    match args.firmware.board.probe_rs_chip() {
        None => {
            let stop = qemu::Stop::Seconds(args.seconds);
            let status = qemu::stream_to_decoder(&elf, &triad, stop, qemu::Inherit)?;
            // The reader of stdout left (`| head`): triad decode stopped
            // quietly with 128 + SIGPIPE, and so does xtask (QEMU is stopped).
            if status.code() == Some(READER_GONE_STATUS) {
                std::process::exit(READER_GONE_STATUS);
            }
            anyhow::ensure!(status.success(), "triad decode exited with {status}");
            Ok(())
        }
        Some(chip) => cmd::run_on_hardware(&elf, &triad, chip, &args.port, args.seconds),
    }
}

fn serve_command(args: ServeArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.firmware.board.is_emulated(),
        "--board {}: serve runs the emulated board; a hardware board is served by itself \
         (talk to its port with triad device --port)",
        args.firmware.board.name()
    );
    let storage = match &args.storage {
        Some(path) => Some(serve::Storage {
            path: serve::prepare_storage(path)?,
            cut_after: args.storage_cut_after,
        }),
        None => None,
    };
    let elf = match args.elf {
        Some(elf) => {
            setup::ensure_for(board::Board::emulated())?;
            elf
        }
        None => build(&args.firmware)?.0,
    };
    let clock = if args.deterministic {
        qemu::Clock::Deterministic
    } else {
        qemu::Clock::RealTime
    };
    serve::serve(&elf, storage.as_ref(), &args.faults, clock)
}

/// Sets up and builds the firmware `args` describe; returns the ELF and the
/// host tool built with it.
fn build(args: &FirmwareArgs) -> anyhow::Result<(std::path::PathBuf, std::path::PathBuf)> {
    if args.high_resolution && args.watermark.unwrap_or(1) < 2 {
        anyhow::bail!(
            "--high-resolution: the high-resolution format is the FIFO's; \
             give --watermark 2..=32 (it is {})",
            args.watermark.unwrap_or(1)
        );
    }
    setup::ensure_for(args.board)?;
    let triad = cmd::build_quick_host_tool()?;
    let calibration = cmd::pack_calibration(&triad, args.calib.as_deref())?;
    let emulated_chip = match (args.board.is_emulated(), args.sensor.as_deref()) {
        (true, chip) => {
            let chip = chip.unwrap_or(triad::sensor::CHIP_NAMES[0]);
            triad::sensor::CHIP_NAMES
                .iter()
                .copied()
                .find(|c| *c == chip)
        }
        (_, None) => None,
        (false, Some(chip)) => anyhow::bail!(
            "--sensor {chip}: the {} firmware finds whichever chip is fitted; \
             --sensor names the emulated board's chip model",
            args.board.name()
        ),
    };
    let firmware = board::Firmware {
        board: args.board,
        bus: args.bus,
        emulated_chip,
        sampling: board::Sampling {
            rate_hz: args.rate,
            slower: match (args.accel_rate, args.gyro_rate) {
                (Some(hz), _) => Some((triad::model::Triad::Accel, hz)),
                (None, Some(hz)) => Some((triad::model::Triad::Gyro, hz)),
                (None, None) => None,
            },
            watermark: args.watermark,
            high_resolution: args.high_resolution,
        },
    };
    let blob = match (&args.scene, &args.unit, &args.script) {
        (Some(name), _, _) => Some(cmd::pack_scene(&triad, name, args.seed)?),
        (None, Some(unit), Some(script)) => Some(cmd::pack_unit(&triad, unit, script, args.seed)?),
        _ => None,
    };
    let elf = match &blob {
        Some(blob) => cmd::build_firmware_with_scene(firmware, &calibration, blob)?,
        None => cmd::build_firmware(firmware, &calibration)?,
    };
    Ok((elf, triad))
}

fn man(dir: &std::path::Path) -> anyhow::Result<()> {
    let triad = cmd::build_quick_host_tool()?;
    let mut command = std::process::Command::new(triad);
    command.args(["man", "--out-dir"]).arg(dir);
    cmd::check(command, "triad man")
}
