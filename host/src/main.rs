//! `triad`: the host side of triad. The subcommands live in the `triad_host`
//! library; this file only parses the command line, dispatches, and reports
//! errors in one line.

use clap::CommandFactory;
use clap::{Parser, Subcommand};
use triad_host::{allan, calib, cli_docs, correct, decode, sim, version};

#[derive(Parser)]
#[command(
    name = "triad",
    version = version::text(),
    about = "Calibrated MEMS inertial sensors: host toolkit"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Decode the firmware's binary stream into CSV.
    Decode(decode::DecodeArgs),
    /// Apply a calibration to measured samples (the firmware's math).
    Correct(correct::CorrectArgs),
    /// Check, pack and fit calibration files.
    Calib(calib::CalibArgs),
    /// Simulate what a sensor measures in a scene.
    Sim(sim::SimArgs),
    /// Allan deviation, IEEE 952 noise terms and sensor grade of rate columns.
    Allan(allan::AllanArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(cli_docs::CompletionsArgs),
    /// Print the man page, or write every command's page into a directory.
    Man(cli_docs::ManArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Decode(args) => decode::run(args),
        Command::Correct(args) => correct::run(args),
        Command::Calib(args) => calib::run(args),
        Command::Sim(args) => sim::run(args),
        Command::Allan(args) => allan::run(args),
        Command::Completions(args) => cli_docs::completions(args, Cli::command()),
        Command::Man(args) => cli_docs::man(args, Cli::command()),
    };
    match result {
        Ok(code) => code,
        Err(error) => {
            eprintln!("triad: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
