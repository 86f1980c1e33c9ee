//! `triad calib fit gyro`: (I+Σ) and b from rate-table runs with known
//! rates ([`gyro_fit`]), or the bias alone from a static record, and with
//! it the g-sensitivity G from a record of several static poses
//! ([`gyro_at_rest`]). The lab fits; this module parses the arguments,
//! reads the records, renders the report and writes the calibration.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad::model::{Triad, TriadCalibration};
use triad::units::{deg_to_rad, rad_to_deg, EARTH_RATE};
use triad_lab::calib_fit::fits::gyro_at_rest::{
    self, AtRestOptions, AtRestRecord, GyroAtRest, GyroAtRestError, PosesAtRest, StaticBias,
};
use triad_lab::calib_fit::fits::gyro_fit::{self, LinearFit, RateSegment};
use triad_lab::calib_fit::poses;
use triad_lab::calib_fit::stillness;

use super::fit::{file_list, inputs, names, write_calibration, Base, Output};
use super::fit_csv;
use super::g_sensitivity_report;
use super::report::{fit_report, method_table, print_vector};
use super::segments::{self, stat, Stat};
use crate::calib::file::vector;
use crate::plumbing::input;
use crate::plumbing::number::{positive, readable};
use crate::plumbing::stdio::outln;

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
    /// A static record (`t,ax,ay,az,gx,gy,gz`): fit the gyro bias alone
    /// (mean of each axis). A record of several static poses with turns
    /// between them (found from the accelerometer) gives the bias and,
    /// where the poses' gravity directions span three dimensions, the
    /// g-sensitivity G, in the frame of --base's accelerometer.
    #[arg(long = "static")]
    static_record: Option<PathBuf>,
    /// With --static: the shortest static pose detected, seconds.
    #[arg(
        long,
        requires = "static_record",
        default_value_t = 2.0,
        allow_negative_numbers = true
    )]
    min_static: f64,
    /// Latitude in degrees: subtract the vertical Earth-rate component from a static bias.
    #[arg(long, requires = "static_record", allow_negative_numbers = true)]
    latitude: Option<f64>,
    /// With --static: the largest mean rate taken as a bias, °/s (a larger
    /// one is a turn, e.g. a rate table, and is refused).
    #[arg(long, value_name = "DEG_PER_S", default_value_t = stillness::DEFAULT_MAX_BIAS_DPS, allow_negative_numbers = true)]
    max_bias: f64,
    #[command(flatten)]
    reading: fit_csv::Reading,
    #[command(flatten)]
    output: Output,
}

/// Runs `triad calib fit gyro`.
pub fn run(args: GyroArgs) -> anyhow::Result<ExitCode> {
    let statics: Vec<PathBuf> = args.static_record.iter().cloned().collect();
    let mut given = inputs("--rate-table", &args.rate_table);
    given.extend(inputs("--static", &statics));
    let base = args.output.prepare(&given)?;
    match &args.static_record {
        Some(path) => gyro_static(&args, base, path),
        None => rate_table(&args, base),
    }
}

/// `x:+30` → the rate vector, rad/s, about that sensor axis.
pub fn parse_rates(text: &str) -> anyhow::Result<Vec<[f64; 3]>> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(parse_rate)
        .collect()
}

fn parse_rate(item: &str) -> anyhow::Result<[f64; 3]> {
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
        .ok_or_else(|| {
            anyhow!(
                "--rates: `{}` in `{item}` is not a number of °/s",
                rate.trim()
            )
        })?;
    let mut w = [0.0; 3];
    w[index] = sign * deg_to_rad(dps);
    Ok(w)
}

/// The rate-table fit: ω̂ = (I+Σ)ω + b over one segment per known rate.
fn rate_table(args: &GyroArgs, base: Base) -> anyhow::Result<ExitCode> {
    let Some(rates_text) = &args.rates else {
        bail!("--rate-table needs --rates: the true rate of each run, e.g. \"z:+30,z:-30,x:+30,y:+30\" (°/s)");
    };
    let rates = parse_rates(rates_text)?;
    let records = args
        .reading
        .read_all(&args.rate_table, fit_csv::GYRO, &args.output.ranges)?;
    let stats = segments::given_or(&records, args.segments.as_deref(), "--rate-table", || {
        Ok(records
            .iter()
            .enumerate()
            .map(|(i, r)| stat(r, i, 0..r.samples.len()))
            .collect())
    })?;
    let segments = rate_segments(&stats, &rates, args.segments.is_some())?;
    let fit = gyro_fit::fit(&segments).map_err(|e| anyhow!("{}: {e}", names(&args.rate_table)))?;
    let mut out = String::new();
    print_rate_table(&mut out, &segments, &fit);
    let report = fit_report!(fit);
    report.print(
        &mut out,
        "I+Σ",
        "rad/s",
        "4 segments for 4 unknowns per axis leave no degree of freedom",
    );
    let mut table = method_table(
        "rate table, known rates: ω̂ = (I+Σ)ω + b, linear least squares (QR)",
        None,
    );
    table.insert("records".into(), file_list(&args.rate_table));
    table.insert("rates".into(), toml::Value::String(rates_text.clone()));
    report.insert_statistics(&mut table);
    let header = format!(
        "Gyroscope fitted by `triad calib fit gyro` from {} rate-table segments of {}\n\
         at rates {rates_text} °/s: residual RMS {:.3e} rad/s.",
        fit.segments,
        names(&args.rate_table),
        fit.residual_rms
    );
    write_calibration(
        &args.output,
        base,
        Triad::Gyro,
        report.triad(),
        &header,
        table,
        &out,
    )
}

/// Each segment's mean against its true rate; one rate per segment.
fn rate_segments(
    stats: &[Stat],
    rates: &[[f64; 3]],
    given: bool,
) -> anyhow::Result<Vec<RateSegment>> {
    if stats.len() != rates.len() {
        bail!(
            "--rates gives {} rate(s) for {} segment(s) ({}): give one rate per run",
            rates.len(),
            stats.len(),
            if given {
                "--segments"
            } else {
                "--rate-table files"
            }
        );
    }
    Ok(stats
        .iter()
        .zip(rates)
        .map(|(s, w)| RateSegment {
            true_rate: *w,
            measured: s.mean,
        })
        .collect())
}

/// The rate-table fit's segments (true rate, mean, residual; °/s) and conditioning.
fn print_rate_table(out: &mut String, segments: &[RateSegment], fit: &LinearFit) {
    outln!(out, "gyro rate-table fit: {} segments", fit.segments);
    outln!(out, "  segment  true rate (°/s)            measured mean (°/s)                    residual (°/s)");
    for (i, s) in segments.iter().enumerate() {
        let r: Vec<String> = fit
            .residual(&s.true_rate, &s.measured)
            .iter()
            .map(|&x| format!("{:+.2e}", rad_to_deg(x)))
            .collect();
        let [w0, w1, w2] = s.true_rate.map(rad_to_deg);
        let [m0, m1, m2] = s.measured.map(rad_to_deg);
        outln!(
            out,
            "  {:7}  [{w0:+7.2}, {w1:+7.2}, {w2:+7.2}]  [{m0:+10.5}, {m1:+10.5}, {m2:+10.5}]  [{}]",
            i + 1,
            r.join(", ")
        );
    }
    outln!(
        out,
        "  residual ω̂ − (I+Σ)ω − b: RMS {:.3e} rad/s, max {:.3e} rad/s; condition number {:.3e}",
        fit.residual_rms,
        fit.residual_max,
        fit.condition
    );
}

/// `--static`: the bias alone, the mean of each axis (less the vertical
/// Earth rate with `--latitude`), the scale kept from `--base`; or, from a
/// record of several poses, the bias and G ([`gyro_at_rest`]).
fn gyro_static(args: &GyroArgs, base: Base, path: &Path) -> anyhow::Result<ExitCode> {
    positive(
        "--max-bias",
        args.max_bias,
        "must be a positive number of °/s",
    )?;
    if let Some(lat) = args.latitude {
        if !(lat.is_finite() && lat.abs() <= 90.0) {
            bail!(
                "--latitude {}: must be within −90..90 degrees",
                readable(lat)
            );
        }
    }
    // Read once (it may be standard input): the gyro, and the accelerometer when there.
    let text = fit_csv::read_content(path)?;
    let ranges = &args.output.ranges;
    let (gyro, _) = args.reading.parse(&text, path, fit_csv::GYRO, ranges)?;
    let accel = args
        .reading
        .parse(&text, path, fit_csv::ACCEL, ranges)
        .ok()
        .map(|(r, _)| r);
    drop(text);
    // With the accelerometer, its static stretches may be several poses.
    let detector = match &accel {
        Some(accel) => {
            positive(
                "--min-static",
                args.min_static,
                "must be a positive number of seconds",
            )?;
            accel
                .rate_hz()
                .ok()
                .map(|rate| poses::detector(rate, args.min_static))
        }
        None => None,
    };
    let parts = accel.as_ref().map(|a| a.parts()).unwrap_or_default();
    let record = AtRestRecord {
        t: &gyro.t,
        gyro: &gyro.samples,
        accel: accel.as_ref().map(|a| a.samples.as_slice()),
        parts: &parts,
    };
    // Without --base the base is the identity.
    let options = AtRestOptions {
        detector,
        max_bias_dps: args.max_bias,
        earth_vertical: args.latitude.map(|lat| EARTH_RATE * deg_to_rad(lat).sin()),
        accel_scale_misalignment: base.calibration.accel.scale_misalignment,
        accel_bias: base.calibration.accel.bias,
        gyro_scale_misalignment: base.calibration.gyro.scale_misalignment,
    };
    let name = input::name(path);
    match gyro_at_rest::fit(&record, &options).map_err(|e| refusal(&name, e))? {
        GyroAtRest::Bias(fit) => write_bias(args, base, path, &fit),
        GyroAtRest::Poses(fit) => write_poses(args, base, path, &gyro, &fit),
    }
}

/// The refusal of the record `name`, in the options' words.
fn refusal(name: &str, e: GyroAtRestError) -> anyhow::Error {
    match e {
        GyroAtRestError::NotStill {
            pose: None,
            why,
            poses_detected,
        } => match poses_detected {
            Some(n) => anyhow!(
                "{} ({})",
                why.named(name),
                gyro_at_rest::fewer_than_two_poses(n)
            ),
            None => anyhow!("{}", why.named(name)),
        },
        GyroAtRestError::NotStill {
            pose: Some(p), why, ..
        } => {
            anyhow!("{}", why.named(&format!("{name} {p}")))
        }
        GyroAtRestError::NoAccelerometer => anyhow!(
            "{name}: --latitude needs the accelerometer columns ax,ay,az to tell the vertical"
        ),
        e @ GyroAtRestError::SingularAccel => anyhow!("--base: {e}"),
        e => anyhow!("{name}: {e}"),
    }
}

/// The bias of a still record: report and calibration.
fn write_bias(
    args: &GyroArgs,
    base: Base,
    path: &Path,
    fit: &StaticBias,
) -> anyhow::Result<ExitCode> {
    let s = &fit.statistics;
    let base_matrix = base.calibration.gyro.scale_misalignment;
    let base_note = if args.output.base.is_some() {
        "from --base"
    } else {
        "identity"
    };
    let earth_note = match args.latitude {
        Some(lat) => format!(
            "the vertical Earth rate Ω·sin φ = {:.3} °/h is removed along the measured vertical; the horizontal \
             part Ω·cos φ = {:.3} °/h (its direction is unknown without a heading) is still included",
            rad_to_deg(EARTH_RATE * deg_to_rad(lat).sin()) * 3600.0,
            rad_to_deg(EARTH_RATE * deg_to_rad(lat).cos()) * 3600.0
        ),
        None => format!(
            "the Earth rate (up to Ω = {:.3} °/h) is included in the bias: give --latitude to remove its vertical part",
            rad_to_deg(EARTH_RATE) * 3600.0
        ),
    };
    let mut out = String::new();
    outln!(
        out,
        "gyro static bias: {} samples of {} (still: no part turned, mean rate within --max-bias)",
        s.count,
        input::name(path)
    );
    print_vector(&mut out, "b (rad/s)", &fit.bias, Some(&s.standard_error));
    outln!(out, "  (± is the standard error s/√n, which assumes white noise; `triad allan` shows the correlated part)");
    outln!(out, "  {earth_note}");
    if let Some(n) = fit.poses_detected {
        outln!(out, "  ({})", gyro_at_rest::fewer_than_two_poses(n));
    }
    let table = static_table(path, fit, &earth_note);
    let header = format!(
        "Gyroscope bias fitted by `triad calib fit gyro --static` from {} ({} samples);\n\
         gyro scale_misalignment {base_note}; {earth_note}.",
        input::name(path),
        s.count
    );
    let triad = TriadCalibration {
        scale_misalignment: base_matrix,
        bias: fit.bias,
        temperature: None,
    };
    write_calibration(&args.output, base, Triad::Gyro, triad, &header, table, &out)
}

/// The bias and G of several static poses: report and calibration, G in
/// the frame of the base's accelerometer (the one the file carries).
fn write_poses(
    args: &GyroArgs,
    base: Base,
    path: &Path,
    gyro: &fit_csv::Record,
    fit: &PosesAtRest,
) -> anyhow::Result<ExitCode> {
    let name = input::name(path);
    let (poses, rest) = (&fit.poses, &fit.rest);
    let base_matrix = base.calibration.gyro.scale_misalignment;
    let earth_note = match args.latitude {
        Some(lat) => format!(
            "the vertical Earth rate Ω·sin φ = {:.3} °/h is removed from each pose along its own measured vertical; the horizontal part Ω·cos φ = {:.3} °/h (its direction is unknown without a heading) is still included",
            rad_to_deg(EARTH_RATE * deg_to_rad(lat).sin()) * 3600.0,
            rad_to_deg(EARTH_RATE * deg_to_rad(lat).cos()) * 3600.0
        ),
        None => format!(
            "the Earth rate (up to Ω = {:.3} °/h) is included in the bias (and, its vertical part turning with each pose, in G as up to {:.4} °/s per g): give --latitude to remove its vertical part",
            rad_to_deg(EARTH_RATE) * 3600.0,
            rad_to_deg(EARTH_RATE)
        ),
    };
    let mut out = String::new();
    outln!(
        out,
        "gyro at rest in {} static poses of {name} (each still; bias{}):",
        poses.len(),
        if rest.support.applied().is_some() {
            " and g-sensitivity"
        } else {
            ""
        }
    );
    outln!(
        out,
        "  pose  from..to (s)         samples          |f| (m/s²)"
    );
    for (i, p) in poses.iter().enumerate() {
        let s = &p.samples;
        outln!(
            out,
            "  {:>4}  {:>8.2}..{:<8.2}  {:>7}..{:<7}  {:.5}",
            i + 1,
            gyro.t[s.start],
            gyro.t[s.end - 1],
            s.start + 1,
            s.end,
            p.force
        );
    }
    print_vector(&mut out, "b (rad/s)", &rest.bias, rest.sigma_bias.as_ref());
    let model = if rest.support.applied().is_some() {
        "about the fit of bias and g-sensitivity to them"
    } else {
        "about their mean"
    };
    outln!(
        out,
        "  (bias σ's: the scatter of the {} poses' means {model}, {} degrees of freedom)",
        poses.len(),
        rest.bias_dof
    );
    g_sensitivity_report::print(&mut out, &rest.support, &rest.check, poses.len());
    outln!(out, "  {earth_note}");
    let mut table = method_table(
        "static poses: bias (and g-sensitivity G where the poses' gravity directions support it) from the poses' means",
        Some("G's columns: the accelerometer's axes as --base corrects them"),
    );
    table.insert("records".into(), file_list(&[path]));
    table.insert("poses".into(), toml::Value::Integer(poses.len() as i64));
    if let Some(sigma) = &rest.sigma_bias {
        table.insert("sigma_bias".into(), vector(sigma));
    }
    table.insert(
        "bias_degrees_of_freedom".into(),
        toml::Value::Integer(rest.bias_dof as i64),
    );
    table.insert("earth_rate".into(), toml::Value::String(earth_note.clone()));
    g_sensitivity_report::insert(&mut table, &rest.support, &rest.check);
    let base_note = if args.output.base.is_some() {
        "from --base"
    } else {
        "identity"
    };
    let header = format!(
        "Gyroscope bias{} fitted by `triad calib fit gyro --static` from {} static poses of {name};\n\
         gyro scale_misalignment {base_note}; {earth_note}.",
        if rest.support.applied().is_some() {
            " and g-sensitivity"
        } else {
            ""
        },
        poses.len()
    );
    let triad = TriadCalibration {
        scale_misalignment: base_matrix,
        bias: rest.bias,
        temperature: None,
    };
    let base = base.with_g_sensitivity(rest.support.applied().map(|g| g.g));
    write_calibration(&args.output, base, Triad::Gyro, triad, &header, table, &out)
}

/// The `[fit.gyro]` table of a static bias.
fn static_table(path: &Path, fit: &StaticBias, earth_note: &str) -> toml::Table {
    let s = &fit.statistics;
    let mut table = method_table("static record: bias = mean of each axis", None);
    table.insert("records".into(), file_list(&[path]));
    table.insert("samples".into(), toml::Value::Integer(s.count as i64));
    table.insert("sigma_bias".into(), vector(&s.standard_error));
    table.insert("earth_rate".into(), toml::Value::String(earth_note.into()));
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_signed_axes_in_degrees_per_second() {
        let r = parse_rates("z:+30, -x:90,,y:0").unwrap();
        assert_eq!(r.len(), 3);
        assert_eq!(r[0], [0.0, 0.0, deg_to_rad(30.0)]);
        assert_eq!(r[1], [-deg_to_rad(90.0), 0.0, 0.0]);
        let err = |t: &str| parse_rates(t).unwrap_err().to_string();
        assert!(err("z30").contains("is not AXIS:RATE"));
        assert!(err("w:30").contains("axis `w` in `w:30`"));
        assert!(err("z:inf").contains("`inf` in `z:inf` is not a number"));
    }

    #[test]
    fn one_rate_per_segment() {
        let s = Stat {
            file: 0,
            from: 0.0,
            to: 1.0,
            mean: [1.0, 2.0, 3.0],
            standard_error: [0.0; 3],
            count: 10,
        };
        let segs = rate_segments(std::slice::from_ref(&s), &[[0.5, 0.0, 0.0]], false).unwrap();
        assert_eq!(
            (segs[0].true_rate[0], segs[0].measured),
            (0.5, [1.0, 2.0, 3.0])
        );
        let err = rate_segments(&[s.clone(), s], &[[0.0; 3]], true).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--rates gives 1 rate(s) for 2 segment(s) (--segments): give one rate per run"
        );
    }
}
