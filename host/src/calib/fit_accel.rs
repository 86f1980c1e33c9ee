//! `triad calib fit accel`: the accelerometer from static positions, in
//! unknown orientations (the ellipsoid fit, [`accel_fit`]) or on the faces of
//! a cube (`--axis-aligned`, [`accel_cube`]).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use triad::model::Triad;
use triad::units::STANDARD_GRAVITY;
use triad_lab::calib_fit::fits::accel_fit::AccelFit;
use triad_lab::calib_fit::fits::accel_fit::AccelFitError;
use triad_lab::calib_fit::fits::gyro_fit::LinearFit;
use triad_lab::calib_fit::fits::{accel_cube, accel_fit};

use super::fit::{file_list, inputs, names, write_calibration, Base, Output};
use super::fit_csv::{self, Reading, Record};
use super::report::{fit_report, method_table, FRAME};
use super::segments::{self, Stat};
use super::Ranges;
use crate::plumbing::stdio::note;
use crate::plumbing::stdio::outln;

/// Arguments of `triad calib fit accel`.
#[derive(clap::Args)]
pub struct AccelArgs {
    /// CSV records (`t,ax,ay,az,...`, s and m/s²) of the sensor at rest in
    /// several orientations, with turns between; repeat for several files.
    /// Needs ≥ 9 distinct orientations spread over the sphere.
    #[arg(long, required = true)]
    positions: Vec<PathBuf>,
    /// The static segments as FROM-TO seconds, comma-separated (one
    /// --positions file only), instead of detecting them.
    #[arg(long)]
    segments: Option<String>,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Shortest static segment detected, seconds.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_static: f64,
    /// The positions are the faces of a cube (one sensor axis vertical in
    /// each, as in the tumble scenes): fit the full (I+Σ) and b linearly
    /// with gravity's direction known; needs ≥ 4 faces not in one plane.
    #[arg(long)]
    axis_aligned: bool,
    #[command(flatten)]
    reading: Reading,
    #[command(flatten)]
    output: Output,
}

/// Runs `triad calib fit accel`.
pub fn run(args: AccelArgs) -> anyhow::Result<ExitCode> {
    check(&args)?;
    let base = args
        .output
        .prepare(&inputs("--positions", &args.positions))?;
    let records = read_records(&args.reading, &args.positions, &args.output.ranges)?;
    let mut dropped = Vec::new();
    let stats = segments::given_or(&records, args.segments.as_deref(), "--positions", || {
        segments::detected_saying(&records, args.min_static, |line| dropped.push(line))
    })?;
    for line in &dropped {
        note!("{line}");
    }
    let means: Vec<[f64; 3]> = stats.iter().map(|s| s.mean).collect();
    if args.axis_aligned {
        cube(&args, base, &stats, &means)
    } else {
        ellipsoid(&args, base, &stats, &means)
    }
}

/// The accelerometer columns of `paths` as `reading` says, each time base
/// that needed repair noted on stderr.
pub fn read_records(
    reading: &Reading,
    paths: &[PathBuf],
    ranges: &Ranges,
) -> anyhow::Result<Vec<Record>> {
    paths
        .iter()
        .map(|p| {
            let (record, time) = reading.read(p, fit_csv::ACCEL, ranges)?;
            if let Some(line) = fit_csv::time_note(&crate::plumbing::input::name(p), &time, &record)
            {
                note!("{line}");
            }
            Ok(record)
        })
        .collect()
}

fn check(args: &AccelArgs) -> anyhow::Result<()> {
    segments::check_pose_options(args.gravity, args.min_static)
}

/// The ellipsoid fit: orientations unknown, |(I+Σ)⁻¹(f̂ − b)| = g.
fn ellipsoid(
    args: &AccelArgs,
    base: Base,
    stats: &[Stat],
    means: &[[f64; 3]],
) -> anyhow::Result<ExitCode> {
    let files = names(&args.positions);
    let fit = accel_fit::fit(means, args.gravity).map_err(|e| match e {
        AccelFitError::TooFewOrientations { .. } => anyhow!(
            "{files}: {e}; use --axis-aligned if one sensor axis was vertical in every position"
        ),
        AccelFitError::OrientationsInOnePlane { .. } => anyhow!("{files}: {e}"),
        _ => anyhow!("{files}: {} static segments: {e}", means.len()),
    })?;
    let mut out = String::new();
    print_ellipsoid(&mut out, args, stats, &fit);
    let report = fit_report!(fit);
    report.print(
        &mut out,
        "I+Σ (upper triangular by convention)",
        "m/s²",
        &format!(
            "{} segments for 9 unknowns leave no degree of freedom",
            fit.segments
        ),
    );
    let mut table = method_table(
        "multi-position, unknown orientations: |(I+Σ)⁻¹(f̂ − b)| = g, Levenberg–Marquardt from an algebraic ellipsoid",
        Some(FRAME),
    );
    table.insert("records".into(), file_list(&args.positions));
    table.insert("gravity".into(), toml::Value::Float(args.gravity));
    table.insert(
        "orientations".into(),
        toml::Value::Integer(fit.orientations as i64),
    );
    report.insert_statistics(&mut table);
    let header = format!(
        "Accelerometer fitted by `triad calib fit accel` from {} static segments\n\
         ({} orientations) of {files}: residual RMS {:.3e} m/s², max {:.3e} m/s².\n\
         (I+Σ) is upper triangular by convention: see [fit.accel].",
        fit.segments, fit.orientations, fit.residual_rms, fit.residual_max
    );
    write_calibration(
        &args.output,
        base,
        Triad::Accel,
        report.triad(),
        &header,
        table,
        &out,
    )
}

/// The ellipsoid fit's segments, residuals and conditioning.
fn print_ellipsoid(out: &mut String, args: &AccelArgs, stats: &[Stat], fit: &AccelFit) {
    outln!(
        out,
        "accelerometer fit: {} static segments, {} distinct orientations, g = {} m/s²",
        fit.segments,
        fit.orientations,
        args.gravity
    );
    outln!(out, "  segment  file  from..to (s)       samples  |f̂| (m/s²)      residual (m/s²)   noise of the mean (m/s²)");
    for (i, s) in stats.iter().enumerate() {
        let raw = (s.mean[0] * s.mean[0] + s.mean[1] * s.mean[1] + s.mean[2] * s.mean[2]).sqrt();
        let r = accel_fit::residual(&fit.inverse, &fit.bias, &s.mean, args.gravity);
        let se = s.standard_error.iter().fold(0.0f64, |a, &x| a.max(x));
        outln!(
            out,
            "  {:7}  {:4}  {:8.2}..{:<8.2} {:7}  {raw:.6}  {r:+.3e}        {se:.1e}",
            i + 1,
            s.file + 1,
            s.from,
            s.to,
            s.count
        );
    }
    outln!(
        out,
        "  residual |(I+Σ)⁻¹(f̂ − b)| − g: RMS {:.3e} m/s², max {:.3e} m/s²",
        fit.residual_rms,
        fit.residual_max
    );
    outln!(
        out,
        "  condition number of the scaled Jacobian {:.3e} (limit {:.0e}), {} iterations",
        fit.condition,
        accel_fit::MAX_CONDITION,
        fit.iterations
    );
}

/// `--axis-aligned`: the cube fit, f̂ = (I+Σ)·(±g e_k) + b.
fn cube(
    args: &AccelArgs,
    base: Base,
    stats: &[Stat],
    means: &[[f64; 3]],
) -> anyhow::Result<ExitCode> {
    let g = args.gravity;
    let fit = accel_cube::fit(means, g).map_err(|e| anyhow!("{}: {e}", names(&args.positions)))?;
    let mut out = String::new();
    print_cube(&mut out, stats, &fit, g);
    let report = fit_report!(fit);
    report.print(
        &mut out,
        "I+Σ (axes of the cube's faces)",
        "m/s²",
        "4 segments for 4 unknowns per axis leave no degree of freedom",
    );
    let mut table = method_table(
        "axis-aligned positions (cube faces): f̂ = (I+Σ)·(±g e_k) + b, linear least squares (QR)",
        Some("full (I+Σ): the axes are those of the cube (fixture) faces the sensor rested on"),
    );
    table.insert("records".into(), file_list(&args.positions));
    table.insert("gravity".into(), toml::Value::Float(g));
    report.insert_statistics(&mut table);
    let header = format!(
        "Accelerometer fitted by `triad calib fit accel --axis-aligned` from {} static\n\
         segments of {}: residual RMS {:.3e} m/s².",
        fit.segments,
        names(&args.positions),
        fit.residual_rms
    );
    write_calibration(
        &args.output,
        base,
        Triad::Accel,
        report.triad(),
        &header,
        table,
        &out,
    )
}

/// The face up of a reference specific force ±g·e_k: "+x" … "-z".
fn face(f: &[f64; 3]) -> &'static str {
    let axis = (0..3).find(|&k| f[k] != 0.0).unwrap_or(0);
    let down = if f.iter().sum::<f64>() < 0.0 { 3 } else { 0 };
    ["+x", "+y", "+z", "-x", "-y", "-z"][axis + down]
}

/// The cube fit's segments (face up, residual per axis) and conditioning.
fn print_cube(out: &mut String, stats: &[Stat], fit: &LinearFit, g: f64) {
    outln!(
        out,
        "accelerometer fit (axis-aligned positions): {} static segments, g = {g} m/s²",
        fit.segments
    );
    outln!(
        out,
        "  segment  file  from..to (s)       samples  face up  residual f̂ − (I+Σ)f − b (m/s²)"
    );
    for (i, s) in stats.iter().enumerate() {
        let f = accel_cube::reference(&s.mean, g).unwrap_or([0.0; 3]);
        let r: Vec<String> = fit
            .residual(&f, &s.mean)
            .iter()
            .map(|x| format!("{x:+.2e}"))
            .collect();
        outln!(
            out,
            "  {:7}  {:4}  {:8.2}..{:<8.2} {:7}  {:>7}  [{}]",
            i + 1,
            s.file + 1,
            s.from,
            s.to,
            s.count,
            face(&f),
            r.join(", ")
        );
    }
    outln!(
        out,
        "  residual: RMS {:.3e} m/s², max {:.3e} m/s²; condition number {:.3e}",
        fit.residual_rms,
        fit.residual_max,
        fit.condition
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_face_up_is_the_signed_axis_of_the_reference() {
        assert_eq!(face(&[0.0, 0.0, 9.8]), "+z");
        assert_eq!(face(&[-9.8, 0.0, 0.0]), "-x");
        assert_eq!(face(&[0.0, -9.8, 0.0]), "-y");
        // No reference (the mean is not near a face): shown as +x.
        assert_eq!(face(&[0.0; 3]), "+x");
    }
}
