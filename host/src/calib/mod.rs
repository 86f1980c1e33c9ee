//! `triad calib`: check and pack calibration files ([`check`], `pack`), and
//! fit them to recorded data ([`fit`]: [`fit_accel`], [`fit_gyro`], [`fit_imu`], [`fit_thermal`], from the
//! records of [`fit_csv`] cut into [`segments`], reported by [`report`]),
//! verify them on fresh records ([`verify`]), and run a guided rig-free
//! calibration on a device ([`session`]).

pub mod check;
pub mod file;
pub mod fit;
pub mod fit_accel;
pub mod fit_csv;
pub mod fit_gyro;
pub mod fit_imu;
pub mod fit_thermal;
pub mod g_sensitivity_report;
pub mod report;
pub mod segments;
pub mod session;
pub mod verify;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;
use triad::model::{blob, Corrector};
use triad::sensor::{CodeRange, ImuScale, TriadScale};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

use crate::calib::file::{self as calib_file, CalibFile};
use crate::plumbing::distinct::{self, named};
use crate::plumbing::number::positive;
use crate::plumbing::outfile;
use crate::plumbing::stdio::note;

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
        /// Where to write the blob (`-`: standard output).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        ranges: Ranges,
    },
    /// Fit a triad's (I+Σ) and b to recorded data and write a calibration file.
    Fit(fit::FitArgs),
    /// Apply a calibration to records its fit did not use; judge the residuals
    /// against the fit's own statistics (exit 1 when they fail).
    Verify(verify::VerifyArgs),
    /// A guided rig-free calibration on a device: turn the board by hand as
    /// told, then fit, upload, save and verify (`--port DEV`).
    Session(session::SessionArgs),
}

/// The sensor's configured ranges: they bound the bias check and, for a
/// 16-bit chip, give the LSB sensitivity that `check` folds in.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Ranges {
    /// Accelerometer full scale, ± g.
    #[arg(long, default_value_t = 16.0, allow_negative_numbers = true)]
    pub accel_range_g: f64,
    /// Gyroscope full scale, ± °/s.
    #[arg(long, default_value_t = 2000.0, allow_negative_numbers = true)]
    pub gyro_range_dps: f64,
}

impl Ranges {
    /// Both ranges positive and finite, or an error naming the option.
    pub fn check(&self) -> anyhow::Result<()> {
        for (option, value, unit) in [
            ("--accel-range-g", self.accel_range_g, "g"),
            ("--gyro-range-dps", self.gyro_range_dps, "°/s"),
        ] {
            let words = format!("the full scale must be a positive number of {unit}");
            positive(option, value, &words)?;
        }
        Ok(())
    }

    /// Full scales in SI units: (m/s², rad/s).
    pub fn full_scale_si(&self) -> (f64, f64) {
        (
            self.accel_range_g * STANDARD_GRAVITY,
            deg_to_rad(self.gyro_range_dps),
        )
    }

    /// The scale of a 16-bit chip at these ranges (full scale = 32768 LSB).
    pub fn scale_16_bit(&self) -> ImuScale {
        let (a, g) = self.full_scale_si();
        ImuScale {
            accel: TriadScale {
                si_per_lsb: a / 32768.0,
                full_scale: a,
                codes: CodeRange::I16,
            },
            gyro: TriadScale {
                si_per_lsb: g / 32768.0,
                full_scale: g,
                codes: CodeRange::I16,
            },
            temperature_per_lsb: 1.0 / 132.48,
            temperature_offset: 25.0,
        }
    }
}

/// Validates a file's calibration into a corrector on SI inputs (what `triad correct` uses).
pub fn si_corrector(file: &CalibFile, ranges: &Ranges) -> anyhow::Result<Corrector> {
    ranges.check()?;
    let (a, g) = ranges.full_scale_si();
    Corrector::new_si(&file.calibration, a, g, file.orientation)
        .map_err(|e| anyhow!("{}: {e}", file.path.display()))
}

/// Runs `triad calib`.
pub fn run(args: CalibArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        CalibCommand::Check { file, ranges } => {
            ranges.check()?;
            check::run(&calib_file::load(&file)?, &ranges)
        }
        CalibCommand::Fit(args) => fit::run(args),
        CalibCommand::Verify(args) => verify::run(args),
        CalibCommand::Session(args) => session::run(args),
        CalibCommand::Pack {
            file,
            output,
            ranges,
        } => {
            ranges.check()?;
            distinct::check(&[named("file", &file)], &[named("--output", &output)])?;
            pack(&calib_file::load(&file)?, &output, &ranges)
        }
    }
}

/// `triad calib pack`: the file validated, then its blob written to `output`.
fn pack(cal: &CalibFile, output: &Path, ranges: &Ranges) -> anyhow::Result<ExitCode> {
    si_corrector(cal, ranges)?;
    let bytes = blob::encode(&cal.calibration);
    outfile::write_whole(output, &bytes)?;
    note!(
        "{}: {} bytes, calibration id {:#010x}",
        output.display(),
        bytes.len(),
        cal.calibration.id
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_full_scales_and_a_16_bit_chip_divides_them() {
        let r = Ranges {
            accel_range_g: 2.0,
            gyro_range_dps: 180.0,
        };
        let (a, g) = r.full_scale_si();
        assert_eq!(a, 2.0 * STANDARD_GRAVITY);
        assert!((g - std::f64::consts::PI).abs() < 1e-15);
        let s = r.scale_16_bit();
        assert_eq!(s.accel.si_per_lsb * 32768.0, a);
        assert_eq!(s.gyro.full_scale, g);
    }

    #[test]
    fn a_range_that_is_not_positive_is_blamed_on_its_option() {
        let r = |a: f64, g: f64| Ranges {
            accel_range_g: a,
            gyro_range_dps: g,
        };
        assert!(r(16.0, 2000.0).check().is_ok());
        assert_eq!(
            r(-16.0, 2000.0).check().unwrap_err().to_string(),
            "--accel-range-g -16: the full scale must be a positive number of g"
        );
        assert_eq!(
            r(16.0, 1e300).check().map(|_| ()).ok(),
            Some(()),
            "large but finite is a range (the bias check bounds nothing then)"
        );
        assert!(r(16.0, f64::NAN)
            .check()
            .unwrap_err()
            .to_string()
            .starts_with("--gyro-range-dps NaN"));
    }
}
