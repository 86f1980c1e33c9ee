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
use triad_lab::calib_fit::accel_fit::AccelFit;
use triad_lab::calib_fit::rig_free::{self, RigFreeGyroFit};

use super::g_sensitivity_report;
use triad_lab::calib_fit::static_segments::Segment;
use triad_lab::calib_fit::{accel_fit, FitError};

use super::fit::{file_list, inputs, write_calibration, Output};
use super::fit_csv::{self, Record};
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
    let accel = fit_csv::read(&args.positions, fit_csv::ACCEL)?;
    let gyro = fit_csv::read(&args.positions, fit_csv::GYRO)?;
    let full_scale = deg_to_rad(args.output.ranges.gyro_range_dps);
    let fit = fit_record(&accel, &gyro, args.gravity, args.min_static, full_scale)?;
    let base = base
        .with_fitted(Triad::Accel, fit.accel, fit.accel_table)
        .with_g_sensitivity(fit.g_sensitivity);
    write_calibration(
        &args.output,
        base,
        Triad::Gyro,
        fit.gyro,
        &fit.header,
        fit.gyro_table,
        &fit.report,
    )
}

/// Both triads fitted from one record, with what the file and the report say.
#[derive(Debug)]
pub struct ImuFit {
    /// The accelerometer's (I+Σ) (upper triangular) and b.
    pub accel: TriadCalibration,
    /// The gyroscope's (I+Σ) (in the accelerometer's corrected axes) and b.
    pub gyro: TriadCalibration,
    /// The gyroscope's g-sensitivity G where the poses show one.
    pub g_sensitivity: Option<[[f64; 3]; 3]>,
    /// The accelerometer fit's statistics, `[fit.accel]`.
    pub accel_table: toml::Table,
    /// The gyroscope fit's statistics, `[fit.gyro]`.
    pub gyro_table: toml::Table,
    /// The file's header comment.
    pub header: String,
    /// The report printed for the user.
    pub report: String,
    /// The static poses found (sample ranges of the record).
    pub poses: Vec<Segment>,
    /// The accelerometer fit.
    pub accel_fit: AccelFit,
    /// The gyroscope fit.
    pub gyro_fit: RigFreeGyroFit,
}

/// Fits both triads to `accel` and `gyro`, the two triads of one record
/// (same times), whose static poses (at least `min_static` s) are found
/// from the accelerometer; `gravity` is local gravity, `full_scale` the
/// gyro's range (rad/s). A refusal names the record and what to do.
pub fn fit_record(
    accel: &Record,
    gyro: &Record,
    gravity: f64,
    min_static: f64,
    full_scale: f64,
) -> anyhow::Result<ImuFit> {
    let name = crate::input::name(&accel.path);
    let paths = [accel.path.clone()];
    // The poses: the accelerometer's static stretches.
    let d = detector(accel.rate_hz()?, min_static);
    let mut buffer = vec![Segment { start: 0, end: 0 }; accel.samples.len() / d.block + 1];
    let n = d
        .detect(&accel.samples, &mut buffer)
        .map_err(|e| anyhow!("{name}: {e}"))?;
    let poses = &buffer[..n];
    let stats: Vec<_> = poses
        .iter()
        .map(|p| stat(accel, 0, p.start..p.end))
        .collect();
    let means: Vec<[f64; 3]> = stats.iter().map(|s| s.mean).collect();
    let accel_fit = accel_fit::fit(&means, gravity).map_err(|e| match e {
        FitError::TooFewOrientations { .. } | FitError::OrientationsInOnePlane { .. } => {
            anyhow!("{name}: accelerometer: {e}; turn the board to more orientations")
        }
        _ => anyhow!("{name}: accelerometer, {} static poses: {e}", means.len()),
    })?;
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
    g_sensitivity_report::print(
        &mut out,
        &gyro_fit.g_sensitivity,
        &gyro_fit.pose_check,
        gyro_fit.segments,
    );
    outln!(
        out,
        "  frame: both (I+Σ) map the accelerometer's corrected axes (corrected z = the accelerometer's z \
         sensing axis, x in its xz plane) to the sensing axes; a truth given in body axes B compares \
         after rotating by R (the rotation of B's accelerometer to upper-triangular form): \
         `accel_frame::in_accel_frame`"
    );

    let mut accel_table = method_table(
        "rig-free: multi-position, unknown orientations, |(I+Σ)⁻¹(f̂ − b)| = g",
        Some("(I+Σ) upper triangular: corrected z = the z sensing axis"),
    );
    accel_table.insert("records".into(), file_list(&paths));
    accel_table.insert("gravity".into(), toml::Value::Float(gravity));
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
    g_sensitivity_report::insert(
        &mut gyro_table,
        &gyro_fit.g_sensitivity,
        &gyro_fit.pose_check,
    );
    let header = format!(
        "Both triads fitted by `triad calib fit imu` from {} hand-turned poses of {name}\n\
         (no rig): accelerometer residual RMS {:.3e} m/s², gyroscope direction residual RMS {:.3e} rad.",
        stats.len(),
        accel_fit.residual_rms,
        gyro_fit.residual_rms
    );
    Ok(ImuFit {
        accel: TriadCalibration {
            scale_misalignment: accel_fit.scale_misalignment,
            bias: accel_fit.bias,
            temperature: None,
        },
        gyro: gyro_report.triad(),
        g_sensitivity: gyro_fit.g_sensitivity.applied().map(|g| g.g),
        accel_table,
        gyro_table,
        header,
        report: out,
        poses: poses.to_vec(),
        accel_fit,
        gyro_fit,
    })
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
    let model = if fit.g_sensitivity.applied().is_some() {
        "about the fit of bias and g-sensitivity to them"
    } else {
        "about their mean"
    };
    outln!(
        out,
        "  (bias σ's: the scatter of the {} poses' means {model}, {} degrees of freedom, so drift between poses is in them; \
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
