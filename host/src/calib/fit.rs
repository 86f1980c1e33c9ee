//! `triad calib fit accel|gyro`: fit (I+Σ) and b to recorded data and write
//! the calibration file the firmware and `triad correct` read.
//!
//! ```text
//! triad calib fit accel --positions IN.csv [--positions IN2.csv ...] [--segments 0-10,12-22]
//!                       [--gravity 9.80665] [--min-static 2] [--base CAL.toml] --out CAL.toml
//! triad calib fit accel --axis-aligned --positions TUMBLE.csv ... --out CAL.toml   (cube faces: full I+Σ)
//! triad calib fit gyro --rate-table IN.csv [...] --rates "z:+30,z:-30,x:+30,y:+30"
//!                       [--segments ...] [--base CAL.toml] --out CAL.toml
//! triad calib fit gyro --static IN.csv [--latitude DEG] [--base CAL.toml] --out CAL.toml
//! ```
//!
//! The fitted triad replaces the one in `--base` (default: identity); the
//! other triad, the orientation and the base's `[fit.*]` statistics of the
//! other triad are kept. The fitted triad's temperature terms are dropped (a
//! fit at one temperature says nothing about them). The fit statistics go in
//! `[fit.accel]` / `[fit.gyro]`, which the loader ignores. The file has no
//! `id`: its identity is the CRC-32 of the parameters. The written file is
//! validated as `triad calib check` does before it is written.
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context};
use triad::model::{Calibration, Orientation, TriadCalibration};
use triad_lab::calib_fit::static_segments;

use super::fit_csv::{self, Record};
use super::{fit_accel, fit_gyro, Ranges};
use crate::calib_file::{self, vector};

/// Arguments of `triad calib fit`.
#[derive(clap::Args)]
pub struct FitArgs {
    #[command(subcommand)]
    command: FitCommand,
}

#[derive(clap::Subcommand)]
enum FitCommand {
    /// Accelerometer (I+Σ) and b from static records in unknown orientations.
    Accel(fit_accel::AccelArgs),
    /// Gyroscope (I+Σ) and b from rate-table runs, or its bias from a static record.
    Gyro(fit_gyro::GyroArgs),
}

/// Where the result goes and what it starts from.
#[derive(clap::Args)]
pub(super) struct Output {
    /// A calibration file to start from (its other triad and orientation are kept); default: identity.
    #[arg(long)]
    pub(super) base: Option<PathBuf>,
    /// The calibration file to write (TOML).
    #[arg(long)]
    pub(super) out: PathBuf,
    #[command(flatten)]
    pub(super) ranges: Ranges,
}

/// Runs `triad calib fit`.
pub fn run(args: FitArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        FitCommand::Accel(a) => fit_accel::run(a),
        FitCommand::Gyro(g) => fit_gyro::run(g),
    }
}

/// The files, for messages: all of them up to three, else first … last (N files).
pub(super) fn names(paths: &[PathBuf]) -> String {
    match paths {
        [first, .., last] if paths.len() > 3 => {
            format!(
                "{} … {} ({} files)",
                first.display(),
                last.display(),
                paths.len()
            )
        }
        _ => paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// One segment's samples, where they came from and their statistics.
pub(super) struct Stat {
    pub(super) file: usize,
    pub(super) from: f64,
    pub(super) to: f64,
    pub(super) mean: [f64; 3],
    /// Standard error of the mean per axis (white noise: s/√n).
    pub(super) standard_error: [f64; 3],
    pub(super) count: usize,
}

pub(super) fn stat(record: &Record, file: usize, range: std::ops::Range<usize>) -> Stat {
    let s = &record.samples[range.clone()];
    let sd = static_segments::standard_deviation(s);
    Stat {
        file,
        from: record.t[range.start],
        to: record.t[range.end - 1],
        mean: static_segments::mean(s),
        standard_error: sd.map(|x| x / (s.len() as f64).sqrt()),
        count: s.len(),
    }
}

/// The segments FROM-TO of `--segments` in `record`.
pub(super) fn given_segments(record: &Record, text: &str) -> anyhow::Result<Vec<Stat>> {
    fit_csv::parse_segments(text)?
        .into_iter()
        .map(|(from, to)| {
            let start = record.t.partition_point(|&t| t < from);
            let n = record.between(from, to).len();
            if n < 2 {
                bail!(
                    "--segments {from}-{to}: {n} sample(s) of {} in that time range, need at least 2",
                    record.path.display()
                );
            }
            Ok(stat(record, 0, start..start + n))
        })
        .collect()
}

fn insert_sigmas(table: &mut toml::Table, m: Option<&[[f64; 3]; 3]>, b: Option<&[f64; 3]>) {
    if let (Some(m), Some(b)) = (m, b) {
        table.insert(
            "sigma_scale_misalignment".into(),
            toml::Value::Array(m.iter().map(vector).collect()),
        );
        table.insert("sigma_bias".into(), vector(b));
    }
}

/// What every (I+Σ), b fit prints and writes: the estimates with their
/// standard deviations, the segment count, the residuals and the condition
/// number. Each fit adds its own method, convention and inputs.
pub(super) struct FitReport<'a> {
    pub scale_misalignment: &'a [[f64; 3]; 3],
    pub sigma_scale_misalignment: Option<&'a [[f64; 3]; 3]>,
    pub bias: &'a [f64; 3],
    pub sigma_bias: Option<&'a [f64; 3]>,
    pub segments: usize,
    pub residual_rms: f64,
    pub residual_max: f64,
    pub condition: f64,
}

impl FitReport<'_> {
    /// Prints (I+Σ) under `matrix_title` and b in `bias_unit`; without
    /// standard deviations, says why (`no_dof`).
    pub fn print(&self, matrix_title: &str, bias_unit: &str, no_dof: &str) {
        print_matrix(
            matrix_title,
            self.scale_misalignment,
            self.sigma_scale_misalignment,
        );
        print_vector(&format!("b ({bias_unit})"), self.bias, self.sigma_bias);
        if self.sigma_bias.is_none() {
            println!("  (no standard deviations: {no_dof})");
        }
    }

    /// The fit table's common keys: segments, residuals, condition number, σ's.
    pub fn insert_statistics(&self, table: &mut toml::Table) {
        table.insert(
            "segments".into(),
            toml::Value::Integer(self.segments as i64),
        );
        table.insert("residual_rms".into(), toml::Value::Float(self.residual_rms));
        table.insert("residual_max".into(), toml::Value::Float(self.residual_max));
        table.insert(
            "condition_number".into(),
            toml::Value::Float(self.condition),
        );
        insert_sigmas(table, self.sigma_scale_misalignment, self.sigma_bias);
    }

    /// The fitted triad (no temperature terms: a fit at one temperature says
    /// nothing about them).
    pub fn triad(&self) -> TriadCalibration {
        TriadCalibration {
            scale_misalignment: *self.scale_misalignment,
            bias: *self.bias,
            temperature: None,
        }
    }
}

/// The input files as a TOML array of strings.
pub(super) fn file_list(paths: &[PathBuf]) -> toml::Value {
    toml::Value::Array(
        paths
            .iter()
            .map(|p| toml::Value::String(p.display().to_string()))
            .collect(),
    )
}

fn print_matrix(name: &str, m: &[[f64; 3]; 3], sigma: Option<&[[f64; 3]; 3]>) {
    println!("  {name}:");
    for (i, row) in m.iter().enumerate() {
        let cells: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(j, x)| match sigma {
                Some(s) => format!("{x:+.7} ± {:.1e}", s[i][j]),
                None => format!("{x:+.7}"),
            })
            .collect();
        println!("    [{}]", cells.join(", "));
    }
}

pub(super) fn print_vector(name: &str, v: &[f64; 3], sigma: Option<&[f64; 3]>) {
    let cells: Vec<String> = v
        .iter()
        .enumerate()
        .map(|(i, x)| match sigma {
            Some(s) => format!("{x:+.6e} ± {:.1e}", s[i]),
            None => format!("{x:+.6e}"),
        })
        .collect();
    println!("  {name}: [{}]", cells.join(", "));
}

/// Which triad a fit replaces.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Which {
    /// The accelerometer.
    Accel,
    /// The gyroscope.
    Gyro,
}

impl Which {
    fn name(self) -> &'static str {
        match self {
            Which::Accel => "accel",
            Which::Gyro => "gyro",
        }
    }
}

/// Puts `triad` into the base (or identity) calibration, validates it like
/// `triad calib check`, and writes it with the fit's statistics.
pub(super) fn write_calibration(
    output: &Output,
    which: Which,
    triad: TriadCalibration,
    header: &str,
    fit_table: toml::Table,
) -> anyhow::Result<ExitCode> {
    let (mut calibration, orientation, mut fit_meta, base_note) = match &output.base {
        Some(path) => {
            let file = calib_file::load(path)?;
            let meta = calib_file::fit_metadata(path)?.unwrap_or_default();
            (
                file.calibration,
                file.orientation,
                meta,
                format!(
                    "The other triad and the orientation are those of {}.",
                    path.display()
                ),
            )
        }
        None => (
            Calibration::identity(0),
            Orientation::RotationNone,
            toml::Table::new(),
            "The other triad is the identity (no --base given).".to_string(),
        ),
    };
    match which {
        Which::Accel => calibration.accel = triad,
        Which::Gyro => calibration.gyro = triad,
    }
    let (a, g) = output.ranges.full_scale_si();
    triad::model::Corrector::new_si(&calibration, a, g, orientation).map_err(|e| {
        anyhow!(
            "the fitted calibration is rejected, {} not written: {e}",
            output.out.display()
        )
    })?;
    fit_meta.insert(which.name().into(), toml::Value::Table(fit_table));
    let mut extra = toml::Table::new();
    extra.insert("fit".into(), toml::Value::Table(fit_meta));
    let text = calib_file::render(
        &calibration,
        orientation,
        &format!("{header}\n{base_note}"),
        extra,
    )?;
    std::fs::write(&output.out, text)
        .with_context(|| format!("{}: cannot write", output.out.display()))?;
    println!("wrote {}", output.out.display());
    Ok(ExitCode::SUCCESS)
}
