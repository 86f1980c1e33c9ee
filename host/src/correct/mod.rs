//! `triad correct`: the firmware's correction, on measured values in SI
//! units. The f32 path runs the same kernel as the firmware
//! (`Corrector::correct_si`); `--exact` runs the f64 reference. Streams in
//! constant memory.
//!
//! The input is triad's CSV ([`csv`]: `t`, `ax`…`gz` (s, m/s², rad/s) and an
//! optional `temp` (°C) found by name among other columns, which are copied
//! as written; `triad decode` writes `seq,t,ax,ay,az,gx,gy,gz,temp,flags`),
//! or a recording in any format [`crate::record`] reads ([`recording`]: its
//! samples as the reader gives them, no text in between; the output is
//! `t,ax,ay,az,gx,gy,gz[,temp]`). The six values are printed in the shortest
//! form that reads back to the same f32 (or f64). With a temperature and
//! temperature terms, the coefficients are refolded whenever the temperature
//! changes (clamped to the validated range). When the file records the
//! temperature range its terms were fitted over (`temperature_range_c` of
//! `[fit.accel]`/`[fit.gyro]`, written by `triad calib fit thermal`), the
//! samples outside it are counted and reported on stderr: there the terms
//! extrapolate.

mod csv;
mod recording;

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use crate::calib::file as calib_file;
use crate::calib::{si_corrector, Ranges};
use crate::plumbing::{input, stdio};
use crate::record;

/// Arguments of `triad correct`.
#[derive(clap::Args)]
pub struct CorrectArgs {
    /// The calibration file (TOML).
    #[arg(long)]
    calib: PathBuf,
    /// Input CSV with the columns `t,ax,ay,az,gx,gy,gz` and optionally
    /// `temp`, found by name among any others (`-` for stdin), or a
    /// recording (bag, MCAP, ULog, EuRoC, imu_tk: README, Recordings).
    input: PathBuf,
    /// Use the f64 reference instead of the firmware's f32 hot path.
    #[arg(long)]
    exact: bool,
    #[command(flatten)]
    ranges: Ranges,
}

/// Runs `triad correct`.
pub fn run(args: CorrectArgs) -> anyhow::Result<ExitCode> {
    let file = calib_file::load(&args.calib)?;
    let mut corrector = si_corrector(&file, &args.ranges)?;
    let has_terms =
        file.calibration.accel.temperature.is_some() || file.calibration.gyro.temperature.is_some();
    let fitted_range = file.fitted_temperature_range();
    let how = How {
        has_terms,
        g_sensitivity: file.calibration.g_sensitivity.is_some(),
        exact: args.exact,
        fitted_range,
    };
    let (name, outside) = if input::is_foreign_record(&args.input)? {
        let opened = record::open(&args.input, &record::options::global())?;
        let name = opened.source.name.clone();
        let mut out = BufWriter::with_capacity(1 << 16, stdio::raw_stdout()?);
        let outside = recording::correct_record(opened, &mut out, &mut corrector, how)?;
        out.flush().map_err(stdio::stdout_error)?;
        (name, outside)
    } else {
        let input = input::open_bytes(&args.input, 1 << 16)?;
        let mut out = BufWriter::with_capacity(1 << 16, stdio::raw_stdout()?);
        let outside =
            csv::correct_stream(input.reader, &mut out, &input.name, &mut corrector, how)?;
        out.flush().map_err(stdio::stdout_error)?;
        (input.name, outside)
    };
    if let (Some([lo, hi]), Outside { outside: 1.., rows }) = (fitted_range, outside) {
        stdio::note!(
            "{name}: {} of {rows} samples lie outside {lo:.1}..{hi:.1} °C, the range {} was fitted over: \
             there its temperature terms extrapolate (the cubic bias and the linear (I+Σ) as fitted; \
             the coefficients are clamped only to {}..{} °C)",
            outside.outside,
            args.calib.display(),
            triad::model::validate::TEMPERATURE_RANGE_C.0,
            triad::model::validate::TEMPERATURE_RANGE_C.1
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// How to correct: what the calibration file says and `--exact`.
#[derive(Clone, Copy, Debug)]
struct How {
    /// The calibration has temperature terms (refold on a temperature change).
    has_terms: bool,
    /// The calibration has a gyro g-sensitivity term (needs the accelerometer).
    g_sensitivity: bool,
    /// The f64 reference instead of the f32 kernel.
    exact: bool,
    /// The temperature range the terms were fitted over, where the file says.
    fitted_range: Option<[f64; 2]>,
}

/// How many rows were corrected, and how many of them had a temperature
/// outside the fitted range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Outside {
    rows: usize,
    outside: usize,
}

impl Outside {
    /// Counts a corrected row at `temperature` against `fitted_range`.
    fn add(&mut self, temperature: Option<f64>, fitted_range: Option<[f64; 2]>) {
        self.rows += 1;
        if let (Some(t), Some([lo, hi])) = (temperature, fitted_range) {
            self.outside += usize::from(!(lo..=hi).contains(&t));
        }
    }
}

/// The six values (ax … gz) of an accelerometer and a gyroscope triad.
fn six<T>(accel: [T; 3], gyro: [T; 3]) -> [T; 6] {
    let [ax, ay, az] = accel;
    let [gx, gy, gz] = gyro;
    [ax, ay, az, gx, gy, gz]
}
