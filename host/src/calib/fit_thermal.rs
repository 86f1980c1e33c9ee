//! `triad calib fit thermal`: the temperature terms of both triads from
//! records over a temperature range (soaks or ramps), written into the
//! calibration file's `[accel.temperature]` and `[gyro.temperature]`, so
//! `triad correct` and the firmware (through the blob) apply them.
//!
//! - The static segments of every record (the accelerometer's), cut where
//!   their temperature has moved by [`CHUNK_C`], each with its mean
//!   temperature: a soak's pose is one segment, a ramp's rest many.
//! - Accelerometer: (I+Σ)₀ + ΔT·D and b cubic in ΔT in one magnitude fit
//!   over every segment in unknown orientations ([`thermal_accel`]);
//!   upper triangular by convention, as `calib fit accel`.
//! - Gyroscope: its bias against temperature from the segments' means
//!   ([`bias_polynomial`]; the Earth's rate is not removed), then its
//!   (I+Σ)₀ + ΔT·D from the turns between consecutive poses of each record
//!   ([`thermal_gyro`], the rig-free method at each move's temperature),
//!   when ≥ 5 turns lie both colder and warmer than the reference; else
//!   its (I+Σ) is `--base`'s (identity without) and D zero, said so.
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

use anyhow::{anyhow, bail};
use triad::model::{TemperatureTerms, Triad, TriadCalibration};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_lab::calib_fit::fits::bias_polynomial::{self, BiasPolynomial, StaticMean};
use triad_lab::calib_fit::fits::rig_free::Record;
use triad_lab::calib_fit::fits::thermal_accel::{self, Terms, ThermalAccelFit};
use triad_lab::calib_fit::fits::thermal_coverage::{self, Coverage, LEVEL_C, MIN_SWING_C};
use triad_lab::calib_fit::fits::thermal_gyro::{self, Poses, ThermalGyroFit};
use triad_lab::calib_fit::static_segments::Segment;
use triad_lab::calib_fit::FitError;

use super::fit::{file_list, inputs, write_calibration, Output};
use super::fit_csv;
use super::report::{matrix_rows, method_table, print_vector};
use super::segments::{check_pose_options, detector, stat};
use crate::calib::file::vector;
use crate::plumbing::stdio::outln;

/// A static segment is cut where its temperature has moved by this (°C)
/// from the cut's start: within a cut the terms change by at most
/// 0.5 °C × the coefficient, and its mean temperature is its temperature.
pub const CHUNK_C: f64 = 0.5;

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
    temp: fit_csv::Record,
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
        temp,
    })
}

/// `segment` cut where the temperature has moved by [`CHUNK_C`]; pieces
/// shorter than `min_len` join the previous piece.
fn cut(temp: &[[f64; 3]], segment: Segment, min_len: usize, out: &mut Vec<Segment>) {
    let first = out.len();
    let mut start = segment.start;
    for i in segment.start..segment.end {
        if (temp[i][0] - temp[start][0]).abs() >= CHUNK_C && i - start >= min_len {
            out.push(Segment { start, end: i });
            start = i;
        }
    }
    if segment.end - start >= min_len || out.len() == first {
        out.push(Segment {
            start,
            end: segment.end,
        });
    } else if let Some(last) = out.last_mut() {
        last.end = segment.end;
    }
}

/// Both triads' static means at every segment of every record.
/// A record's static poses (uncut), their accelerometer means and temperatures.
struct RecordPoses {
    segments: Vec<Segment>,
    accel_means: Vec<[f64; 3]>,
    temperatures: Vec<f64>,
}

/// Both triads' static means at every (cut) segment of every record, and
/// each record's whole poses for the gyro's turns.
fn static_means(
    records: &[Channels],
    min_static: f64,
) -> anyhow::Result<(Vec<StaticMean>, Vec<StaticMean>, Vec<RecordPoses>)> {
    let (mut accel, mut gyro, mut poses) = (Vec::new(), Vec::new(), Vec::new());
    for (file, r) in records.iter().enumerate() {
        let name = crate::plumbing::input::name(&r.accel.path);
        let d = detector(r.accel.rate_hz()?, min_static);
        let mut buffer = vec![Segment { start: 0, end: 0 }; r.accel.samples.len() / d.block + 1];
        let n = d
            .detect(&r.accel.samples, &mut buffer)
            .map_err(|e| anyhow!("{name}: {e}"))?;
        let segments = buffer[..n].to_vec();
        poses.push(RecordPoses {
            accel_means: segments
                .iter()
                .map(|p| stat(&r.accel, file, p.start..p.end).mean)
                .collect(),
            temperatures: segments
                .iter()
                .map(|p| stat(&r.temp, file, p.start..p.end).mean[0])
                .collect(),
            segments,
        });
        let mut pieces = Vec::new();
        for s in &buffer[..n] {
            cut(&r.temp.samples, *s, d.block * d.min_blocks, &mut pieces);
        }
        for p in pieces {
            let temperature_c = stat(&r.temp, file, p.start..p.end).mean[0];
            for (out, record) in [(&mut accel, &r.accel), (&mut gyro, &r.gyro)] {
                let s = stat(record, file, p.start..p.end);
                out.push(StaticMean {
                    temperature_c,
                    mean: s.mean,
                    standard_error: s.standard_error,
                });
            }
        }
    }
    Ok((accel, gyro, poses))
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

/// The accelerometer's thermal fit and the terms it leaves out, unless `--gyro-only`.
fn fit_accel(
    args: &ThermalArgs,
    names: &str,
    means: &[StaticMean],
    coverage: &Coverage,
) -> anyhow::Result<Option<(ThermalAccelFit, Vec<String>)>> {
    if args.gyro_only {
        return Ok(None);
    }
    let directions: Vec<[f64; 3]> = means.iter().map(|m| m.mean).collect();
    let temps: Vec<f64> = means.iter().map(|m| m.temperature_c).collect();
    let mut scratch = vec![[0.0; 3]; means.len()];
    let sides = thermal_coverage::orientations_either_side(
        &directions,
        &temps,
        coverage.reference_c,
        &mut scratch,
    );
    thermal_coverage::check_scale_support(sides, coverage)
        .map_err(|e| anyhow!("{names}: accelerometer: {e}"))?;
    let terms = Terms {
        reference_c: coverage.reference_c,
        bias_order: coverage.bias_order(),
        scale: true,
    };
    let mut weights = vec![0.0; means.len()];
    let fit = thermal_accel::fit(means, args.gravity, terms, &mut scratch, &mut weights).map_err(
        |e| {
            anyhow!(
                "{names}: accelerometer, {} static segments: {e}",
                means.len()
            )
        },
    )?;
    Ok(Some((fit, not_fitted(coverage, terms.bias_order, None))))
}

/// Runs `triad calib fit thermal`.
pub fn run(args: ThermalArgs) -> anyhow::Result<ExitCode> {
    check_pose_options(args.gravity, args.min_static)?;
    let base = args.output.prepare(&inputs("record", &args.records))?;
    let names = super::fit::names(&args.records);
    let records: Vec<Channels> = args
        .records
        .iter()
        .map(|p| read(p))
        .collect::<anyhow::Result<_>>()?;
    let (accel_means, gyro_means, poses) = static_means(&records, args.min_static)?;
    let temps: Vec<f64> = accel_means.iter().map(|m| m.temperature_c).collect();
    let coverage = thermal_coverage::coverage(&temps).map_err(|e| anyhow!("{names}: {e}"))?;
    let order = coverage.bias_order();
    let accel = fit_accel(&args, &names, &accel_means, &coverage)?;
    let gyro = bias_polynomial::fit(&gyro_means, coverage.reference_c, order)
        .map_err(|e| anyhow!("{names}: gyroscope bias: {e}"))?;
    let (gyro_scale, scale_why) = match &accel {
        None => (
            None,
            Some(
                "needs the accelerometer's fit (--gyro-only): (I+Σ) from --base, D left zero"
                    .to_string(),
            ),
        ),
        Some((accel_fit, _)) => {
            let sets: Vec<Poses> = records
                .iter()
                .zip(&poses)
                .map(|(r, p)| Poses {
                    record: Record {
                        t: &r.gyro.t,
                        gyro: &r.gyro.samples,
                    },
                    segments: &p.segments,
                    accel_means: &p.accel_means,
                    temperatures: &p.temperatures,
                })
                .collect();
            let full_scale = deg_to_rad(args.output.ranges.gyro_range_dps);
            match thermal_gyro::fit(&sets, accel_fit, &gyro, full_scale) {
                Ok(fit) => (Some(fit), None),
                Err(e @ FitError::TooFewTurnsForScale { .. }) => {
                    (None, Some(format!("{e}; (I+Σ) from --base, D left zero")))
                }
                Err(e) => bail!("{names}: gyroscope (I+Σ) against temperature: {e}"),
            }
        }
    };
    let gyro_not = not_fitted(&coverage, order, scale_why.as_deref());
    let report = report(
        &names,
        &coverage,
        accel.as_ref(),
        &gyro,
        gyro_scale.as_ref(),
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
    insert_gyro_statistics(&mut gyro_table, &gyro, gyro_scale.as_ref());
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
        accel_means.len(),
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
    accel: Option<&(ThermalAccelFit, Vec<String>)>,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A temperature series as the record's `temp` column.
    fn temps(values: &[f64]) -> Vec<[f64; 3]> {
        values.iter().map(|&t| [t; 3]).collect()
    }

    #[test]
    fn a_ramp_is_cut_every_half_degree_and_a_soak_is_not() {
        // 0.1 °C a sample: a cut every 5 samples; the last 2 join the previous.
        let ramp = temps(&(0..22).map(|i| 0.1 * i as f64).collect::<Vec<_>>());
        let mut out = Vec::new();
        cut(&ramp, Segment { start: 0, end: 22 }, 3, &mut out);
        let bounds: Vec<(usize, usize)> = out.iter().map(|s| (s.start, s.end)).collect();
        assert_eq!(bounds, [(0, 5), (5, 10), (10, 15), (15, 22)]);
        let soak = temps(&[25.0; 40]);
        let mut out = Vec::new();
        cut(&soak, Segment { start: 3, end: 40 }, 3, &mut out);
        assert_eq!(out, [Segment { start: 3, end: 40 }]);
        // Shorter than the shortest piece: kept whole (the detector's own minimum).
        let mut out = Vec::new();
        cut(&ramp, Segment { start: 0, end: 2 }, 3, &mut out);
        assert_eq!(out, [Segment { start: 0, end: 2 }]);
    }
}
