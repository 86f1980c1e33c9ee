//! `triad`: the host side of triad. Each subcommand lives in its own module;
//! this file only parses the command line and reports errors in one line.

use clap::{Parser, Subcommand};

mod allan;
mod allan_plot;
mod calib;
mod calib_file;
mod correct;
mod decode;
mod progress;
mod scene_file;
mod sim;

#[derive(Parser)]
#[command(
    name = "triad",
    version,
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
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Decode(args) => decode::run(args),
        Command::Correct(args) => correct::run(args),
        Command::Calib(args) => calib::run(args),
        Command::Sim(args) => sim::run(args),
        Command::Allan(args) => allan::run(args),
    };
    match result {
        Ok(code) => code,
        Err(error) => {
            eprintln!("triad: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
