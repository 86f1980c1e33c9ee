//! `triad calib`: check and pack calibration files, and fit them to
//! recorded data ([`fit`]).

mod fit;
mod fit_accel;
mod fit_csv;
mod fit_gyro;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, Context};
use triad::model::{blob, Corrector, FixedCorrector, Triad};
use triad::sensor::{ImuScale, TriadScale};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

use crate::calib_file::{self, CalibFile};

/// Arguments of `triad calib`.
#[derive(clap::Args)]
pub struct CalibArgs {
    #[command(subcommand)]
    command: CalibCommand,
}

/// The `triad calib` subcommands.
#[derive(clap::Subcommand)]
enum CalibCommand {
    /// Validate a calibration file; print condition numbers and folded coefficients.
    Check {
        /// The calibration file (TOML).
        file: PathBuf,
        #[command(flatten)]
        ranges: Ranges,
    },
    /// Validate a calibration file and write its binary blob (what the firmware embeds).
    Pack {
        /// The calibration file (TOML).
        file: PathBuf,
        /// Where to write the blob.
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        ranges: Ranges,
    },
    /// Fit a triad's (I+Σ) and b to recorded data and write a calibration file.
    Fit(fit::FitArgs),
}

/// The sensor's configured ranges: they bound the bias check and, for a
/// 16-bit chip, give the LSB sensitivity that `check` folds in.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Ranges {
    /// Accelerometer full scale, ± g.
    #[arg(long, default_value_t = 16.0)]
    pub accel_range_g: f64,
    /// Gyroscope full scale, ± °/s.
    #[arg(long, default_value_t = 2000.0)]
    pub gyro_range_dps: f64,
}

impl Ranges {
    /// Full scales in SI units: (m/s², rad/s).
    pub fn full_scale_si(&self) -> (f64, f64) {
        (
            self.accel_range_g * STANDARD_GRAVITY,
            deg_to_rad(self.gyro_range_dps),
        )
    }

    /// The scale of a 16-bit chip at these ranges (full scale = 32768 LSB).
    fn scale_16_bit(&self) -> ImuScale {
        let (a, g) = self.full_scale_si();
        ImuScale {
            accel: TriadScale {
                si_per_lsb: a / 32768.0,
                full_scale: a,
            },
            gyro: TriadScale {
                si_per_lsb: g / 32768.0,
                full_scale: g,
            },
            temperature_per_lsb: 1.0 / 132.48,
            temperature_offset: 25.0,
        }
    }
}

/// Validates a file's calibration into a corrector on SI inputs (what `triad correct` uses).
pub fn si_corrector(file: &CalibFile, ranges: &Ranges) -> anyhow::Result<Corrector> {
    let (a, g) = ranges.full_scale_si();
    Corrector::new_si(&file.calibration, a, g, file.orientation)
        .map_err(|e| anyhow!("{}: {e}", file.path.display()))
}

/// Runs `triad calib`.
pub fn run(args: CalibArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        CalibCommand::Check { file, ranges } => check(&calib_file::load(&file)?, &ranges),
        CalibCommand::Fit(args) => fit::run(args),
        CalibCommand::Pack {
            file,
            output,
            ranges,
        } => {
            let cal = calib_file::load(&file)?;
            si_corrector(&cal, &ranges)?;
            let bytes = blob::encode(&cal.calibration);
            std::fs::write(&output, bytes)
                .with_context(|| format!("{}: cannot write", output.display()))?;
            eprintln!(
                "{}: {} bytes, calibration id {:#010x}",
                output.display(),
                bytes.len(),
                cal.calibration.id
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn check(file: &CalibFile, ranges: &Ranges) -> anyhow::Result<ExitCode> {
    let si = si_corrector(file, ranges)?;
    let per_lsb = Corrector::new(&file.calibration, &ranges.scale_16_bit(), file.orientation)
        .map_err(|e| anyhow!("{}: {e}", file.path.display()))?;
    let fixed =
        FixedCorrector::new(&per_lsb).map_err(|e| anyhow!("{}: {e}", file.path.display()))?;
    let bound = fixed.error_bound();
    let cal = &file.calibration;
    println!("{}: OK", file.path.display());
    let source = if file.id_from_parameters {
        " (CRC-32 of the parameters)"
    } else {
        ""
    };
    println!("calibration id: {:#010x}{source}", cal.id);
    println!("orientation: {}", file.orientation);
    println!(
        "ranges: ±{} g, ±{} °/s (a 16-bit chip: full scale = 32768 LSB)",
        ranges.accel_range_g, ranges.gyro_range_dps
    );
    for (triad, unit, lsb, bound, q_format) in [
        (
            Triad::Accel,
            "m/s²",
            per_lsb.scale().accel.si_per_lsb,
            bound[0],
            "Q16.16",
        ),
        (
            Triad::Gyro,
            "rad/s",
            per_lsb.scale().gyro.si_per_lsb,
            bound[1],
            "Q12.20",
        ),
    ] {
        println!();
        println!(
            "[{}] condition number κ₁ = {:.6}",
            triad.name(),
            si.condition_number(triad)
        );
        if let Some(t) = &cal.triad(triad).temperature {
            println!(
                "  temperature terms around {} °C (folded here at that temperature)",
                t.reference_c
            );
        }
        let f = si.folded(triad);
        println!("  m = K·x + k with x in {unit} (triad correct):");
        print_matrix("K", &f.k);
        println!("    k = {}", vector(&f.offset));
        let f = per_lsb.folded(triad);
        println!("  m = K·raw + k with raw in LSB ({lsb:e} {unit}/LSB, the firmware's fold):");
        print_matrix("K", &f.k);
        println!("    k = {}", vector(&f.offset));
        println!(
            "  fixed point ({q_format}) error bound: {bound:.3e} {unit} = {:.4} LSB",
            bound / lsb
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn vector(v: &[f64; 3]) -> String {
    // `+ 0.0` turns −0 into +0 for the reader.
    format!(
        "[{:+.12e}, {:+.12e}, {:+.12e}]",
        v[0] + 0.0,
        v[1] + 0.0,
        v[2] + 0.0
    )
}

fn print_matrix(name: &str, m: &[[f64; 3]; 3]) {
    for (i, row) in m.iter().enumerate() {
        let label = if i == 0 {
            format!("{name} =")
        } else {
            " ".repeat(name.len() + 2)
        };
        println!("    {label} {}", vector(row));
    }
}
