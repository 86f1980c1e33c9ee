//! `cargo xtask`: the two commands of the README and the jobs behind them.
//!
//! - `cargo xtask run`: set up, build the firmware for a board, chip and bus,
//!   run it (QEMU by default) and print the decoded, calibrated samples as CSV.
//! - `cargo xtask test`: every host test, the first-run checks, every board's
//!   firmware build, and the end-to-end tests on QEMU.
//! - `cargo xtask man DIR`: the `triad` man pages, from its argument definitions.
//! - `cargo xtask bench`: the benchmark firmware on emulated cores; writes
//!   docs/BENCHMARKS.md.

use clap::{Parser, Subcommand};

mod bench;
mod board;
mod cmd;
mod defmt_log;
mod elf_facts;
mod embedded_checks;
mod first_run;
mod qemu;
mod setup;
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
    },
    /// Benchmark every variant on the emulated cores; write docs/BENCHMARKS.md.
    Bench {
        /// Print the rows as a JSON array instead of a table.
        #[arg(long)]
        json: bool,
    },
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

/// Arguments of `cargo xtask run`.
#[derive(clap::Args)]
pub struct RunArgs {
    /// The board: `qemu` (emulated, the default) or `nucleo-f401re` (hardware via probe-rs).
    #[arg(long, default_value = "qemu")]
    board: board::Board,
    /// The emulated board's chip model (the firmware finds it on the bus, as
    /// it finds the chip fitted to a hardware board).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(triad::sensor::CHIP_NAMES))]
    sensor: Option<String>,
    /// The bus between the microcontroller and the chip (cargo feature `bus-*`).
    #[arg(long, default_value = "spi")]
    bus: board::Bus,
    /// Stop after this many seconds of streamed (emulated) time.
    #[arg(long, default_value_t = 2.0)]
    seconds: f64,
    /// Calibration file (TOML) to embed; default calibrations/default.toml.
    #[arg(long)]
    calib: Option<std::path::PathBuf>,
    /// Feed the emulated board's chip model with this scene (a scenes/ name
    /// or a TOML file) simulated at the chip's rate, instead of the demo motion.
    #[arg(long, value_name = "NAME|FILE")]
    scene: Option<String>,
    /// Seed of the scene's random streams (with --scene).
    #[arg(long, default_value_t = 1, requires = "scene")]
    seed: u64,
    /// Serial port of the hardware board's stream (nucleo-f401re only).
    #[arg(long, default_value = "/dev/ttyACM0")]
    port: String,
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(args),
        Command::Test {
            e2e_only,
            first_run_only,
        } => test::run(match (e2e_only, first_run_only) {
            (true, _) => test::Scope::EndToEnd,
            (_, true) => test::Scope::FirstRun,
            _ => test::Scope::All,
        }),
        Command::Bench { json } => setup::ensure_all().and_then(|()| bench::run(json)),
        Command::Setup => setup::ensure_all(),
        Command::Man { dir } => man(&dir),
        Command::Log { elf, log } => defmt_log::print_file(&elf, &log),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("xtask: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(args: RunArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.seconds.is_finite() && args.seconds > 0.0,
        "--seconds {}: must be a positive number of seconds",
        args.seconds
    );
    setup::ensure_for(args.board)?;
    let triad = cmd::build_host_tool()?;
    let calibration = cmd::pack_calibration(&triad, args.calib.as_deref())?;
    let emulated_chip = match (args.board, args.sensor.as_deref()) {
        (board::Board::Qemu, chip) => {
            let chip = chip.unwrap_or(triad::sensor::CHIP_NAMES[0]);
            triad::sensor::CHIP_NAMES
                .iter()
                .copied()
                .find(|c| *c == chip)
        }
        (_, None) => None,
        (board, Some(chip)) => anyhow::bail!(
            "--sensor {chip}: the {} firmware finds whichever chip is fitted; \
             --sensor names the emulated board's chip model",
            board.name()
        ),
    };
    let firmware = board::Firmware {
        board: args.board,
        bus: args.bus,
        emulated_chip,
    };
    eprintln!("xtask: firmware for {}", firmware.label());
    let elf = match &args.scene {
        Some(name) => {
            let blob = cmd::pack_scene(&triad, name, args.seed)?;
            cmd::build_firmware_with_scene(firmware, &calibration, &blob)?
        }
        None => cmd::build_firmware(firmware, &calibration)?,
    };
    match args.board {
        board::Board::Qemu => {
            let stop = qemu::Stop::Seconds(args.seconds);
            let status = qemu::stream_to_decoder(&elf, &triad, stop, qemu::Inherit)?;
            anyhow::ensure!(status.success(), "triad decode exited with {status}");
            Ok(())
        }
        board::Board::NucleoF401re => cmd::run_on_hardware(&elf, &triad, &args.port, args.seconds),
    }
}

/// `triad man --out-dir DIR` of the freshly built host tool: the pages come
/// from the argument definitions `triad` itself parses.
fn man(dir: &std::path::Path) -> anyhow::Result<()> {
    let triad = cmd::build_host_tool()?;
    let mut command = std::process::Command::new(triad);
    command.args(["man", "--out-dir"]).arg(dir);
    cmd::check(command, "triad man")
}
