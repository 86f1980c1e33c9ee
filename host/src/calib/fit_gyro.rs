//! `triad calib fit gyro`: (I+Σ) and b from rate-table runs with known
//! rates ([`gyro_fit`]), or the bias alone from a static record, and with
//! it the g-sensitivity G from a record of several static poses
//! ([`static_gyro`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad::model::matrix::{self, mul_vec, Mat3};
use triad::model::{Triad, TriadCalibration};
use triad::units::{deg_to_rad, rad_to_deg, EARTH_RATE};
use triad_lab::calib_fit::fits::gyro_fit::{self, LinearFit, RateSegment};
use triad_lab::calib_fit::fits::static_gyro::{self, Frame};
use triad_lab::calib_fit::static_segments::{self, Segment};

use super::fit::{file_list, inputs, names, write_calibration, Base, Output};
use super::fit_csv;
use super::g_sensitivity_report;
use super::report::{fit_report, method_table, print_vector};
use super::segments::{self, stat, Stat};
use super::stillness;
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
        let model = mul_vec(&fit.scale_misalignment, &s.true_rate);
        let r: Vec<String> = (0..3)
            .map(|k| {
                format!(
                    "{:+.2e}",
                    rad_to_deg(s.measured[k] - model[k] - fit.bias[k])
                )
            })
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
/// Earth rate with `--latitude`), the scale kept from `--base`.
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
    // Several poses (the accelerometer's static stretches) with turns
    // between them: the bias and G from the poses.
    if let Some(accel) = &accel {
        positive(
            "--min-static",
            args.min_static,
            "must be a positive number of seconds",
        )?;
        if let Ok(found) = segments::detect(accel, args.min_static) {
            if found.segments.len() >= 2 {
                return gyro_poses(args, base, path, &gyro, accel, &found.segments);
            }
        }
    }
    let s = stat(&gyro, 0, 0..gyro.samples.len());
    if s.count < 2 {
        bail!(
            "{}: {} sample(s), need at least 2 for a mean and its standard error",
            input::name(path),
            s.count
        );
    }
    stillness::check(
        &input::name(path),
        &gyro.samples,
        accel.as_ref().map(|a| a.samples.as_slice()),
        &s.mean,
        args.max_bias,
    )?;
    // Without --base the base is the identity.
    let base_matrix = base.calibration.gyro.scale_misalignment;
    let base_note = if args.output.base.is_some() {
        "from --base"
    } else {
        "identity"
    };
    let (bias, earth_note) = match args.latitude {
        Some(lat) => without_earth_rate(path, accel.as_ref(), s.mean, lat, &base_matrix)?,
        None => (
            s.mean,
            format!(
                "the Earth rate (up to Ω = {:.3} °/h) is included in the bias: give --latitude to remove its vertical part",
                rad_to_deg(EARTH_RATE) * 3600.0
            ),
        ),
    };
    let mut out = String::new();
    outln!(
        out,
        "gyro static bias: {} samples of {} (still: no part turned, mean rate within --max-bias)",
        s.count,
        input::name(path)
    );
    print_vector(&mut out, "b (rad/s)", &bias, Some(&s.standard_error));
    outln!(out, "  (± is the standard error s/√n, which assumes white noise; `triad allan` shows the correlated part)");
    outln!(out, "  {earth_note}");
    let table = static_table(path, &s, &earth_note);
    let header = format!(
        "Gyroscope bias fitted by `triad calib fit gyro --static` from {} ({} samples);\n\
         gyro scale_misalignment {base_note}; {earth_note}.",
        input::name(path),
        s.count
    );
    let triad = TriadCalibration {
        scale_misalignment: base_matrix,
        bias,
        temperature: None,
    };
    write_calibration(&args.output, base, Triad::Gyro, triad, &header, table, &out)
}

/// `--static` on a record of several poses: the bias and G from the
/// poses' means ([`static_gyro`]), each pose checked still, G in the frame
/// of the base's accelerometer (the one the file carries).
fn gyro_poses(
    args: &GyroArgs,
    base: Base,
    path: &Path,
    gyro: &fit_csv::Record,
    accel: &fit_csv::Record,
    poses: &[Segment],
) -> anyhow::Result<ExitCode> {
    let name = input::name(path);
    let pose_span = |p: &Segment| {
        format!(
            "t = {:.2}..{:.2} s",
            gyro.t[p.start],
            gyro.t[p.end.max(p.start + 1) - 1]
        )
    };
    for (i, p) in poses.iter().enumerate() {
        let still = stat(gyro, 0, p.start..p.end);
        stillness::check(
            &format!("{name} pose {} ({})", i + 1, pose_span(p)),
            &gyro.samples[p.start..p.end],
            Some(&accel.samples[p.start..p.end]),
            &still.mean,
            args.max_bias,
        )?;
    }
    let accel_cal = &base.calibration.accel;
    let accel_inverse = matrix::inverse(&accel_cal.scale_misalignment).ok_or_else(|| {
        anyhow!("--base: the accelerometer's (I+Σ) is singular: cannot correct the poses' specific force")
    })?;
    let base_matrix = base.calibration.gyro.scale_misalignment;
    let earth = args
        .latitude
        .map(|lat| (EARTH_RATE * deg_to_rad(lat).sin(), base_matrix));
    let frame = Frame {
        accel_inverse,
        accel_bias: accel_cal.bias,
        earth,
    };
    let rest = static_gyro::fit(&gyro.t, &gyro.samples, &accel.samples, poses, &frame)
        .map_err(|e| anyhow!("{name}: gyroscope: {e}"))?;
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
        let m = static_segments::mean(&accel.samples[p.start..p.end]);
        let f = mul_vec(&accel_inverse, &[0, 1, 2].map(|k| m[k] - accel_cal.bias[k]));
        outln!(
            out,
            "  {:>4}  {:>8.2}..{:<8.2}  {:>7}..{:<7}  {:.5}",
            i + 1,
            gyro.t[p.start],
            gyro.t[p.end - 1],
            p.start + 1,
            p.end,
            (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()
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
fn static_table(path: &Path, s: &Stat, earth_note: &str) -> toml::Table {
    let mut table = method_table("static record: bias = mean of each axis", None);
    table.insert("records".into(), file_list(&[path]));
    table.insert("samples".into(), toml::Value::Integer(s.count as i64));
    table.insert("sigma_bias".into(), vector(&s.standard_error));
    table.insert("earth_rate".into(), toml::Value::String(earth_note.into()));
    table
}

/// The static `mean` of the record at `path` less the vertical Earth rate
/// at latitude `lat` (degrees) as a gyro of scale `matrix` sees it, and the
/// sentence saying what was removed. `accel` is the record's accelerometer.
fn without_earth_rate(
    path: &Path,
    accel: Option<&fit_csv::Record>,
    mean: [f64; 3],
    lat: f64,
    matrix: &Mat3,
) -> anyhow::Result<([f64; 3], String)> {
    // At rest the specific force points up: its mean direction is the
    // vertical, which carries Ω·sin φ of the Earth rate.
    let Some(accel) = accel else {
        bail!(
            "{}: --latitude needs the accelerometer columns ax,ay,az to tell the vertical",
            input::name(path)
        );
    };
    let up = static_segments::mean(&accel.samples);
    let bias = remove_vertical_rate(mean, up, lat, matrix).ok_or_else(|| {
        anyhow!(
            "{}: the mean specific force is zero: cannot tell the vertical",
            input::name(path)
        )
    })?;
    let vertical = EARTH_RATE * deg_to_rad(lat).sin();
    let horizontal = EARTH_RATE * deg_to_rad(lat).cos();
    let note = format!(
        "the vertical Earth rate Ω·sin φ = {:.3} °/h is removed along the measured vertical; the horizontal \
         part Ω·cos φ = {:.3} °/h (its direction is unknown without a heading) is still included",
        rad_to_deg(vertical) * 3600.0,
        rad_to_deg(horizontal) * 3600.0
    );
    Ok((bias, note))
}

/// `mean` less Ω·sin φ along the direction of `up`, as the gyro measures it
/// through (I+Σ) = `matrix`: ω̂ = (I+Σ)·ω_e + b. None when `up` is zero.
fn remove_vertical_rate(mean: [f64; 3], up: [f64; 3], lat: f64, matrix: &Mat3) -> Option<[f64; 3]> {
    let n = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    if n.is_nan() || n <= 0.0 {
        return None;
    }
    let vertical = EARTH_RATE * deg_to_rad(lat).sin();
    let w = up.map(|fi| vertical * fi / n);
    let seen = mul_vec(matrix, &w);
    let mut bias = mean;
    for (b, x) in bias.iter_mut().zip(seen) {
        *b -= x;
    }
    Some(bias)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::model::calibration::IDENTITY;

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

    #[test]
    fn the_vertical_earth_rate_is_removed_along_the_measured_up() {
        // Level, z up, at the pole: all of Ω on z.
        let b = remove_vertical_rate([1.0, 2.0, 3.0], [0.0, 0.0, 9.8], 90.0, &IDENTITY).unwrap();
        assert_eq!((b[0], b[1]), (1.0, 2.0));
        assert!((b[2] - (3.0 - EARTH_RATE)).abs() < 1e-15);
        // At the equator nothing is vertical.
        let b = remove_vertical_rate([1.0; 3], [0.0, 9.8, 0.0], 0.0, &IDENTITY).unwrap();
        assert_eq!(b, [1.0; 3]);
        assert!(remove_vertical_rate([0.0; 3], [0.0; 3], 45.0, &IDENTITY).is_none());
    }
}
