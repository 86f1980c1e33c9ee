//! `triad correct` on triad's CSV: columns found by name, every other cell
//! copied as written, streamed line by line in constant memory.

use std::io::{self, BufRead, Write};

use anyhow::{anyhow, bail, Context};
use triad::model::Corrector;

use super::{six, How, Outside};
use crate::plumbing::input::strip_bom;
use crate::plumbing::stdio;

/// The columns read, by name: `t`, the six values, then the optional `temp`.
const COLUMNS: [&str; 8] = ["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"];

/// Where the columns are: the cell index of `t`, the six values and `temp`.
struct Header {
    /// The header's names, as the output's header.
    names: Vec<String>,
    /// Cell index of each of [`COLUMNS`] (`temp` optional).
    index: [Option<usize>; 8],
    /// For each cell, which of the six values (0 = ax … 5 = gz) it holds.
    value_of_cell: Vec<Option<usize>>,
}

impl Header {
    /// The header from its line; `t` and the six values must be there, once.
    fn parse(line: &str) -> Result<Header, String> {
        let names: Vec<String> = strip_bom(line)
            .trim()
            .split(',')
            .map(|n| n.trim().to_string())
            .collect();
        let mut index = [None; 8];
        for (k, column) in COLUMNS.iter().enumerate() {
            let mut at = names.iter().enumerate().filter(|(_, n)| n == column);
            index[k] = at.next().map(|(i, _)| i);
            if at.next().is_some() {
                return Err(format!("column `{column}` appears twice in the header"));
            }
        }
        let missing: Vec<String> = COLUMNS[..7]
            .iter()
            .zip(&index)
            .filter(|(_, i)| i.is_none())
            .map(|(c, _)| format!("`{c}`"))
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "missing column(s) {} in the header `{}` (needed: t,ax,ay,az,gx,gy,gz; temp optional)",
                missing.join(", "),
                names.join(",")
            ));
        }
        let mut value_of_cell = vec![None; names.len()];
        for (k, cell) in index[1..7].iter().enumerate() {
            if let Some(cell) = cell {
                value_of_cell[*cell] = Some(k);
            }
        }
        Ok(Header {
            names,
            index,
            value_of_cell,
        })
    }

    /// The cell index of column `k` of [`COLUMNS`] (`t` and the six values are always there).
    fn cell(&self, k: usize) -> usize {
        self.index[k].unwrap_or(0)
    }
}

/// Where a message points: the input's name and the line.
#[derive(Clone, Copy)]
struct Place<'a> {
    name: &'a str,
    number: usize,
}

impl Place<'_> {
    /// The finite number in cell `cell` of `fields`, column `column`.
    fn number(self, fields: &[&str], cell: usize, column: &str) -> anyhow::Result<f64> {
        let Place { name, number } = self;
        let raw = fields[cell];
        let value: f64 = raw.parse().map_err(|_| {
            anyhow!(
                "{name} line {number}, column {} ({column}): `{raw}` is not a number",
                cell + 1,
            )
        })?;
        if value.is_finite() {
            Ok(value)
        } else {
            bail!(
                "{name} line {number}, column {} ({column}): `{raw}` is not a finite number",
                cell + 1,
            )
        }
    }

    /// The six measured values (ax … gz) as f64.
    fn f64_values(self, fields: &[&str], header: &Header) -> anyhow::Result<[f64; 6]> {
        let mut v = [0.0f64; 6];
        for (i, x) in v.iter_mut().enumerate() {
            *x = self.number(fields, header.cell(i + 1), COLUMNS[i + 1])?;
        }
        Ok(v)
    }

    /// The six measured values straight to f32 (one correct rounding, as a
    /// device reading the same decimal would), not via f64.
    fn f32_values(self, fields: &[&str], header: &Header) -> anyhow::Result<[f32; 6]> {
        let mut f = [0.0f32; 6];
        for (i, x) in f.iter_mut().enumerate() {
            *x = fields[header.cell(i + 1)].parse().unwrap_or(f32::NAN);
        }
        let Some(i) = f.iter().position(|x| !x.is_finite()) else {
            return Ok(f);
        };
        // A bad cell is worded as --exact words it (not a number, not
        // finite: the first such cell); only a number that is finite as
        // an f64 is beyond the f32 range.
        self.f64_values(fields, header)?;
        let cell = header.cell(i + 1);
        let Place { name, number } = self;
        bail!(
            "{name} line {number}, column {} ({}): `{}` is beyond the f32 range",
            cell + 1,
            COLUMNS[i + 1],
            fields[cell]
        )
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

    /// The header (after blank lines).
    fn header(&mut self) -> anyhow::Result<Header> {
        let name = self.name.clone();
        loop {
            if !self.next().with_context(|| format!("{name}: read error"))? {
                bail!("{name}: empty input, expected a header with the columns t,ax,ay,az,gx,gy,gz[,temp]");
            }
            if strip_bom(&self.line).trim().is_empty() {
                continue;
            }
            return Header::parse(&self.line)
                .map_err(|e| anyhow!("{name} line {}: {e}", self.number));
        }
    }
}

/// Reads the CSV from `input`, writes the corrected CSV to `out`.
pub(super) fn correct_stream(
    input: impl BufRead,
    out: &mut impl Write,
    name: &str,
    corrector: &mut Corrector,
    how: How,
) -> anyhow::Result<Outside> {
    let How {
        has_terms,
        exact,
        fitted_range,
        ..
    } = how;
    let mut count = Outside::default();
    let mut lines = Lines {
        input,
        name: name.to_string(),
        line: String::new(),
        number: 0,
    };
    let header = lines.header()?;
    let width = header.names.len();
    writeln!(out, "{}", header.names.join(",")).map_err(stdio::stdout_error)?;
    let mut folded_at: Option<f64> = None;
    loop {
        let more = lines
            .next()
            .with_context(|| format!("{name}: read error at line {}", lines.number))?;
        if !more {
            return Ok(count);
        }
        let text = lines.line.trim();
        if text.is_empty() {
            continue;
        }
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        let at = lines.place();
        if fields.len() != width {
            bail!(
                "{name} line {}: expected {width} columns as in the header, found {}",
                at.number,
                fields.len()
            );
        }
        at.number(&fields, header.cell(0), "t")?;
        let temperature = match header.index[7] {
            Some(cell) => Some(at.number(&fields, cell, "temp")?),
            None => None,
        };
        if let (Some(t), true) = (temperature, has_terms) {
            if folded_at != Some(t) {
                corrector
                    .refold(t)
                    .map_err(|e| anyhow!("{name} line {}: {e}", at.number))?;
                folded_at = Some(t);
            }
        }
        correct_row(out, corrector, at, &fields, &header, temperature, exact)?;
        count.add(temperature, fitted_range);
    }
}

/// Corrects one row's six values and writes the row, every other cell as written.
fn correct_row(
    out: &mut impl Write,
    corrector: &Corrector,
    at: Place,
    fields: &[&str],
    header: &Header,
    temperature: Option<f64>,
    exact: bool,
) -> anyhow::Result<()> {
    let written = if exact {
        let v = at.f64_values(fields, header)?;
        let m = corrector.reference_si(
            [v[0], v[1], v[2]],
            [v[3], v[4], v[5]],
            temperature.unwrap_or(0.0),
        );
        write_row(out, fields, header, six(m.accel, m.gyro))
    } else {
        let f = at.f32_values(fields, header)?;
        let m = corrector.correct_si(
            [f[0], f[1], f[2]],
            [f[3], f[4], f[5]],
            temperature.unwrap_or(0.0) as f32,
        );
        write_row(out, fields, header, six(m.accel, m.gyro))
    };
    written.map_err(stdio::stdout_error)
}

/// One output row: the input's cells, the six values replaced by
/// `corrected`, each in the shortest form that reads back to the same number.
fn write_row<T: std::fmt::Display>(
    out: &mut impl Write,
    fields: &[&str],
    header: &Header,
    corrected: [T; 6],
) -> io::Result<()> {
    for (cell, raw) in fields.iter().enumerate() {
        if cell > 0 {
            out.write_all(b",")?;
        }
        match header.value_of_cell[cell] {
            Some(k) => write!(out, "{}", corrected[k])?,
            None => out.write_all(raw.as_bytes())?,
        }
    }
    out.write_all(b"\n")
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
        correct_stream(
            input.as_bytes(),
            &mut out,
            "in.csv",
            &mut c,
            How {
                has_terms: false,
                g_sensitivity: false,
                exact,
                fitted_range: None,
            },
        )?;
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
    fn columns_are_found_by_name_and_the_others_copied() {
        // `triad decode`'s columns, with a byte-order mark before the header.
        let input =
            "\u{feff}seq,t,ax,ay,az,gx,gy,gz,temp,flags\n7,0.01,1.0,2,3,0.1,0.2,0.3,25.5,4\n";
        let out = corrected(input, false).unwrap();
        assert_eq!(
            out,
            "seq,t,ax,ay,az,gx,gy,gz,temp,flags\n7,0.01,1,2,3,0.1,0.2,0.3,25.5,4\n"
        );
        let shuffled = corrected("gz,gy,gx,az,ay,ax,t\n6,5,4,3,2,1,0.5\n", true).unwrap();
        assert_eq!(shuffled, "gz,gy,gx,az,ay,ax,t\n6,5,4,3,2,1,0.5\n");
        let e = corrected("seq,t,ax,ay,az,gx,gy,gz\n1,0,0,0,x,0,0,0\n", false)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "in.csv line 2, column 5 (az): `x` is not a number");
    }

    #[test]
    fn bad_input_is_named_by_line_and_column() {
        let err = |input: &str| corrected(input, false).unwrap_err().to_string();
        assert!(err("").contains("empty input"));
        assert!(err("t,ax\n").starts_with("in.csv line 1: missing column(s) `ay`, `az`, `gx`"));
        assert!(err("t,ax,ay,az,gx,gy,gz,ax\n").contains("column `ax` appears twice"));
        let e = err("t,ax,ay,az,gx,gy,gz\n1,2,3\n");
        assert_eq!(
            e,
            "in.csv line 2: expected 7 columns as in the header, found 3"
        );
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
        // A cell that is no number is named before one beyond f32, as --exact names it.
        let e = err("t,ax,ay,az,gx,gy,gz\n1,1e39,x,0,0,0,0\n");
        assert_eq!(e, "in.csv line 2, column 3 (ay): `x` is not a number");
    }
}
