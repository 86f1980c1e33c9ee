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

/// Where a message points: the input's name and the line.
#[derive(Clone, Copy)]
struct Place<'a> {
    name: &'a str,
    number: usize,
}

impl Place<'_> {
    /// The finite number in column `col` of `fields`.
    fn number(self, fields: &[&str], col: usize) -> anyhow::Result<f64> {
        let Place { name, number } = self;
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
    }

    /// The six measured values straight to f32 (one correct rounding, as a
    /// device reading the same decimal would), not via f64.
    fn f32_values(self, fields: &[&str]) -> anyhow::Result<[f32; 6]> {
        let Place { name, number } = self;
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
        Ok(f)
    }
}

/// The input's lines, counted.
struct Lines<R> {
    input: R,
    name: String,
    line: String,
    number: usize,
}

impl<R: BufRead> Lines<R> {
    /// Reads the next line into `self.line`; false at the end.
    fn next(&mut self) -> io::Result<bool> {
        self.line.clear();
        self.number += 1;
        Ok(self.input.read_line(&mut self.line)? > 0)
    }

    fn place(&self) -> Place<'_> {
        Place {
            name: &self.name,
            number: self.number,
        }
    }

    /// The header (after blank lines): 7 columns, or 8 with `temp`.
    fn header(&mut self) -> anyhow::Result<usize> {
        let name = self.name.clone();
        loop {
            if !self.next().with_context(|| format!("{name}: read error"))? {
                bail!("{name}: empty input, expected the header `t,ax,ay,az,gx,gy,gz[,temp]`");
            }
            let header: Vec<&str> = self.line.trim().split(',').map(str::trim).collect();
            if header == [""] {
                continue;
            }
            return match header.len() {
                7 | 8 if header[..] == COLUMNS[..header.len()] => Ok(header.len()),
                _ => bail!(
                    "{name} line {}: header must be `t,ax,ay,az,gx,gy,gz` or `t,ax,ay,az,gx,gy,gz,temp`, found `{}`",
                    self.number,
                    self.line.trim()
                ),
            };
        }
    }
}

/// Reads the CSV from `input`, writes the corrected CSV to `out`.
fn correct_stream(
    input: impl BufRead,
    out: &mut impl Write,
    name: &str,
    corrector: &mut Corrector,
    has_terms: bool,
    exact: bool,
) -> anyhow::Result<()> {
    let mut lines = Lines {
        input,
        name: name.to_string(),
        line: String::new(),
        number: 0,
    };
    let width = lines.header()?;
    writeln!(out, "{}", COLUMNS[..width].join(","))?;
    let mut folded_at: Option<f64> = None;
    loop {
        let more = lines
            .next()
            .with_context(|| format!("{name}: read error at line {}", lines.number))?;
        if !more {
            return Ok(());
        }
        let text = lines.line.trim();
        if text.is_empty() {
            continue;
        }
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        let at = lines.place();
        if fields.len() != width {
            bail!(
                "{name} line {}: expected {width} columns, found {}",
                at.number,
                fields.len()
            );
        }
        at.number(&fields, 0)?;
        let temperature = if width == 8 {
            Some(at.number(&fields, 7)?)
        } else {
            None
        };
        if let (Some(t), true) = (temperature, has_terms) {
            if folded_at != Some(t) {
                corrector
                    .refold(t)
                    .map_err(|e| anyhow!("{name} line {}: {e}", at.number))?;
                folded_at = Some(t);
            }
        }
        correct_row(out, corrector, at, &fields, temperature, exact)?;
    }
}

/// Corrects one row's six values and writes the row, `t` and `temp` as written.
fn correct_row(
    out: &mut impl Write,
    corrector: &Corrector,
    at: Place,
    fields: &[&str],
    temperature: Option<f64>,
    exact: bool,
) -> anyhow::Result<()> {
    let mut v = [0.0f64; 6];
    for (i, x) in v.iter_mut().enumerate() {
        *x = at.number(fields, i + 1)?;
    }
    let tail = fields.get(7).map(|t| format!(",{t}")).unwrap_or_default();
    if exact {
        let m = corrector.reference_si(
            [v[0], v[1], v[2]],
            [v[3], v[4], v[5]],
            temperature.unwrap_or(0.0),
        );
        write_row(out, fields[0], m.accel, m.gyro, &tail)?;
    } else {
        let f = at.f32_values(fields)?;
        let m = corrector.correct_si(
            [f[0], f[1], f[2]],
            [f[3], f[4], f[5]],
            temperature.unwrap_or(0.0) as f32,
        );
        write_row(out, fields[0], m.accel, m.gyro, &tail)?;
    }
    Ok(())
}

/// One output row: `t` as written, the corrected values in the shortest form
/// that reads back to the same number, then `tail` (`,temp` or nothing).
fn write_row<T: std::fmt::Display>(
    out: &mut impl Write,
    t: &str,
    accel: [T; 3],
    gyro: [T; 3],
    tail: &str,
) -> io::Result<()> {
    let [ax, ay, az] = accel;
    let [gx, gy, gz] = gyro;
    writeln!(out, "{t},{ax},{ay},{az},{gx},{gy},{gz}{tail}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::model::{Calibration, Orientation};

    fn identity() -> Corrector {
        Corrector::new_si(
            &Calibration::identity(1),
            160.0,
            35.0,
            Orientation::RotationNone,
        )
        .unwrap()
    }

    fn corrected(input: &str, exact: bool) -> anyhow::Result<String> {
        let mut out = Vec::new();
        let mut c = identity();
        correct_stream(input.as_bytes(), &mut out, "in.csv", &mut c, false, exact)?;
        Ok(String::from_utf8(out).unwrap())
    }

    #[test]
    fn the_identity_gives_back_the_values_and_keeps_t_and_temp() {
        let input = "\nt,ax,ay,az,gx,gy,gz,temp\n0.01,1,2,3,0.1,0.2,0.3, 25.50\n\n0.02,-1,0,9.5,0,0,-0.5,26\n";
        let out = corrected(input, false).unwrap();
        assert_eq!(
            out,
            "t,ax,ay,az,gx,gy,gz,temp\n0.01,1,2,3,0.1,0.2,0.3,25.50\n0.02,-1,0,9.5,0,0,-0.5,26\n"
        );
        let exact = corrected("t,ax,ay,az,gx,gy,gz\n1,0.1,0,0,0,0,0\n", true).unwrap();
        assert_eq!(exact, "t,ax,ay,az,gx,gy,gz\n1,0.1,0,0,0,0,0\n");
    }

    #[test]
    fn bad_input_is_named_by_line_and_column() {
        let err = |input: &str| corrected(input, false).unwrap_err().to_string();
        assert!(err("").contains("empty input"));
        assert!(err("t,ax\n").starts_with("in.csv line 1: header must be"));
        let e = err("t,ax,ay,az,gx,gy,gz\n1,2,3\n");
        assert_eq!(e, "in.csv line 2: expected 7 columns, found 3");
        let e = err("t,ax,ay,az,gx,gy,gz\n\n1,2,x,0,0,0,0\n");
        assert_eq!(e, "in.csv line 3, column 3 (ay): `x` is not a number");
        let e = err("t,ax,ay,az,gx,gy,gz\n1,2,3,inf,0,0,0\n");
        assert_eq!(
            e,
            "in.csv line 2, column 4 (az): `inf` is not a finite number"
        );
        let e = err("t,ax,ay,az,gx,gy,gz\n1,1e39,0,0,0,0,0\n");
        assert_eq!(
            e,
            "in.csv line 2, column 2 (ax): `1e39` is beyond the f32 range"
        );
    }
}
