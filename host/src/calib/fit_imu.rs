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
use triad_lab::calib_fit::fits::accel_fit::AccelFitError;
use triad_lab::calib_fit::fits::imu::{
    self, ImuFitError, ImuOptions, ImuRecord, LeftOutMove, PoseSource,
};
use triad_lab::calib_fit::fits::move_selection::LeftOut;
use triad_lab::calib_fit::fits::rig_free::RigFreeError;
use triad_lab::calib_fit::fits::rig_free::{RigFreeGyroFit, MAX_RANGE_FRACTION};
use triad_lab::calib_fit::fits::turn_refusals::{TooFastForRate, TooFewRotations};
use triad_lab::calib_fit::poses;
use triad_lab::calib_fit::static_segments::Segment;

use super::g_sensitivity_report;

use super::fit::{file_list, inputs, write_calibration, Output};
use super::fit_csv::{self, Reading, Record};
use super::report::{method_table, FitReport, FRAME};
use super::segments::{self, check_pose_options};
use crate::plumbing::stdio::outln;

/// Arguments of `triad calib fit imu`.
#[derive(clap::Args)]
pub struct ImuArgs {
    /// One CSV record (`t,ax,ay,az,gx,gy,gz,...`, SI units unless
    /// --accel-unit/--gyro-unit say otherwise) of the IMU turned by hand
    /// between at least 9 static poses in different orientations, turning
    /// about several axes.
    #[arg(long)]
    positions: PathBuf,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Shortest static pose detected, seconds.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_static: f64,
    /// The static poses as FROM-TO seconds, comma-separated, instead of
    /// detecting them.
    #[arg(long)]
    segments: Option<String>,
    /// Poses to leave out, by their number in the report (e.g. 3,7): the
    /// accelerometer fit and the bias do without them, and the gyro
    /// integrates across them.
    #[arg(long, value_delimiter = ',')]
    exclude_poses: Vec<usize>,
    /// The poses are the faces of a cube (one sensor axis vertical in each,
    /// a tumble): the accelerometer's full (I+Σ) from the known face
    /// directions (as `fit accel --axis-aligned`), the gyro's from the turns
    /// between faces, both in the faces' frame.
    #[arg(long)]
    axis_aligned: bool,
    #[command(flatten)]
    reading: Reading,
    #[command(flatten)]
    output: Output,
}

/// How `fit imu` finds and uses the poses.
#[derive(Clone, Debug)]
pub struct Options {
    /// Local gravity, m/s².
    pub gravity: f64,
    /// Shortest static pose detected, s.
    pub min_static: f64,
    /// The gyro's full scale, rad/s.
    pub full_scale: f64,
    /// `--segments`: the poses as FROM-TO seconds.
    pub segments: Option<String>,
    /// `--exclude-poses`: numbers (1-based) of poses to leave out.
    pub exclude: Vec<usize>,
    /// `--axis-aligned`: the poses are a cube's faces.
    pub axis_aligned: bool,
}

/// Runs `triad calib fit imu`.
pub fn run(args: ImuArgs) -> anyhow::Result<ExitCode> {
    check_pose_options(args.gravity, args.min_static)?;
    let paths = [args.positions.clone()];
    let base = args.output.prepare(&inputs("--positions", &paths))?;
    let ranges = args.output.ranges;
    let text = fit_csv::read_content(&args.positions)?;
    let (accel, time) = args
        .reading
        .parse(&text, &args.positions, fit_csv::ACCEL, &ranges)?;
    let (gyro, _) = args
        .reading
        .parse(&text, &args.positions, fit_csv::GYRO, &ranges)?;
    let options = Options {
        gravity: args.gravity,
        min_static: args.min_static,
        full_scale: deg_to_rad(ranges.gyro_range_dps),
        segments: args.segments.clone(),
        exclude: args.exclude_poses.clone(),
        axis_aligned: args.axis_aligned,
    };
    let mut fit = fit_record_with(&accel, &gyro, &options)?;
    if let Some(note) = fit_csv::time_note(
        &crate::plumbing::input::name(&args.positions),
        &time,
        &accel,
    ) {
        fit.report = format!("{note}\n{}", fit.report);
    }
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
    /// The lab's fit: the poses used, both fits, what was left out.
    pub fit: imu::ImuFit,
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
    let options = Options {
        gravity,
        min_static,
        full_scale,
        segments: None,
        exclude: Vec::new(),
        axis_aligned: false,
    };
    fit_record_with(accel, gyro, &options)
}

/// The times of samples `s` of `record`, for messages: "t = A..B s".
fn span(record: &Record, s: &Segment) -> String {
    format!(
        "t = {:.2}..{:.2} s",
        record.t[s.start],
        record.t[s.end.max(s.start + 1) - 1]
    )
}

/// [`fit_record`] with the poses given or left out as `options` say.
pub fn fit_record_with(accel: &Record, gyro: &Record, options: &Options) -> anyhow::Result<ImuFit> {
    let name = crate::plumbing::input::name(&accel.path);
    let paths = [accel.path.clone()];
    let poses = match &options.segments {
        Some(text) => PoseSource::Given(
            segments::given(accel, text)?
                .iter()
                .map(|s| {
                    let start = accel.t.partition_point(|&t| t < s.from);
                    Segment {
                        start,
                        end: start + s.count,
                    }
                })
                .collect(),
        ),
        None => PoseSource::Detect(poses::detector(accel.rate_hz()?, options.min_static)),
    };
    let parts = gyro.parts();
    let record = ImuRecord {
        t: &gyro.t,
        accel: &accel.samples,
        gyro: &gyro.samples,
        parts: &parts,
    };
    let lab_options = ImuOptions {
        gravity: options.gravity,
        full_scale: options.full_scale,
        poses,
        exclude: options.exclude.clone(),
        axis_aligned: options.axis_aligned,
    };
    let fit =
        imu::fit(&record, &lab_options).map_err(|e| refusal(&name, gyro, options.full_scale, e))?;
    let (accel_fit, gyro_fit) = (&fit.accel, &fit.gyro);

    let mut out = String::new();
    outln!(
        out,
        "rig-free fit of {name}: {} static poses ({} orientations), {} moves between them ({} turns of 10° or more)",
        fit.poses.len(),
        accel_fit.orientations,
        gyro_fit.rotations,
        gyro_fit.turns
    );
    outln!(
        out,
        "  pose  from..to (s)         samples          |f̂| (m/s²)"
    );
    for p in &fit.poses {
        let m = p.accel.mean;
        outln!(
            out,
            "  {:>4}  {:>8.2}..{:<8.2}  {:>7}..{:<7}  {:.5}",
            p.number,
            accel.t[p.samples.start],
            accel.t[p.samples.end - 1],
            p.samples.start + 1,
            p.samples.end,
            (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt()
        );
    }
    for (n, s) in &fit.excluded {
        outln!(
            out,
            "  pose {n} ({}) left out by --exclude-poses",
            span(accel, s)
        );
    }
    for line in left_out_lines(gyro, options.full_scale, &fit.left_out) {
        outln!(out, "  {line}");
    }
    if let (Some(&first), n) = (fit.outside.first(), fit.outside.len()) {
        outln!(
            out,
            "  {n} sample(s) beyond {:.0} % of the gyro's full scale lie outside the poses and moves the fit uses \
             (the first at t = {:.2} s, sample {}): ignored",
            100.0 * MAX_RANGE_FRACTION,
            gyro.t[first],
            first + 1
        );
    }
    for line in segments::dropped_lines(&fit.dropped, accel, options.min_static) {
        outln!(out, "  {line}");
    }
    let (method, matrix_title, frame) = if options.axis_aligned {
        (
            "accelerometer (a cube's faces: f̂ = (I+Σ)·(±g e_k) + b, full I+Σ):",
            "I+Σ (full, in the faces' frame)",
            "the faces' frame: each face's vertical is a sensor axis (taken as exact: the fixture's \
             flatness is not in the σ's)",
        )
    } else {
        (
            "accelerometer (unknown orientations, |(I+Σ)⁻¹(f̂ − b)| = g):",
            "I+Σ (upper triangular by convention)",
            FRAME,
        )
    };
    outln!(out, "{method}");
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
        matrix_title,
        "m/s²",
        "9 poses for 9 unknowns leave no degree of freedom",
    );
    outln!(
        out,
        "gyroscope (integrated between poses, gravity direction matched):"
    );
    let gyro_report = gyro_report(gyro_fit);
    gyro_report.print(
        &mut out,
        "I+Σ (in the accelerometer's corrected axes)",
        "rad/s",
        "too few moves for the 9 unknowns",
    );
    print_gyro_extras(&mut out, gyro_fit);
    g_sensitivity_report::print(
        &mut out,
        &gyro_fit.g_sensitivity,
        &gyro_fit.pose_check,
        gyro_fit.segments,
    );
    outln!(
        out,
        "  frame: both (I+Σ) map the accelerometer's corrected axes to the sensing axes; {frame} (of the \
         accelerometer); a truth given in body axes B compares after rotating by R (the rotation of B's \
         accelerometer to upper-triangular form): `accel_frame::in_accel_frame`"
    );

    let mut accel_table = if options.axis_aligned {
        method_table(
            "rig-free on a cube's faces: f̂ = (I+Σ)·(±g e_k) + b, linear least squares",
            Some("(I+Σ) full: the faces' frame"),
        )
    } else {
        method_table(
            "rig-free: multi-position, unknown orientations, |(I+Σ)⁻¹(f̂ − b)| = g",
            Some(FRAME),
        )
    };
    accel_table.insert("records".into(), file_list(&paths));
    accel_table.insert("gravity".into(), toml::Value::Float(options.gravity));
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
        fit.poses.len(),
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
        fit,
    })
}

/// One line per move left out: the poses it joins, when, and why.
fn left_out_lines(gyro: &Record, full_scale: f64, left_out: &[LeftOutMove]) -> Vec<String> {
    left_out
        .iter()
        .map(|m| {
            let label = format!(
                "move from pose {} to pose {} ({})",
                m.poses[0],
                m.poses[1],
                span(gyro, &m.samples)
            );
            match m.why {
                LeftOut::CrossesGap => format!("{label} left out: it crosses a gap in the time stamps"),
                LeftOut::Held { at, samples: n } => format!(
                    "{label} left out: the gyro repeats one value for {n} samples from t = {:.2} s (sample {}): \
                     held samples (a logger repeating over lost frames?) lose the turn",
                    gyro.t[at],
                    at + 1
                ),
                LeftOut::NearRange { sample, rate: peak } => format!(
                    "{label} left out: the gyro reads {:.1} °/s at t = {:.2} s (sample {}), beyond {:.0} % of its \
                     full scale {:.0} °/s, so the turn may have clipped",
                    peak.to_degrees(),
                    gyro.t[sample],
                    sample + 1,
                    100.0 * MAX_RANGE_FRACTION,
                    full_scale.to_degrees()
                ),
            }
        })
        .collect()
}

/// The lab's refusal as the user reads it: the record's name, the triad,
/// and the option that helps (with the times of a pose or sample it names).
fn refusal(name: &str, gyro: &Record, full_scale: f64, e: ImuFitError) -> anyhow::Error {
    let (error, pose, left_out) = match e {
        ImuFitError::Detection(e) => return anyhow!("{name}: {e}"),
        ImuFitError::NoSuchPose { pose, poses } => {
            return anyhow!(
                "{name}: --exclude-poses {pose}: the record has {poses} pose(s), numbered from 1 in the report"
            )
        }
        ImuFitError::AccelCube { error, .. } => {
            return anyhow!("{name}: accelerometer (--axis-aligned): {error}")
        }
        ImuFitError::Accel {
            error:
                e @ (AccelFitError::TooFewOrientations { .. }
                | AccelFitError::OrientationsInOnePlane { .. }),
            ..
        } => {
            return anyhow!(
                "{name}: accelerometer: {e}; turn the board to more orientations \
                 (or give --axis-aligned for a cube tumble)"
            )
        }
        ImuFitError::Accel { error, poses, .. } => {
            return anyhow!("{name}: accelerometer, {poses} static poses: {error}")
        }
        ImuFitError::Gyro(refusal) => (
            refusal.error,
            refusal.pose,
            left_out_lines(gyro, full_scale, &refusal.left_out),
        ),
    };
    let refused = match (error, pose) {
        (e @ RigFreeError::PoseNotStatic(_), Some(p)) => {
            let text = e.to_string();
            let rest = text.split_once(": ").map_or(text.as_str(), |(_, r)| r);
            anyhow!(
                "{name}: gyroscope: pose {} ({}): {rest}; or leave it out with --exclude-poses {}",
                p.number,
                span(gyro, &p.samples),
                p.number
            )
        }
        // This refusal lists what was left out itself.
        (e @ RigFreeError::TooFewRotations(TooFewRotations { .. }), _) if !left_out.is_empty() => {
            return anyhow!(
                "{name}: gyroscope: {e} ({} move(s) were left out: {})",
                left_out.len(),
                left_out.join("; ")
            )
        }
        (e @ RigFreeError::TooFastForRate(TooFastForRate { sample, .. }), _) => {
            anyhow!("{name}: gyroscope: {e} (t = {:.2} s)", gyro.t[sample])
        }
        (e, _) => anyhow!("{name}: gyroscope: {e}"),
    };
    // What was left out is said even when the gyro fit then refuses.
    for line in &left_out {
        crate::plumbing::stdio::note!("{name}: {line}");
    }
    refused
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
