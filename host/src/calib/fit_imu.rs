//! `triad calib fit imu`: both triads from one record of the IMU turned by
//! hand between static poses, no rate table and no fixture. The
//! accelerometer is fitted first from the poses in unknown orientations
//! ([`accel_fit`]); then the gyroscope's bias from the poses and its (I+Σ)
//! by integrating it between consecutive poses and matching the predicted
//! gravity direction to the measured one ([`rig_free`]: the method of
//! Tedaldi, Pretto and Menegatti, ICRA 2014). Both go in the file, with
//! their statistics in `[fit.accel]` and `[fit.gyro]`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use triad::model::{Triad, TriadCalibration};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_lab::calib_fit::rig_free::{self, RigFreeGyroFit};
use triad_lab::calib_fit::static_segments::Segment;
use triad_lab::calib_fit::{accel_fit, FitError};

use super::fit::{file_list, inputs, write_calibration, Output};
use super::fit_csv;
use super::report::{method_table, FitReport};
use super::segments::{check_pose_options, detector, stat};
use crate::stdio::outln;

/// Arguments of `triad calib fit imu`.
#[derive(clap::Args)]
pub struct ImuArgs {
    /// One CSV record (`t,ax,ay,az,gx,gy,gz,...`, SI units) of the IMU
    /// turned by hand between at least 9 static poses in different
    /// orientations, turning about several axes.
    #[arg(long)]
    positions: PathBuf,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Shortest static pose detected, seconds.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_static: f64,
    #[command(flatten)]
    output: Output,
}

/// Runs `triad calib fit imu`.
pub fn run(args: ImuArgs) -> anyhow::Result<ExitCode> {
    check_pose_options(args.gravity, args.min_static)?;
    let paths = [args.positions.clone()];
    let base = args.output.prepare(&inputs("--positions", &paths))?;
    let name = crate::input::name(&args.positions);
    let accel = fit_csv::read(&args.positions, fit_csv::ACCEL)?;
    let gyro = fit_csv::read(&args.positions, fit_csv::GYRO)?;
    // The poses: the accelerometer's static stretches.
    let d = detector(accel.rate_hz()?, args.min_static);
    let mut buffer = vec![Segment { start: 0, end: 0 }; accel.samples.len() / d.block + 1];
    let n = d
        .detect(&accel.samples, &mut buffer)
        .map_err(|e| anyhow!("{name}: {e}"))?;
    let poses = &buffer[..n];
    let stats: Vec<_> = poses
        .iter()
        .map(|p| stat(&accel, 0, p.start..p.end))
        .collect();
    let means: Vec<[f64; 3]> = stats.iter().map(|s| s.mean).collect();
    let accel_fit = accel_fit::fit(&means, args.gravity).map_err(|e| match e {
        FitError::TooFewOrientations { .. } | FitError::OrientationsInOnePlane { .. } => {
            anyhow!("{name}: accelerometer: {e}; turn the board to more orientations")
        }
        _ => anyhow!("{name}: accelerometer, {} static poses: {e}", means.len()),
    })?;
    let full_scale = deg_to_rad(args.output.ranges.gyro_range_dps);
    let record = rig_free::Record {
        t: &gyro.t,
        gyro: &gyro.samples,
    };
    let gyro_fit = rig_free::fit(record, poses, &means, &accel_fit, full_scale)
        .map_err(|e| anyhow!("{name}: gyroscope: {e}"))?;

    let mut out = String::new();
    outln!(
        out,
        "rig-free fit of {name}: {} static poses ({} orientations), {} moves between them ({} turns of 10° or more)",
        stats.len(),
        accel_fit.orientations,
        gyro_fit.rotations,
        gyro_fit.turns
    );
    outln!(
        out,
        "accelerometer (unknown orientations, |(I+Σ)⁻¹(f̂ − b)| = g):"
    );
    let accel_report = FitReport {
        scale_misalignment: &accel_fit.scale_misalignment,
        sigma_scale_misalignment: accel_fit.sigma_scale_misalignment.as_ref(),
        bias: &accel_fit.bias,
        sigma_bias: accel_fit.sigma_bias.as_ref(),
        segments: accel_fit.segments,
        dof: accel_fit.dof,
        residual_rms: accel_fit.residual_rms,
        residual_max: accel_fit.residual_max,
        condition: accel_fit.condition,
    };
    accel_report.print(
        &mut out,
        "I+Σ (upper triangular by convention)",
        "m/s²",
        "9 poses for 9 unknowns leave no degree of freedom",
    );
    outln!(
        out,
        "gyroscope (integrated between poses, gravity direction matched):"
    );
    let gyro_report = gyro_report(&gyro_fit);
    gyro_report.print(
        &mut out,
        "I+Σ (in the accelerometer's corrected axes)",
        "rad/s",
        "too few moves for the 9 unknowns",
    );
    print_gyro_extras(&mut out, &gyro_fit);

    let mut accel_table = method_table(
        "rig-free: multi-position, unknown orientations, |(I+Σ)⁻¹(f̂ − b)| = g",
        Some("(I+Σ) upper triangular: corrected z = the z sensing axis"),
    );
    accel_table.insert("records".into(), file_list(&paths));
    accel_table.insert("gravity".into(), toml::Value::Float(args.gravity));
    accel_report.insert_statistics(&mut accel_table);
    let mut gyro_table = method_table(
        "rig-free: gyro integrated (RK4, quaternions) between static poses, predicted gravity direction matched to the measured (Tedaldi, Pretto, Menegatti 2014); bias from the poses",
        Some("(I+Σ) maps the accelerometer's corrected axes to the gyro's sensing axes"),
    );
    gyro_table.insert("records".into(), file_list(&paths));
    gyro_table.insert(
        "moves".into(),
        toml::Value::Integer(gyro_fit.rotations as i64),
    );
    gyro_table.insert(
        "bias_degrees_of_freedom".into(),
        toml::Value::Integer(gyro_fit.bias_dof as i64),
    );
    gyro_report.insert_statistics(&mut gyro_table);
    let header = format!(
        "Both triads fitted by `triad calib fit imu` from {} hand-turned poses of {name}\n\
         (no rig): accelerometer residual RMS {:.3e} m/s², gyroscope direction residual RMS {:.3e} rad.",
        stats.len(),
        accel_fit.residual_rms,
        gyro_fit.residual_rms
    );
    let accel_triad = TriadCalibration {
        scale_misalignment: accel_fit.scale_misalignment,
        bias: accel_fit.bias,
        temperature: None,
    };
    let base = base.with_fitted(Triad::Accel, accel_triad, accel_table);
    write_calibration(
        &args.output,
        base,
        Triad::Gyro,
        gyro_report.triad(),
        &header,
        gyro_table,
        &out,
    )
}

/// The common report of the gyro's fit. Its σ's have the smallest of the
/// entries' degrees of freedom (the gyro's own moves and the accelerometer
/// fit's, combined); the bias's are printed apart.
fn gyro_report(fit: &RigFreeGyroFit) -> FitReport<'_> {
    FitReport {
        scale_misalignment: &fit.scale_misalignment,
        sigma_scale_misalignment: fit.sigma_scale_misalignment.as_ref(),
        bias: &fit.bias,
        sigma_bias: fit.sigma_bias.as_ref(),
        segments: fit.segments,
        dof: fit.dof,
        residual_rms: fit.residual_rms,
        residual_max: fit.residual_max,
        condition: fit.condition,
    }
}

/// What only the rig-free fit has: how the bias σ's were found, the turns'
/// spread and the record's fastest turn.
fn print_gyro_extras(out: &mut String, fit: &RigFreeGyroFit) {
    outln!(
        out,
        "  (bias σ's: the scatter of the {} poses' means, {} degrees of freedom, so drift between poses is in them; \
         the Earth's rate is not removed from the bias)",
        fit.segments,
        fit.bias_dof
    );
    outln!(
        out,
        "  turn axes' spread: eigenvalues {:.3} and {:.3} of their scatter (0: all in a plane or about one axis)",
        fit.axis_spread[0],
        fit.axis_spread[1]
    );
    outln!(
        out,
        "  fastest turn: {:.2}° per sample, peak rate {:.1} °/s; residual of the gravity direction RMS {:.3e} rad",
        fit.max_rotation_per_sample_deg,
        fit.peak_rate.to_degrees(),
        fit.residual_rms
    );
}
