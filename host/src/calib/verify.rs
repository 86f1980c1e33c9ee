//! `triad calib verify CAL.toml REC.csv`: a calibration applied to a record
//! its fit did not use, and whether the residuals are what the fit's own
//! statistics predict.
//!
//! Accelerometer: each static pose of the record, corrected, should have the
//! magnitude of gravity; the residual is |(I+Σ)⁻¹(f̂ − b)| − g. Gyroscope
//! (`--rates`, one file per rate-table run, or `--segments`): each run's
//! corrected mean should be the table's rate; the residuals are its three
//! components.
//!
//! The verdict is an F test of the residuals' mean square against the
//! fit's own, from the file (`[fit.TRIAD]`): s² = residual_rms²·N/ν, N the
//! fit's residuals and ν its degrees of freedom, widened by 1 + p/N for
//! the calibration's own estimation error (p = N − ν parameters: a residual
//! on fresh data has that much more variance than one the fit saw, on
//! average). F = (Σr²/n) / (s²·(1 + p/N)) is compared with the 99 % point
//! of F(n, ν). Both mean squares hold what varies between poses within a
//! session (white noise, bias wander), so a record like the fit's, of the
//! same unit, passes 99 % of the time; one whose (I+Σ) or b differ by more
//! than the fit's residuals fail. The standard error of each pose's mean is
//! shown beside its residual.
//!
//! A calibration with temperature terms is applied at each pose's (or
//! run's) mean temperature from the records' `temp` column, as the firmware
//! and `triad correct` apply it; such a record needs that column.
//!
//! What the verdict assumes: that the bias holds from the fit's session to
//! this one. The fit's σ's leave out what is common to its segments (its
//! report says so), so a unit whose bias moves between sessions by more
//! than the fit's residuals (bias instability, turn-on to turn-on) fails
//! here even when its (I+Σ) is right; the residuals then share an offset.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad::model::{matrix, Triad};
use triad::units::STANDARD_GRAVITY;
use triad_lab::f_dist;

use super::fit::names;
use super::fit_csv;
use super::fit_gyro::parse_rates;
use super::segments::{self, stat, Stat};
use crate::calib::file::{self as calib_file, CalibFile};
use crate::plumbing::stdio::{self, outln};

/// The verdict's level: a good calibration fails 1 % of the time.
pub const LEVEL: f64 = 0.99;

/// Arguments of `triad calib verify`.
#[derive(clap::Args)]
pub struct VerifyArgs {
    /// The calibration file (TOML) to verify, as `calib fit` wrote it (its
    /// `[fit.accel]` or `[fit.gyro]` statistics give the verdict's scale).
    calibration: PathBuf,
    /// Records the fit did not use: static poses (accel), or one file per
    /// rate-table run (gyro, with --rates).
    #[arg(required = true)]
    records: Vec<PathBuf>,
    /// Which triad: accel (static poses against gravity) or gyro (runs
    /// against --rates).
    #[arg(long, default_value = "accel", value_parser = ["accel", "gyro"])]
    triad: String,
    /// The table's rate of each run, as `calib fit gyro --rates` takes them
    /// (e.g. "z:+30,z:-30", °/s about sensor axes), one per file.
    #[arg(long)]
    rates: Option<String>,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Shortest static pose detected, seconds.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_static: f64,
    #[command(flatten)]
    reading: fit_csv::Reading,
    /// The sensor's ranges (for records in counts).
    #[command(flatten)]
    ranges: super::Ranges,
}

/// One checked pose or run.
struct Residual {
    /// Where: file and time range.
    label: String,
    /// The residual components (one for a pose, three for a run).
    r: Vec<f64>,
    /// The standard errors of the means behind them.
    standard_error: Vec<f64>,
}

/// What the fit says about its residuals, from the calibration file.
pub struct FitScale {
    /// Residual mean square per degree of freedom, s².
    pub mean_square: f64,
    /// Degrees of freedom ν.
    pub dof: f64,
    /// Residuals the fit had, N.
    pub residuals: f64,
}

/// The F test of `n` fresh residuals whose squares sum to `sum_sq`.
pub struct Verdict {
    /// The fit's parameters, p = N − ν.
    pub parameters: f64,
    /// The mean square a fresh residual is expected to have: s²·(1 + p/N).
    pub expected: f64,
    /// F = (Σr²/n) / expected.
    pub f: f64,
    /// The 99 % point of F(n, ν).
    pub limit: f64,
    /// F ≤ limit.
    pub pass: bool,
}

impl FitScale {
    /// The verdict on `n` fresh residuals with Σr² = `sum_sq`.
    pub fn verdict(&self, sum_sq: f64, n: usize) -> Verdict {
        let parameters = self.residuals - self.dof;
        let expected = self.mean_square * (1.0 + parameters / self.residuals);
        let f = sum_sq / n as f64 / expected;
        let limit = f_dist::quantile(LEVEL, n as f64, self.dof);
        Verdict {
            parameters,
            expected,
            f,
            limit,
            pass: f <= limit,
        }
    }
}

/// Runs `triad calib verify`.
pub fn run(args: VerifyArgs) -> anyhow::Result<ExitCode> {
    segments::check_pose_options(args.gravity, args.min_static)?;
    let file = calib_file::load(&args.calibration)?;
    let triad = if args.triad == "gyro" {
        Triad::Gyro
    } else {
        Triad::Accel
    };
    let fit = fit_scale(&file, triad)?;
    let temperature = AppliedAt::of(&args, &file, triad)?;
    let cal = file.calibration.triad(triad);
    let path = file.path.display().to_string();
    let correct = |m: &[f64; 3], s: &Stat| -> anyhow::Result<[f64; 3]> {
        let t = temperature.of_stat(s);
        let (k, b) = cal.at_temperature(t);
        let inverse = matrix::inverse(&k)
            .ok_or_else(|| anyhow!("{path}: {} (I+Σ) is singular at {t:.1} °C", triad.name()))?;
        Ok(matrix::mul_vec(
            &inverse,
            &[m[0] - b[0], m[1] - b[1], m[2] - b[2]],
        ))
    };
    let residuals = match triad {
        Triad::Accel => accel_residuals(&args, &correct)?,
        Triad::Gyro => gyro_residuals(&args, &correct)?,
    };
    let mut out = String::new();
    let (sum_sq, n) = report(&mut out, &file, triad, &fit, &residuals);
    if n == 0 {
        bail!("{}: no static pose or run to verify", names(&args.records));
    }
    let Verdict {
        parameters,
        expected,
        f,
        limit,
        pass,
    } = fit.verdict(sum_sq, n);
    outln!(
        out,
        "residual RMS {:.3e}, the fit's prediction {:.3e} (s·√(1 + p/N), p = {parameters}, N = {})",
        (sum_sq / n as f64).sqrt(),
        expected.sqrt(),
        fit.residuals
    );
    outln!(
        out,
        "verdict: {} (F = {:.2} against F({n}, {}) at {:.0} %: {:.2})",
        if pass { "PASS" } else { "FAIL" },
        f,
        fit.dof,
        100.0 * LEVEL,
        limit
    );
    stdio::print(&out)?;
    Ok(if pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The fit's residual scale, from the file's `[fit.TRIAD]` table: its
/// residuals per segment are 1 for the ellipsoid fit (a magnitude) and 3
/// for the linear fits (a vector), told apart by the degrees of freedom.
pub fn fit_scale(file: &CalibFile, triad: Triad) -> anyhow::Result<FitScale> {
    let table = file.fit.get(triad.name()).and_then(|v| v.as_table());
    let number = |key: &str| {
        table
            .and_then(|t| t.get(key))
            .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
    };
    let (Some(rms), Some(segments), Some(dof)) = (
        number("residual_rms"),
        number("segments"),
        number("degrees_of_freedom"),
    ) else {
        bail!(
            "{}: no [fit.{}] statistics (residual_rms, segments, degrees_of_freedom): \
             verify needs a file `triad calib fit` wrote",
            file.path.display(),
            triad.name()
        );
    };
    if dof <= 0.0 {
        bail!(
            "{}: its {} fit left no degree of freedom, so it predicts no spread to verify against",
            file.path.display(),
            triad.name()
        );
    }
    // The ellipsoid fit: 9 parameters, one residual (a magnitude) per
    // segment; the thermal fit likewise, with the parameter count it states
    // (`parameters`). The linear fits (rate table, cube faces): 4
    // parameters per axis, three residuals per segment, and the file's
    // degrees of freedom are one axis's.
    let parameters = segments - dof;
    let magnitude_fit = parameters == 9.0 || number("parameters") == Some(parameters);
    let (residuals, dof) = if magnitude_fit {
        (segments, dof)
    } else if parameters == 4.0 {
        (3.0 * segments, 3.0 * dof)
    } else {
        bail!(
            "{}: [fit.{}] has {segments} segments and {dof} degrees of freedom \
             ({parameters} parameters): not a fit `triad calib fit` writes",
            file.path.display(),
            triad.name()
        );
    };
    Ok(FitScale {
        mean_square: rms * rms * residuals / dof,
        dof,
        residuals,
    })
}

/// A pose's or run's mean measurement corrected, at its temperature.
type Correct<'a> = dyn Fn(&[f64; 3], &Stat) -> anyhow::Result<[f64; 3]> + 'a;

/// The temperature the calibration is applied at, per pose or run.
enum AppliedAt {
    /// No temperature terms: (I+Σ) and b as they are.
    Constant,
    /// Temperature terms: each pose's or run's mean of the records' `temp`
    /// column, as the firmware and `triad correct` apply them.
    Record(Vec<fit_csv::Record>),
}

impl AppliedAt {
    /// Follows the records' temperature when the calibration has
    /// temperature terms for `triad`; they then need a `temp` column.
    fn of(args: &VerifyArgs, file: &CalibFile, triad: Triad) -> anyhow::Result<AppliedAt> {
        if file.calibration.triad(triad).temperature.is_none() {
            return Ok(AppliedAt::Constant);
        }
        let mut temps = Vec::with_capacity(args.records.len());
        for path in &args.records {
            let text = fit_csv::read_content(path)?;
            let why = format!(
                "{} has {} temperature terms, which verify applies at each pose's temperature",
                file.path.display(),
                triad.name()
            );
            temps.push(fit_csv::parse_temperature(&text, path, &why)?);
        }
        Ok(AppliedAt::Record(temps))
    }

    /// The temperature for `s` (°C); the reference of no temperature term
    /// does not matter, (I+Σ) and b being constant.
    fn of_stat(&self, s: &Stat) -> f64 {
        match self {
            AppliedAt::Constant => 25.0,
            AppliedAt::Record(temps) => {
                let during = temps[s.file].between(s.from, s.to);
                during.iter().map(|t| t[0]).sum::<f64>() / during.len().max(1) as f64
            }
        }
    }
}

/// |`mean`| − `gravity` of a corrected static mean (m/s²), and the mean's
/// standard error along its direction (from the axes' `standard_error`).
pub fn gravity_residual(mean: &[f64; 3], standard_error: &[f64; 3], gravity: f64) -> (f64, f64) {
    let m = mean;
    let norm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    let u = m.map(|x| x / norm);
    let se = (0..3)
        .map(|i| (u[i] * standard_error[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    (norm - gravity, se)
}

fn accel_residuals(args: &VerifyArgs, correct: &Correct<'_>) -> anyhow::Result<Vec<Residual>> {
    let records = super::fit_accel::read_records(&args.reading, &args.records, &args.ranges)?;
    let stats = segments::detected(&records, args.min_static)?;
    stats
        .iter()
        .map(|s| {
            let m = correct(&s.mean, s)?;
            let (r, se) = gravity_residual(&m, &s.standard_error, args.gravity);
            Ok(Residual {
                label: label(args, s),
                r: vec![r],
                standard_error: vec![se],
            })
        })
        .collect()
}

fn gyro_residuals(args: &VerifyArgs, correct: &Correct<'_>) -> anyhow::Result<Vec<Residual>> {
    let Some(text) = &args.rates else {
        bail!(
            "--triad gyro needs --rates: the table's rate of each run, e.g. \"z:+30,z:-30\" (°/s)"
        );
    };
    let rates = parse_rates(text)?;
    if rates.len() != args.records.len() {
        bail!(
            "--rates gives {} rates for {} record files: one rate per run file",
            rates.len(),
            args.records.len()
        );
    }
    let records = fit_csv::read_all(&args.records, fit_csv::GYRO)?;
    records
        .iter()
        .enumerate()
        .zip(&rates)
        .map(|((i, r), w)| {
            let s = stat(r, i, 0..r.samples.len());
            let m = correct(&s.mean, &s)?;
            Ok(Residual {
                label: label(args, &s),
                r: (0..3).map(|k| m[k] - w[k]).collect(),
                standard_error: s.standard_error.to_vec(),
            })
        })
        .collect()
}

fn label(args: &VerifyArgs, s: &Stat) -> String {
    format!(
        "{} {:.1}–{:.1} s",
        crate::plumbing::input::name(&args.records[s.file]),
        s.from,
        s.to
    )
}

/// Prints each residual and returns (Σr², number of residuals).
fn report(
    out: &mut String,
    file: &CalibFile,
    triad: Triad,
    fit: &FitScale,
    residuals: &[Residual],
) -> (f64, usize) {
    let unit = match triad {
        Triad::Accel => "m/s²",
        Triad::Gyro => "rad/s",
    };
    outln!(
        out,
        "{}: {} calibration {:#010x} on {} {}; the fit's residual s {:.3e} {unit} ({} degrees of freedom)",
        file.path.display(),
        triad.name(),
        file.calibration.id,
        residuals.len(),
        match triad {
            Triad::Accel => "static poses (|corrected| − g)",
            Triad::Gyro => "rate-table runs (corrected − table rate, x y z)",
        },
        fit.mean_square.sqrt(),
        fit.dof
    );
    let mut sum_sq = 0.0;
    let mut n = 0;
    for res in residuals {
        sum_sq += res.r.iter().map(|r| r * r).sum::<f64>();
        n += res.r.len();
        let cells: Vec<String> = res
            .r
            .iter()
            .zip(&res.standard_error)
            .map(|(r, se)| format!("{r:+.3e} (mean's SE {se:.1e})"))
            .collect();
        outln!(out, "  {}: {}", res.label, cells.join(", "));
    }
    (sum_sq, n)
}
