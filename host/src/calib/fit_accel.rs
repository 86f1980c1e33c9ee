//! `triad calib fit accel`: the accelerometer from static positions, in
//! unknown orientations (the ellipsoid fit, [`accel_fit`]) or on the faces of
//! a cube (`--axis-aligned`, [`accel_cube`]).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad::units::STANDARD_GRAVITY;
use triad_lab::calib_fit::static_segments::{Detector, Segment};
use triad_lab::calib_fit::{accel_cube, accel_fit, FitError};

use super::fit::{
    file_list, given_segments, names, stat, write_calibration, FitReport, Output, Stat, Which,
};
use super::fit_csv;

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
    #[arg(long, default_value_t = STANDARD_GRAVITY)]
    gravity: f64,
    /// Shortest static segment detected, seconds.
    #[arg(long, default_value_t = 2.0)]
    min_static: f64,
    /// The positions are the faces of a cube (one sensor axis vertical in
    /// each, as in the tumble scenes): fit the full (I+Σ) and b linearly
    /// with gravity's direction known; needs ≥ 4 faces not in one plane.
    #[arg(long)]
    axis_aligned: bool,
    #[command(flatten)]
    output: Output,
}

/// Runs `triad calib fit accel`.
pub fn run(args: AccelArgs) -> anyhow::Result<ExitCode> {
    if !(args.gravity.is_finite() && args.gravity > 0.0) {
        bail!(
            "--gravity {}: must be a positive number of m/s²",
            args.gravity
        );
    }
    if !(args.min_static.is_finite() && args.min_static > 0.0) {
        bail!(
            "--min-static {}: must be a positive number of seconds",
            args.min_static
        );
    }
    let records = args
        .positions
        .iter()
        .map(|p| fit_csv::read(p, fit_csv::ACCEL))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let stats = match &args.segments {
        Some(text) => {
            if records.len() != 1 {
                bail!(
                    "--segments applies to a single --positions file; {} were given",
                    records.len()
                );
            }
            given_segments(&records[0], text)?
        }
        None => {
            let mut stats = Vec::new();
            for (file, record) in records.iter().enumerate() {
                let rate = record.rate_hz()?;
                // Blocks of 0.5 s (≥ 25 samples so the block deviation is
                // within ~15 % of σ, see static_segments::THRESHOLD_FACTOR).
                let block = ((0.5 * rate).round() as usize).max(25);
                let block_s = block as f64 / rate;
                let detector = Detector {
                    block,
                    min_blocks: (args.min_static / block_s).ceil() as usize,
                };
                let mut buffer =
                    vec![Segment { start: 0, end: 0 }; record.samples.len() / block + 1];
                let n = detector
                    .detect(&record.samples, &mut buffer)
                    .map_err(|e| anyhow!("{}: {e}", record.path.display()))?;
                stats.extend(
                    buffer[..n]
                        .iter()
                        .map(|s| stat(record, file, s.start..s.end)),
                );
            }
            stats
        }
    };
    let means: Vec<[f64; 3]> = stats.iter().map(|s| s.mean).collect();
    if args.axis_aligned {
        return accel_axis_aligned(&args, &stats, &means);
    }
    let fit = accel_fit::fit(&means, args.gravity).map_err(|e| match e {
        FitError::TooFewOrientations { .. } => anyhow!(
            "{}: {e}; use --axis-aligned if one sensor axis was vertical in every position",
            names(&args.positions)
        ),
        FitError::OrientationsInOnePlane { .. } => anyhow!("{}: {e}", names(&args.positions)),
        _ => anyhow!(
            "{}: {} static segments: {e}",
            names(&args.positions),
            means.len()
        ),
    })?;

    println!(
        "accelerometer fit: {} static segments, {} distinct orientations, g = {} m/s²",
        fit.segments, fit.orientations, args.gravity
    );
    println!("  segment  file  from..to (s)       samples  |f̂| (m/s²)      residual (m/s²)   noise of the mean (m/s²)");
    for (i, s) in stats.iter().enumerate() {
        let raw = (s.mean[0] * s.mean[0] + s.mean[1] * s.mean[1] + s.mean[2] * s.mean[2]).sqrt();
        let r = accel_fit::residual(&fit.inverse, &fit.bias, &s.mean, args.gravity);
        let se = s.standard_error.iter().fold(0.0f64, |a, &x| a.max(x));
        println!(
            "  {:7}  {:4}  {:8.2}..{:<8.2} {:7}  {raw:.6}  {r:+.3e}        {se:.1e}",
            i + 1,
            s.file + 1,
            s.from,
            s.to,
            s.count
        );
    }
    println!(
        "  residual |(I+Σ)⁻¹(f̂ − b)| − g: RMS {:.3e} m/s², max {:.3e} m/s²",
        fit.residual_rms, fit.residual_max
    );
    println!(
        "  condition number of the scaled Jacobian {:.3e} (limit {:.0e}), {} iterations",
        fit.condition,
        accel_fit::MAX_CONDITION,
        fit.iterations
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
        "I+Σ (upper triangular by convention)",
        "m/s²",
        &format!(
            "{} segments for 9 unknowns leave no degree of freedom",
            fit.segments
        ),
    );

    let mut fit_table = toml::Table::new();
    let s = |x: &str| toml::Value::String(x.into());
    fit_table.insert(
        "method".into(),
        s("multi-position, unknown orientations: |(I+Σ)⁻¹(f̂ − b)| = g, Levenberg–Marquardt from an algebraic ellipsoid"),
    );
    fit_table.insert(
        "convention".into(),
        s("(I+Σ) upper triangular: corrected z = the z sensing axis, corrected y in the plane of the y and z sensing axes, x completes the frame"),
    );
    fit_table.insert("records".into(), file_list(&args.positions));
    fit_table.insert("gravity".into(), toml::Value::Float(args.gravity));
    fit_table.insert(
        "orientations".into(),
        toml::Value::Integer(fit.orientations as i64),
    );
    report.insert_statistics(&mut fit_table);
    let header = format!(
        "Accelerometer fitted by `triad calib fit accel` from {} static segments\n\
         ({} orientations) of {}: residual RMS {:.3e} m/s², max {:.3e} m/s².\n\
         (I+Σ) is upper triangular by convention: see [fit.accel].",
        fit.segments,
        fit.orientations,
        names(&args.positions),
        fit.residual_rms,
        fit.residual_max
    );
    write_calibration(
        &args.output,
        Which::Accel,
        report.triad(),
        &header,
        fit_table,
    )
}

/// `triad calib fit accel --axis-aligned`: the cube fit.
fn accel_axis_aligned(
    args: &AccelArgs,
    stats: &[Stat],
    means: &[[f64; 3]],
) -> anyhow::Result<ExitCode> {
    let g = args.gravity;
    let fit = accel_cube::fit(means, g).map_err(|e| anyhow!("{}: {e}", names(&args.positions)))?;
    println!(
        "accelerometer fit (axis-aligned positions): {} static segments, g = {g} m/s²",
        fit.segments
    );
    println!(
        "  segment  file  from..to (s)       samples  face up  residual f̂ − (I+Σ)f − b (m/s²)"
    );
    for (i, s) in stats.iter().enumerate() {
        let f = accel_cube::reference(&s.mean, g).unwrap_or([0.0; 3]);
        let face = ["+x", "+y", "+z", "-x", "-y", "-z"][(0..3).find(|&k| f[k] != 0.0).unwrap_or(0)
            + if f.iter().sum::<f64>() < 0.0 { 3 } else { 0 }];
        let model = triad::model::matrix::mul_vec(&fit.scale_misalignment, &f);
        let r: Vec<String> = (0..3)
            .map(|k| format!("{:+.2e}", s.mean[k] - model[k] - fit.bias[k]))
            .collect();
        println!(
            "  {:7}  {:4}  {:8.2}..{:<8.2} {:7}  {face:>7}  [{}]",
            i + 1,
            s.file + 1,
            s.from,
            s.to,
            s.count,
            r.join(", ")
        );
    }
    println!(
        "  residual: RMS {:.3e} m/s², max {:.3e} m/s²; condition number {:.3e}",
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
        "I+Σ (axes of the cube's faces)",
        "m/s²",
        "4 segments for 4 unknowns per axis leave no degree of freedom",
    );
    let s = |x: &str| toml::Value::String(x.into());
    let mut table = toml::Table::new();
    table.insert(
        "method".into(),
        s("axis-aligned positions (cube faces): f̂ = (I+Σ)·(±g e_k) + b, linear least squares (QR)"),
    );
    table.insert(
        "convention".into(),
        s("full (I+Σ): the axes are those of the cube (fixture) faces the sensor rested on"),
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
    write_calibration(&args.output, Which::Accel, report.triad(), &header, table)
}
