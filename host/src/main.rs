//! `triad`: the host side of triad. The subcommands live in the `triad_host`
//! library; this file only parses the command line, dispatches, and reports
//! errors in one line.
//!
//! Exit status: 0 on success, 1 on an error (one line on stderr), 2 for a
//! command line clap refuses, 141 (quietly) when the reader of stdout
//! closed it, as `… | head -1` does: files the command writes are complete
//! before anything is printed, so they are not lost.

use std::process::ExitCode;

use clap::CommandFactory;
use clap::{Parser, Subcommand};
use triad_host::plumbing::stdio::{self, READER_GONE_STATUS};
use triad_host::plumbing::{progress, version};
use triad_host::{allan, calib, cli_docs, convert, correct, decode, device, record, sim, units};

#[derive(Parser)]
#[command(
    name = "triad",
    version = version::text(),
    about = "Calibrated MEMS inertial sensors: host toolkit"
)]
struct Cli {
    /// No progress lines on stderr.
    #[arg(long, short, global = true)]
    quiet: bool,
    /// How recordings (bags, ULogs) are read, for every command that reads one.
    #[command(flatten)]
    record: record::Options,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Decode the firmware's binary stream into CSV.
    Decode(decode::DecodeArgs),
    /// Drive a board running triad firmware over its serial port.
    Device(device::DeviceArgs),
    /// Apply a calibration to measured samples (the firmware's math).
    Correct(correct::CorrectArgs),
    /// Check, pack and fit calibration files.
    Calib(calib::CalibArgs),
    /// Simulate what a sensor measures in a scene.
    Sim(sim::SimArgs),
    /// Allan deviation, IEEE 952 noise terms and sensor grade of rate columns.
    Allan(allan::AllanArgs),
    /// Convert a recording (CSV, EuRoC, imu_tk, ROS 1/2 bag, MCAP, ULog) to triad's CSV or to MCAP.
    Convert(convert::ConvertArgs),
    /// Convert a specification value between data-sheet, Allan and Kalibr units.
    Units(units::UnitsArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(cli_docs::CompletionsArgs),
    /// Print the man page, or write every command's page into a directory.
    Man(cli_docs::ManArgs),
}

/// Runs before Rust's runtime, which puts /dev/null on a closed standard
/// descriptor: records whether stdout was closed (`>&-`) rather than given
/// /dev/null on purpose (see `stdio::check_stdout_open`).
#[cfg(any(target_os = "linux", target_os = "android", target_os = "freebsd"))]
#[used]
#[link_section = ".init_array"]
static RECORD_STDOUT_AT_START: extern "C" fn() = stdio::record_stdout_at_start;

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    if cli.quiet {
        progress::silence();
    }
    record::options::set(cli.record);
    stdio::check_stdout_open()?;
    match cli.command {
        Command::Decode(args) => decode::run(args),
        Command::Device(args) => device::run(args),
        Command::Correct(args) => correct::run(args),
        Command::Calib(args) => calib::run(args),
        Command::Sim(args) => sim::run(args),
        Command::Allan(args) => allan::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Units(args) => units::run(args),
        Command::Completions(args) => cli_docs::completions(args, Cli::command()),
        Command::Man(args) => cli_docs::man(args, Cli::command()),
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(error) if stdio::is_reader_gone(&error) => ExitCode::from(READER_GONE_STATUS),
        Err(error) => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "triad: {error:#}");
            ExitCode::FAILURE
        }
    }
}
