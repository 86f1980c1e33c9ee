//! `triad correct`: the firmware's correction, on a CSV of measured values in
//! SI units. The f32 path runs the same kernel as the firmware
//! (`Corrector::correct_si`); `--exact` runs the f64 reference. Streams line
//! by line in constant memory.
//!
//! Input columns `t,ax,ay,az,gx,gy,gz[,temp]` (s, m/s², rad/s, °C); output
//! the same columns, `t` and `temp` copied as written, the corrected values
//! printed in the shortest form that reads back to the same f32 (or f64).
//! With a `temp` column and temperature terms, the coefficients are refolded
//! whenever the temperature changes (clamped to the validated range).

use std::fs::File;
use std::io::{self, BufRead, BufReader, BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context};
use triad::model::Corrector;

use crate::calib::{si_corrector, Ranges};
use crate::calib_file;

/// Arguments of `triad correct`.
#[derive(clap::Args)]
pub struct CorrectArgs {
    /// The calibration file (TOML).
    #[arg(long)]
    calib: PathBuf,
    /// Input CSV with header `t,ax,ay,az,gx,gy,gz[,temp]` (`-` for stdin).
    input: PathBuf,
    /// Use the f64 reference instead of the firmware's f32 hot path.
    #[arg(long)]
    exact: bool,
    #[command(flatten)]
    ranges: Ranges,
}

const COLUMNS: [&str; 8] = ["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"];

/// Runs `triad correct`.
pub fn run(args: CorrectArgs) -> anyhow::Result<ExitCode> {
    let file = calib_file::load(&args.calib)?;
    let mut corrector = si_corrector(&file, &args.ranges)?;
    let has_terms =
        file.calibration.accel.temperature.is_some() || file.calibration.gyro.temperature.is_some();
    let name = if args.input.as_os_str() == "-" {
        "stdin".to_string()
    } else {
        args.input.display().to_string()
    };
    let input: Box<dyn BufRead> = if args.input.as_os_str() == "-" {
        Box::new(io::stdin().lock())
    } else {
        Box::new(BufReader::new(
            File::open(&args.input).with_context(|| format!("{name}: cannot open"))?,
        ))
    };
    let mut out = BufWriter::new(io::stdout().lock());
    correct_stream(
        input,
        &mut out,
        &name,
        &mut corrector,
        has_terms,
        args.exact,
    )?;
    out.flush().context("stdout")?;
    Ok(ExitCode::SUCCESS)
}

/// Reads the CSV from `input`, writes the corrected CSV to `out`.
fn correct_stream(
    mut input: impl BufRead,
    out: &mut impl Write,
    name: &str,
    corrector: &mut Corrector,
    has_terms: bool,
    exact: bool,
) -> anyhow::Result<()> {
    let mut line = String::new();
    let mut number = 0usize;
    let width = loop {
        line.clear();
        number += 1;
        if input
            .read_line(&mut line)
            .with_context(|| format!("{name}: read error"))?
            == 0
        {
            bail!("{name}: empty input, expected the header `t,ax,ay,az,gx,gy,gz[,temp]`");
        }
        let header: Vec<&str> = line.trim().split(',').map(str::trim).collect();
        if header == [""] {
            continue;
        }
        match header.len() {
            7 | 8 if header[..] == COLUMNS[..header.len()] => break header.len(),
            _ => bail!(
                "{name} line {number}: header must be `t,ax,ay,az,gx,gy,gz` or `t,ax,ay,az,gx,gy,gz,temp`, found `{}`",
                line.trim()
            ),
        }
    };
    writeln!(out, "{}", COLUMNS[..width].join(","))?;
    let mut folded_at: Option<f64> = None;
    loop {
        line.clear();
        number += 1;
        if input
            .read_line(&mut line)
            .with_context(|| format!("{name}: read error at line {number}"))?
            == 0
        {
            return Ok(());
        }
        let text = line.trim();
        if text.is_empty() {
            continue;
        }
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != width {
            bail!(
                "{name} line {number}: expected {width} columns, found {}",
                fields.len()
            );
        }
        let field = |col: usize| -> anyhow::Result<f64> {
            let raw = fields[col];
            let value: f64 = raw.parse().map_err(|_| {
                anyhow!(
                    "{name} line {number}, column {} ({}): `{raw}` is not a number",
                    col + 1,
                    COLUMNS[col]
                )
            })?;
            if value.is_finite() {
                Ok(value)
            } else {
                bail!(
                    "{name} line {number}, column {} ({}): `{raw}` is not a finite number",
                    col + 1,
                    COLUMNS[col]
                )
            }
        };
        field(0)?;
        let temperature = if width == 8 { Some(field(7)?) } else { None };
        if let (Some(t), true) = (temperature, has_terms) {
            if folded_at != Some(t) {
                corrector
                    .refold(t)
                    .map_err(|e| anyhow!("{name} line {number}: {e}"))?;
                folded_at = Some(t);
            }
        }
        let mut v = [0.0f64; 6];
        for (i, x) in v.iter_mut().enumerate() {
            *x = field(i + 1)?;
        }
        let tail = if width == 8 {
            format!(",{}", fields[7])
        } else {
            String::new()
        };
        if exact {
            let m = corrector.reference_si(
                [v[0], v[1], v[2]],
                [v[3], v[4], v[5]],
                temperature.unwrap_or(0.0),
            );
            let [ax, ay, az] = m.accel;
            let [gx, gy, gz] = m.gyro;
            writeln!(out, "{},{ax},{ay},{az},{gx},{gy},{gz}{tail}", fields[0])?;
        } else {
            // Parse the text straight to f32 (one correct rounding, as a
            // device reading the same decimal would), not via f64.
            let mut f = [0.0f32; 6];
            for (i, x) in f.iter_mut().enumerate() {
                *x = fields[i + 1].parse().unwrap_or(f32::NAN);
                if !x.is_finite() {
                    bail!(
                        "{name} line {number}, column {} ({}): `{}` is beyond the f32 range",
                        i + 2,
                        COLUMNS[i + 1],
                        fields[i + 1]
                    );
                }
            }
            let m = corrector.correct_si(
                [f[0], f[1], f[2]],
                [f[3], f[4], f[5]],
                temperature.unwrap_or(0.0) as f32,
            );
            let [ax, ay, az] = m.accel;
            let [gx, gy, gz] = m.gyro;
            writeln!(out, "{},{ax},{ay},{az},{gx},{gy},{gz}{tail}", fields[0])?;
        }
    }
}
