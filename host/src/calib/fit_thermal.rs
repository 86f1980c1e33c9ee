//! `triad calib fit thermal`: the temperature terms of both triads from
//! records over a temperature range (soaks or ramps), written into the
//! calibration file's `[accel.temperature]` and `[gyro.temperature]`, so
//! `triad correct` and the firmware (through the blob) apply them. The fit
//! is the lab's ([`thermal`]); this module reads the records, renders the
//! report and writes the file.
//!
//! - The static segments of every record (the accelerometer's), cut where
//!   their temperature has moved by [`thermal::CHUNK_C`], each with its mean
//!   temperature: a soak's pose is one segment, a ramp's rest many.
//! - Accelerometer: (I+Σ)₀ + ΔT·D and b cubic in ΔT in one magnitude fit
//!   over every segment in unknown orientations; upper triangular by
//!   convention, as `calib fit accel`.
//! - Gyroscope: its bias against temperature from the segments' means
//!   (the Earth's rate is not removed), then its (I+Σ)₀ + ΔT·D from the
//!   turns between consecutive poses of each record (the rig-free method at
//!   each move's temperature), when ≥ 5 turns lie both colder and warmer
//!   than the reference; else its (I+Σ) is `--base`'s (identity without)
//!   and D zero, said so.
//! - Which terms are fitted is decided by the temperatures alone
//!   ([`thermal_coverage`]): swing ≥ 10 °C per order and order + 1 distinct
//!   levels for the bias; for the accelerometer's D ≥ 9 orientations both
//!   colder and warmer than the reference (else refused: `--gyro-only`
//!   fits the gyro's bias alone). Terms not fitted are zero and listed in
//!   the report and the file (`not_fitted`).
//! - The range covered goes in the file (`temperature_range_c` of
//!   `[fit.accel]`/`[fit.gyro]`); outside it the terms extrapolate (the
//!   model clamps only to −40..85 °C), and `triad correct` counts the
//!   samples outside the range and says so.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use triad::model::{TemperatureTerms, Triad, TriadCalibration};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_lab::calib_fit::fits::bias_polynomial::BiasPolynomial;
use triad_lab::calib_fit::fits::thermal::{
    self, ScaleNotFitted, ThermalFitError, ThermalOptions, ThermalRecord,
};
use triad_lab::calib_fit::fits::thermal_accel::ThermalAccelFit;
use triad_lab::calib_fit::fits::thermal_coverage::{self, Coverage, LEVEL_C, MIN_SWING_C};
use triad_lab::calib_fit::fits::thermal_gyro::ThermalGyroFit;
use triad_lab::calib_fit::poses::detector;

use super::fit::{file_list, inputs, write_calibration, Output};
use super::fit_csv;
use super::report::{matrix_rows, method_table, print_vector};
use super::segments::check_pose_options;
use crate::calib::file::vector;
use crate::plumbing::stdio::outln;

/// Arguments of `triad calib fit thermal`.
#[derive(clap::Args)]
pub struct ThermalArgs {
    /// CSV records (`t,ax,ay,az,gx,gy,gz,temp`, SI units and °C) over a
    /// temperature range: poses in ≥ 9 orientations both colder and warmer
    /// than the middle of the range (e.g. the hand-soak script), plus any
    /// static records (ramps) for the biases.
    #[arg(required = true)]
    records: Vec<PathBuf>,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Shortest static pose detected, seconds.
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    min_static: f64,
    /// Fit only the gyroscope's bias against temperature (e.g. from a static
    /// ramp, which cannot separate the accelerometer's bias from its (I+Σ)):
    /// the accelerometer is `--base`'s (identity without).
    #[arg(long)]
    gyro_only: bool,
    #[command(flatten)]
    output: Output,
}

/// One record: accelerometer, gyroscope, temperature.
struct Channels {
    accel: fit_csv::Record,
    gyro: fit_csv::Record,
    temp: Vec<f64>,
}

fn read(path: &std::path::Path) -> anyhow::Result<Channels> {
    let text = fit_csv::read_content(path)?;
    let temp = fit_csv::parse_temperature(
        &text,
        path,
        "a thermal fit needs the chip's temperature (°C) with every sample \
         (`triad sim` and `triad decode` write it)",
    )?;
    Ok(Channels {
        accel: fit_csv::parse(&text, path, fit_csv::ACCEL)?,
        gyro: fit_csv::parse(&text, path, fit_csv::GYRO)?,
        temp: temp.samples.iter().map(|s| s[0]).collect(),
    })
}

/// The terms not fitted and why, for the report and `not_fitted`.
fn not_fitted(coverage: &Coverage, order: usize, scale: Option<&str>) -> Vec<String> {
    let mut out: Vec<String> = (order + 1..=thermal_coverage::MAX_BIAS_ORDER)
        .map(|k| {
            let why = if coverage.levels <= k {
                format!(
                    "{} distinct temperature level(s) ({LEVEL_C} °C apart), order {k} needs {}",
                    coverage.levels,
                    k + 1
                )
            } else {
                format!(
                    "swing {:.1} °C, order {k} needs ≥ {} °C",
                    coverage.swing_c(),
                    MIN_SWING_C * k as f64
                )
            };
            format!("bias_coefficients c{k}: {why}")
        })
        .collect();
    if let Some(why) = scale {
        out.push(format!("scale_misalignment_per_c: {why}"));
    }
    out
}

/// Runs `triad calib fit thermal`.
pub fn run(args: ThermalArgs) -> anyhow::Result<ExitCode> {
    check_pose_options(args.gravity, args.min_static)?;
    let base = args.output.prepare(&inputs("record", &args.records))?;
    let names = super::fit::names(&args.records);
    let channels: Vec<Channels> = args
        .records
        .iter()
        .map(|p| read(p))
        .collect::<anyhow::Result<_>>()?;
    let records: Vec<ThermalRecord> = channels
        .iter()
        .map(|c| {
            Ok(ThermalRecord {
                t: &c.gyro.t,
                accel: &c.accel.samples,
                gyro: &c.gyro.samples,
                temperature: &c.temp,
                detector: detector(c.accel.rate_hz()?, args.min_static),
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let options = ThermalOptions {
        gravity: args.gravity,
        full_scale: deg_to_rad(args.output.ranges.gyro_range_dps),
        gyro_only: args.gyro_only,
    };
    let fit = thermal::fit(&records, &options).map_err(|e| match e {
        ThermalFitError::Detection { record, error } => anyhow!(
            "{}: {error}",
            crate::plumbing::input::name(&args.records[record])
        ),
        ThermalFitError::Coverage(e) => anyhow!("{names}: {e}"),
        e => anyhow!("{names}: {e}"),
    })?;
    let coverage = fit.coverage;
    let order = coverage.bias_order();
    let gyro = &fit.gyro_bias;
    let accel = fit
        .accel
        .as_ref()
        .map(|a| (a, not_fitted(&coverage, a.terms.bias_order, None)));
    let gyro_scale = fit.gyro_scale.as_ref().ok();
    let scale_why = match fit.gyro_scale {
        Ok(_) => None,
        Err(ScaleNotFitted::GyroOnly) => Some(
            "needs the accelerometer's fit (--gyro-only): (I+Σ) from --base, D left zero"
                .to_string(),
        ),
        Err(ScaleNotFitted::TooFewTurns(e)) => Some(format!("{e}; (I+Σ) from --base, D left zero")),
    };
    let gyro_not = not_fitted(&coverage, order, scale_why.as_deref());
    let report = report(
        &names,
        &coverage,
        accel.as_ref(),
        gyro,
        gyro_scale,
        &gyro_not,
    );

    let range = toml::Value::Array(vec![
        toml::Value::Float(coverage.min_c),
        toml::Value::Float(coverage.max_c),
    ]);
    let common = |table: &mut toml::Table, not: &[String]| {
        table.insert("records".into(), file_list(&args.records));
        table.insert(
            "reference_c".into(),
            toml::Value::Float(coverage.reference_c),
        );
        table.insert("temperature_range_c".into(), range.clone());
        table.insert(
            "temperature_levels".into(),
            toml::Value::Integer(coverage.levels as i64),
        );
        table.insert("bias_order".into(), toml::Value::Integer(order as i64));
        table.insert(
            "not_fitted".into(),
            toml::Value::Array(not.iter().map(|s| toml::Value::String(s.clone())).collect()),
        );
        table.insert(
            "outside_the_range".into(),
            toml::Value::String(
                "the terms extrapolate (cubic bias, linear (I+Σ)); the model clamps only to −40..85 °C; \
                 `triad correct` counts the samples outside"
                    .into(),
            ),
        );
    };
    let terms_of = |c: [[f64; 3]; 3], d: [[f64; 3]; 3]| TemperatureTerms {
        reference_c: coverage.reference_c,
        bias_coefficients: c,
        scale_misalignment_per_c: d,
    };
    let mut base = base;
    if let Some((fit, not)) = &accel {
        let fit = *fit;
        let mut table = method_table(
            "thermal: |((I+Σ)₀ + ΔT·D)⁻¹(f̂ − b(ΔT))| = g over static segments in unknown orientations at their own temperatures, b cubic in ΔT",
            Some("(I+Σ) and D upper triangular: corrected z = the z sensing axis at every temperature"),
        );
        common(&mut table, not);
        table.insert("gravity".into(), toml::Value::Float(args.gravity));
        insert_accel_statistics(&mut table, fit);
        let triad = TriadCalibration {
            scale_misalignment: fit.scale_misalignment,
            bias: fit.bias,
            temperature: Some(terms_of(
                fit.bias_coefficients,
                fit.scale_misalignment_per_c,
            )),
        };
        base = base.with_fitted(Triad::Accel, triad, table);
    }
    let mut gyro_table = match &gyro_scale {
        Some(_) => method_table(
            "thermal: bias polynomial in ΔT from the static segments' means (weighted least squares; the Earth's rate not removed); (I+Σ)₀ + ΔT·D by integrating the gyro between consecutive poses and matching the gravity direction (rig-free, Tedaldi, Pretto, Menegatti 2014), each move at its temperature",
            Some("(I+Σ) maps the accelerometer's corrected axes (at each temperature) to the gyro's sensing axes"),
        ),
        None => method_table(
            "thermal: bias polynomial in ΔT from the static segments' means (weighted least squares; the Earth's rate not removed)",
            Some("(I+Σ) from --base (identity without), not fitted here"),
        ),
    };
    common(&mut gyro_table, &gyro_not);
    insert_gyro_statistics(&mut gyro_table, gyro, gyro_scale);
    let (gyro_matrix, gyro_d) = match &gyro_scale {
        Some(fit) => (fit.scale_misalignment, fit.scale_misalignment_per_c),
        None => (base.calibration.gyro.scale_misalignment, [[0.0; 3]; 3]),
    };
    let gyro_triad = TriadCalibration {
        scale_misalignment: gyro_matrix,
        bias: gyro.bias,
        temperature: Some(terms_of(gyro.coefficients, gyro_d)),
    };
    let header = format!(
        "Temperature terms fitted by `triad calib fit thermal` from {names}{}:\n\
         {} static segments over {:.1}..{:.1} °C (reference {:.1} °C); outside that range the terms extrapolate.",
        if accel.is_none() { " (gyroscope only)" } else { "" },
        fit.segments,
        coverage.min_c,
        coverage.max_c,
        coverage.reference_c
    );
    write_calibration(
        &args.output,
        base,
        Triad::Gyro,
        gyro_triad,
        &header,
        gyro_table,
        &report,
    )
}

fn matrix_value(m: &[[f64; 3]; 3]) -> toml::Value {
    toml::Value::Array(m.iter().map(vector).collect())
}

fn insert_accel_statistics(table: &mut toml::Table, fit: &ThermalAccelFit) {
    let entries = [
        ("segments", toml::Value::Integer(fit.segments as i64)),
        ("parameters", toml::Value::Integer(fit.fitted as i64)),
        ("degrees_of_freedom", toml::Value::Integer(fit.dof as i64)),
        ("residual_rms", toml::Value::Float(fit.residual_rms)),
        ("residual_max", toml::Value::Float(fit.residual_max)),
        ("variance_factor", toml::Value::Float(fit.variance_factor)),
        ("condition_number", toml::Value::Float(fit.condition)),
        (
            "sigma_scale_misalignment",
            matrix_value(&fit.sigma_scale_misalignment),
        ),
        ("sigma_bias", vector(&fit.sigma_bias)),
        (
            "sigma_bias_coefficients",
            matrix_value(&fit.sigma_bias_coefficients),
        ),
        (
            "sigma_scale_misalignment_per_c",
            matrix_value(&fit.sigma_scale_misalignment_per_c),
        ),
    ];
    for (k, v) in entries {
        table.insert(k.into(), v);
    }
}

/// The gyro's statistics: `degrees_of_freedom` is the smallest of every σ
/// in the table (the bias's and, when fitted, each (I+Σ) entry's effective
/// one, also given per entry).
fn insert_gyro_statistics(
    table: &mut toml::Table,
    fit: &BiasPolynomial,
    scale: Option<&ThermalGyroFit>,
) {
    let integer = |n: usize| toml::Value::Integer(n as i64);
    let smallest = scale.map_or(fit.dof, |s| s.dof.min(fit.dof));
    let mut entries = vec![
        ("segments", integer(fit.dof + fit.order + 1)),
        ("degrees_of_freedom", integer(smallest)),
        ("bias_degrees_of_freedom", integer(fit.dof)),
        ("bias_residual_rms", vector(&fit.residual_rms)),
        ("sigma_bias", vector(&fit.sigma_bias)),
        (
            "sigma_bias_coefficients",
            matrix_value(&fit.sigma_coefficients),
        ),
    ];
    if let Some(s) = scale {
        entries.extend([
            ("moves", integer(s.moves)),
            ("residual_rms", toml::Value::Float(s.residual_rms)),
            ("residual_max", toml::Value::Float(s.residual_max)),
            ("condition_number", toml::Value::Float(s.condition)),
            (
                "sigma_scale_misalignment",
                matrix_value(&s.sigma_scale_misalignment),
            ),
            (
                "sigma_scale_misalignment_per_c",
                matrix_value(&s.sigma_scale_misalignment_per_c),
            ),
            (
                "scale_misalignment_degrees_of_freedom",
                matrix_value(&s.dof_entries[0]),
            ),
            (
                "scale_misalignment_per_c_degrees_of_freedom",
                matrix_value(&s.dof_entries[1]),
            ),
        ]);
    }
    for (k, v) in entries {
        table.insert(k.into(), v);
    }
}

/// The printed report.
fn report(
    names: &str,
    coverage: &Coverage,
    accel: Option<&(&ThermalAccelFit, Vec<String>)>,
    gyro: &BiasPolynomial,
    gyro_scale: Option<&ThermalGyroFit>,
    gyro_not: &[String],
) -> String {
    let mut out = String::new();
    outln!(
        out,
        "thermal fit of {names}: {} static segments over {:.1}..{:.1} °C (swing {:.1} °C, {} levels), reference {:.1} °C",
        gyro.dof + gyro.order + 1,
        coverage.min_c,
        coverage.max_c,
        coverage.swing_c(),
        coverage.levels,
        coverage.reference_c
    );
    let coverage_note = |out: &mut String, dof: usize| {
        outln!(
            out,
            "  (σ's: {dof} degrees of freedom, so ±2σ covers {:.1} % (Student-t); from the scatter of the segments about the fit)",
            100.0 * triad_lab::student_t::coverage(2.0, dof as f64)
        );
    };
    match accel {
        Some((accel, _)) => {
            outln!(
                out,
                "accelerometer (unknown orientations, |(I+Σ)(T)⁻¹(f̂ − b(T))| = g):"
            );
            outln!(
                out,
                "  I+Σ at {:.1} °C (upper triangular by convention):",
                coverage.reference_c
            );
            for line in matrix_rows(
                &accel.scale_misalignment,
                Some(&accel.sigma_scale_misalignment),
            ) {
                outln!(out, "    {line}");
            }
            outln!(out, "  D = d(I+Σ)/dT (1/°C):");
            for line in matrix_rows(
                &accel.scale_misalignment_per_c,
                Some(&accel.sigma_scale_misalignment_per_c),
            ) {
                outln!(out, "    {line}");
            }
            print_bias(
                &mut out,
                "m/s²",
                &accel.bias,
                &accel.sigma_bias,
                accel.terms.bias_order,
                &accel.bias_coefficients,
                &accel.sigma_bias_coefficients,
            );
            coverage_note(&mut out, accel.dof);
            outln!(
                out,
                "  residual RMS {:.3e} m/s², max {:.3e}; condition number {:.1}",
                accel.residual_rms,
                accel.residual_max,
                accel.condition
            );
        }
        None => outln!(
            out,
            "accelerometer: not fitted (--gyro-only): --base's, or the identity"
        ),
    }
    outln!(
        out,
        "gyroscope bias (static segments' means; the Earth's rate not removed):"
    );
    print_bias(
        &mut out,
        "rad/s",
        &gyro.bias,
        &gyro.sigma_bias,
        gyro.order,
        &gyro.coefficients,
        &gyro.sigma_coefficients,
    );
    coverage_note(&mut out, gyro.dof);
    if let Some(g) = gyro_scale {
        outln!(
            out,
            "gyroscope (I+Σ) (integrated over {} moves between poses, gravity direction matched; turns colder/warmer {}/{}):",
            g.moves,
            g.turns[0],
            g.turns[1]
        );
        outln!(
            out,
            "  I+Σ at {:.1} °C (in the accelerometer's corrected axes):",
            coverage.reference_c
        );
        for line in matrix_rows(&g.scale_misalignment, Some(&g.sigma_scale_misalignment)) {
            outln!(out, "    {line}");
        }
        outln!(out, "  D = d(I+Σ)/dT (1/°C):");
        for line in matrix_rows(
            &g.scale_misalignment_per_c,
            Some(&g.sigma_scale_misalignment_per_c),
        ) {
            outln!(out, "    {line}");
        }
        coverage_note(&mut out, g.dof);
        outln!(
            out,
            "  (the smallest effective degrees of freedom of the entries: the moves' own {} and the accelerometer fit's, combined)",
            g.gyro_dof
        );
        outln!(
            out,
            "  residual of the gravity direction RMS {:.3e} rad, max {:.3e}; condition number {:.1}",
            g.residual_rms,
            g.residual_max,
            g.condition
        );
    }
    let accel_not = accel.map(|(_, not)| not.as_slice()).unwrap_or_default();
    for (triad, list) in [("accelerometer", accel_not), ("gyroscope", gyro_not)] {
        for line in list {
            outln!(out, "warning: {triad}: not fitted, left zero: {line}");
        }
    }
    outln!(
        out,
        "outside {:.1}..{:.1} °C the terms extrapolate; `triad correct` counts such samples",
        coverage.min_c,
        coverage.max_c
    );
    out
}

/// b₀ and each fitted coefficient with its σ and t = value/σ.
fn print_bias(
    out: &mut String,
    unit: &str,
    b: &[f64; 3],
    sigma: &[f64; 3],
    order: usize,
    c: &[[f64; 3]; 3],
    sigma_c: &[[f64; 3]; 3],
) {
    print_vector(out, &format!("b at the reference ({unit})"), b, Some(sigma));
    for k in 0..order {
        let v = [0, 1, 2].map(|i| c[i][k]);
        let s = [0, 1, 2].map(|i| sigma_c[i][k]);
        print_vector(
            out,
            &format!("c{} ({unit}/°C^{})", k + 1, k + 1),
            &v,
            Some(&s),
        );
        let weak: Vec<String> = (0..3)
            .filter(|&i| v[i].abs() < 2.0 * s[i])
            .map(|i| ["x", "y", "z"][i].to_string())
            .collect();
        if !weak.is_empty() {
            outln!(
                out,
                "    (c{} of {} within 2σ of zero: consistent with no such term over this range)",
                k + 1,
                weak.join(", ")
            );
        }
    }
}
