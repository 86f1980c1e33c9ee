//! `triad calib fit gyro`: (I+Σ) and b from rate-table runs with known
//! rates ([`gyro_fit`]), or the bias alone from a static record.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad::model::TriadCalibration;
use triad::units::{deg_to_rad, rad_to_deg, EARTH_RATE};
use triad_lab::calib_fit::gyro_fit::{self, RateSegment};
use triad_lab::calib_fit::static_segments;

use super::fit::{
    file_list, given_segments, names, print_vector, stat, write_calibration, FitReport, Output,
    Which,
};
use super::fit_csv;
use crate::calib_file::{self, vector};

/// Arguments of `triad calib fit gyro`.
#[derive(clap::Args)]
pub struct GyroArgs {
    /// CSV records (`t,...,gx,gy,gz,...`, rad/s) of rate-table runs: each
    /// file is one run at one rate (or give --segments for one file).
    #[arg(
        long,
        required_unless_present = "static_record",
        conflicts_with = "static_record"
    )]
    rate_table: Vec<PathBuf>,
    /// The true rate of each run (or segment), in order: AXIS:RATE in °/s,
    /// comma-separated, AXIS one of x y z (sensor axes, optionally signed),
    /// e.g. "z:+30,z:-30,x:+30,y:+30". Needs ≥ 4 rate vectors not in one plane.
    #[arg(long, requires = "rate_table")]
    rates: Option<String>,
    /// Segments FROM-TO seconds within a single --rate-table file, one per rate.
    #[arg(long, requires = "rate_table")]
    segments: Option<String>,
    /// A static record (`t,ax,ay,az,gx,gy,gz`): fit the gyro bias alone (mean of each axis).
    #[arg(long = "static")]
    static_record: Option<PathBuf>,
    /// Latitude in degrees: subtract the vertical Earth-rate component from a static bias.
    #[arg(long, requires = "static_record")]
    latitude: Option<f64>,
    #[command(flatten)]
    output: Output,
}

/// Runs `triad calib fit gyro`.
pub fn run(args: GyroArgs) -> anyhow::Result<ExitCode> {
    if args.static_record.is_some() {
        gyro_static(args)
    } else {
        gyro_rate_table(args)
    }
}

/// `x:+30` → (axis index, sign·rate in rad/s).
fn parse_rates(text: &str) -> anyhow::Result<Vec<[f64; 3]>> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|item| {
            let (axis, rate) = item.split_once(':').ok_or_else(|| {
                anyhow!("--rates: `{item}` is not AXIS:RATE (e.g. z:+30, in °/s about the sensor's z axis)")
            })?;
            let (sign, index) = match axis.trim() {
                "x" | "+x" => (1.0, 0),
                "-x" => (-1.0, 0),
                "y" | "+y" => (1.0, 1),
                "-y" => (-1.0, 1),
                "z" | "+z" => (1.0, 2),
                "-z" => (-1.0, 2),
                other => bail!("--rates: axis `{other}` in `{item}` is not one of x, y, z, -x, -y, -z"),
            };
            let dps: f64 = rate
                .trim()
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| anyhow!("--rates: `{}` in `{item}` is not a number of °/s", rate.trim()))?;
            let mut w = [0.0; 3];
            w[index] = sign * deg_to_rad(dps);
            Ok(w)
        })
        .collect()
}

fn gyro_rate_table(args: GyroArgs) -> anyhow::Result<ExitCode> {
    let Some(rates_text) = &args.rates else {
        bail!("--rate-table needs --rates: the true rate of each run, e.g. \"z:+30,z:-30,x:+30,y:+30\" (°/s)");
    };
    let rates = parse_rates(rates_text)?;
    let records = args
        .rate_table
        .iter()
        .map(|p| fit_csv::read(p, fit_csv::GYRO))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let stats = match &args.segments {
        Some(text) => {
            if records.len() != 1 {
                bail!(
                    "--segments applies to a single --rate-table file; {} were given",
                    records.len()
                );
            }
            given_segments(&records[0], text)?
        }
        None => records
            .iter()
            .enumerate()
            .map(|(i, r)| stat(r, i, 0..r.samples.len()))
            .collect(),
    };
    if stats.len() != rates.len() {
        bail!(
            "--rates gives {} rate(s) for {} segment(s) ({}): give one rate per run",
            rates.len(),
            stats.len(),
            if args.segments.is_some() {
                "--segments"
            } else {
                "--rate-table files"
            }
        );
    }
    let segments: Vec<RateSegment> = stats
        .iter()
        .zip(&rates)
        .map(|(s, w)| RateSegment {
            true_rate: *w,
            measured: s.mean,
        })
        .collect();
    let fit = gyro_fit::fit(&segments).map_err(|e| anyhow!("{}: {e}", names(&args.rate_table)))?;
    println!("gyro rate-table fit: {} segments", fit.segments);
    println!("  segment  true rate (°/s)            measured mean (°/s)                    residual (°/s)");
    for (i, s) in segments.iter().enumerate() {
        let model = triad::model::matrix::mul_vec(&fit.scale_misalignment, &s.true_rate);
        let r: Vec<String> = (0..3)
            .map(|k| {
                format!(
                    "{:+.2e}",
                    rad_to_deg(s.measured[k] - model[k] - fit.bias[k])
                )
            })
            .collect();
        println!(
            "  {:7}  [{:+7.2}, {:+7.2}, {:+7.2}]  [{:+10.5}, {:+10.5}, {:+10.5}]  [{}]",
            i + 1,
            rad_to_deg(s.true_rate[0]),
            rad_to_deg(s.true_rate[1]),
            rad_to_deg(s.true_rate[2]),
            rad_to_deg(s.measured[0]),
            rad_to_deg(s.measured[1]),
            rad_to_deg(s.measured[2]),
            r.join(", ")
        );
    }
    println!(
        "  residual ω̂ − (I+Σ)ω − b: RMS {:.3e} rad/s, max {:.3e} rad/s; condition number {:.3e}",
        fit.residual_rms, fit.residual_max, fit.condition
    );
    let report = FitReport {
        scale_misalignment: &fit.scale_misalignment,
        sigma_scale_misalignment: fit.sigma_scale_misalignment.as_ref(),
        bias: &fit.bias,
        sigma_bias: fit.sigma_bias.as_ref(),
        segments: fit.segments,
        residual_rms: fit.residual_rms,
        residual_max: fit.residual_max,
        condition: fit.condition,
    };
    report.print(
        "I+Σ",
        "rad/s",
        "4 segments for 4 unknowns per axis leave no degree of freedom",
    );
    let s = |x: &str| toml::Value::String(x.into());
    let mut table = toml::Table::new();
    table.insert(
        "method".into(),
        s("rate table, known rates: ω̂ = (I+Σ)ω + b, linear least squares (QR)"),
    );
    table.insert("records".into(), file_list(&args.rate_table));
    table.insert("rates".into(), s(rates_text));
    report.insert_statistics(&mut table);
    let header = format!(
        "Gyroscope fitted by `triad calib fit gyro` from {} rate-table segments of {}\n\
         at rates {rates_text} °/s: residual RMS {:.3e} rad/s.",
        fit.segments,
        names(&args.rate_table),
        fit.residual_rms
    );
    write_calibration(&args.output, Which::Gyro, report.triad(), &header, table)
}

fn gyro_static(args: GyroArgs) -> anyhow::Result<ExitCode> {
    let path: &Path = args.static_record.as_deref().unwrap_or(Path::new("-"));
    let gyro = fit_csv::read(path, fit_csv::GYRO)?;
    let s = stat(&gyro, 0, 0..gyro.samples.len());
    if s.count < 2 {
        bail!(
            "{}: {} sample(s), need at least 2 for a mean and its standard error",
            path.display(),
            s.count
        );
    }
    let (base_matrix, base_note) = match &args.output.base {
        Some(p) => (
            calib_file::load(p)?.calibration.gyro.scale_misalignment,
            "from --base",
        ),
        None => (triad::model::calibration::IDENTITY, "identity"),
    };
    let mut bias = s.mean;
    let earth_note = match args.latitude {
        Some(lat) => {
            if !(lat.is_finite() && lat.abs() <= 90.0) {
                bail!("--latitude {lat}: must be within −90..90 degrees");
            }
            // At rest the specific force points up: its mean direction is the
            // vertical, which carries Ω·sin φ of the Earth rate. The gyro
            // measures it through (I+Σ): ω̂ = (I+Σ)·ω_e + b.
            let accel = fit_csv::read(path, fit_csv::ACCEL)?;
            let f = static_segments::mean(&accel.samples);
            let n = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            if n.is_nan() || n <= 0.0 {
                bail!("{}: the mean specific force is zero: cannot tell the vertical", path.display());
            }
            let vertical = EARTH_RATE * deg_to_rad(lat).sin();
            let w = f.map(|fi| vertical * fi / n);
            let seen = triad::model::matrix::mul_vec(&base_matrix, &w);
            for (b, x) in bias.iter_mut().zip(seen) {
                *b -= x;
            }
            let horizontal = EARTH_RATE * deg_to_rad(lat).cos();
            format!(
                "the vertical Earth rate Ω·sin φ = {:.3} °/h is removed along the measured vertical; the horizontal \
                 part Ω·cos φ = {:.3} °/h (its direction is unknown without a heading) is still included",
                rad_to_deg(vertical) * 3600.0,
                rad_to_deg(horizontal) * 3600.0
            )
        }
        None => format!(
            "the Earth rate (up to Ω = {:.3} °/h) is included in the bias: give --latitude to remove its vertical part",
            rad_to_deg(EARTH_RATE) * 3600.0
        ),
    };
    println!(
        "gyro static bias: {} samples of {}",
        s.count,
        path.display()
    );
    print_vector("b (rad/s)", &bias, Some(&s.standard_error));
    println!("  (± is the standard error s/√n, which assumes white noise; `triad allan` shows the correlated part)");
    println!("  {earth_note}");
    let s_ = |x: &str| toml::Value::String(x.into());
    let mut table = toml::Table::new();
    table.insert(
        "method".into(),
        s_("static record: bias = mean of each axis"),
    );
    table.insert(
        "records".into(),
        toml::Value::Array(vec![s_(&path.display().to_string())]),
    );
    table.insert("samples".into(), toml::Value::Integer(s.count as i64));
    table.insert("sigma_bias".into(), vector(&s.standard_error));
    table.insert("earth_rate".into(), s_(&earth_note));
    let header = format!(
        "Gyroscope bias fitted by `triad calib fit gyro --static` from {} ({} samples);\n\
         gyro scale_misalignment {base_note}; {earth_note}.",
        path.display(),
        s.count
    );
    let triad = TriadCalibration {
        scale_misalignment: base_matrix,
        bias,
        temperature: None,
    };
    write_calibration(&args.output, Which::Gyro, triad, &header, table)
}
