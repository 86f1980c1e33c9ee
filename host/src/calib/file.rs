//! Calibration files: the TOML form a lab writes (issue 2, item 2), read by
//! [`load`] and written by `triad calib fit` through [`render`].
//!
//! ```toml
//! id = 7                          # optional; default: CRC-32C of the blob's parameter bytes
//! orientation = "ROTATION_NONE"   # optional; PX4 name or id, default ROTATION_NONE
//! [accel]
//! scale_misalignment = [[1.002, 0.001, -0.0005], [0.0003, 0.998, 0.002], [0.0, -0.001, 1.001]]  # I + Σ
//! bias = [0.05, -0.02, 0.10]        # m/s²
//! [accel.temperature]               # optional
//! reference_c = 25.0
//! bias_coefficients = [[c1, c2, c3], [..], [..]]   # per axis, SI/°C, SI/°C², SI/°C³
//! scale_misalignment_per_c = [[..], [..], [..]]    # d(I+Σ)/dT, 1/°C
//! [gyro]
//! scale_misalignment = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
//! bias = [0.001, -0.002, 0.0005]    # rad/s
//! g_sensitivity = [[..], [..], [..]]  # optional; G in (rad/s)/(m/s²): gyro bias per unit specific force
//! ```
//!
//! Other top-level keys and tables are allowed (metadata, e.g. the
//! `[fit.accel]` / `[fit.gyro]` statistics `triad calib fit` writes); inside `[accel]`,
//! `[gyro]` and their `temperature` tables unknown keys are errors, so a
//! misspelt optional key cannot silently vanish. This module only reads the
//! file; [`triad::model::Corrector`] validates the values.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};
use serde::Deserialize;
use triad::model::{blob, Calibration, Orientation, TemperatureTerms, TriadCalibration};

/// A calibration file as read.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibFile {
    /// Where it was read from (for messages).
    pub path: PathBuf,
    /// The calibration; `id` is the file's or the parameter CRC.
    pub calibration: Calibration,
    /// True when the file set no `id`.
    pub id_from_parameters: bool,
    /// The mounting orientation.
    pub orientation: Orientation,
    /// The top-level `[fit]` table (the statistics earlier fits wrote),
    /// empty when there is none: kept when another triad is fitted from
    /// this file as `--base`.
    pub fit: toml::Table,
}

#[derive(Deserialize)]
struct FileShape {
    id: Option<u32>,
    orientation: Option<toml::Value>,
    accel: TriadShape,
    gyro: TriadShape,
    /// Metadata: any value is allowed; only a table is kept.
    fit: Option<toml::Value>,
}

/// A vector or matrix as written, with where it is: its length is
/// checked here (a fixed-size array would silently drop extra entries).
type Spanned<T> = toml::Spanned<T>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TriadShape {
    scale_misalignment: Spanned<Vec<Spanned<Vec<f64>>>>,
    bias: Spanned<Vec<f64>>,
    temperature: Option<TemperatureShape>,
    /// The gyroscope's only; refused in `[accel]`.
    g_sensitivity: Option<Spanned<Vec<Spanned<Vec<f64>>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TemperatureShape {
    reference_c: f64,
    bias_coefficients: Spanned<Vec<Spanned<Vec<f64>>>>,
    scale_misalignment_per_c: Spanned<Vec<Spanned<Vec<f64>>>>,
}

/// Checks lengths against the text the values were read from, for positions.
struct Shapes<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Shapes<'_> {
    /// `PATH: LINE:COL: invalid length N, expected an array of length 3
    /// (in `KEY`)`, as the TOML reader words its own errors.
    fn wrong_length(&self, span: std::ops::Range<usize>, found: usize, key: &str) -> anyhow::Error {
        anyhow!(
            "{}: {}invalid length {found}, expected an array of length 3 (in `{key}`)",
            self.path.display(),
            position(self.text, span.start)
        )
    }

    fn vector(&self, v: &Spanned<Vec<f64>>, key: &str) -> anyhow::Result<[f64; 3]> {
        <[f64; 3]>::try_from(v.get_ref().as_slice())
            .map_err(|_| self.wrong_length(v.span(), v.get_ref().len(), key))
    }

    fn matrix(
        &self,
        m: &Spanned<Vec<Spanned<Vec<f64>>>>,
        key: &str,
    ) -> anyhow::Result<[[f64; 3]; 3]> {
        let rows = m.get_ref();
        if rows.len() != 3 {
            return Err(self.wrong_length(m.span(), rows.len(), key));
        }
        let mut out = [[0.0; 3]; 3];
        for (i, row) in rows.iter().enumerate() {
            out[i] = self.vector(row, key)?;
        }
        Ok(out)
    }

    fn triad(&self, t: &TriadShape, name: &str) -> anyhow::Result<TriadCalibration> {
        let temperature = match &t.temperature {
            None => None,
            Some(x) => Some(TemperatureTerms {
                reference_c: x.reference_c,
                bias_coefficients: self.matrix(
                    &x.bias_coefficients,
                    &format!("{name}.temperature.bias_coefficients"),
                )?,
                scale_misalignment_per_c: self.matrix(
                    &x.scale_misalignment_per_c,
                    &format!("{name}.temperature.scale_misalignment_per_c"),
                )?,
            }),
        };
        Ok(TriadCalibration {
            scale_misalignment: self
                .matrix(&t.scale_misalignment, &format!("{name}.scale_misalignment"))?,
            bias: self.vector(&t.bias, &format!("{name}.bias"))?,
            temperature,
        })
    }
}

/// `LINE:COL: ` of byte `offset` in `text`.
fn position(text: &str, offset: usize) -> String {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
    format!("{line}:{column}: ")
}

/// Reads and parses `path`, or the shipped calibration of that name
/// (`default`; the rule is [`crate::plumbing::shipped`]'s); errors name the file, the
/// line and the key.
pub fn load(path: &Path) -> anyhow::Result<CalibFile> {
    let source = crate::plumbing::shipped::locate(
        path,
        "calibration",
        crate::plumbing::shipped::CALIBRATIONS,
    )?;
    parse(&source.text()?, &source.shown())
}

/// Parses the text of a calibration file read from `path`.
pub fn parse(text: &str, path: &Path) -> anyhow::Result<CalibFile> {
    let text = crate::plumbing::input::strip_bom(text);
    let shape: FileShape =
        toml::from_str(text).map_err(|e| anyhow!("{}:{}", path.display(), one_line(&e, text)))?;
    let orientation = match &shape.orientation {
        None => Orientation::RotationNone,
        Some(value) => parse_orientation(value)
            .map_err(|reason| anyhow!("{}: orientation: {reason}", path.display()))?,
    };
    let shapes = Shapes { path, text };
    if let Some(g) = &shape.accel.g_sensitivity {
        anyhow::bail!(
            "{}: {}`accel.g_sensitivity`: g-sensitivity is the gyroscope's (bias per unit specific force): put it in [gyro]",
            path.display(),
            position(text, g.span().start)
        );
    }
    let g_sensitivity = match &shape.gyro.g_sensitivity {
        None => None,
        Some(g) => Some(shapes.matrix(g, "gyro.g_sensitivity")?),
    };
    let mut calibration = Calibration {
        id: 0,
        accel: shapes.triad(&shape.accel, "accel")?,
        gyro: shapes.triad(&shape.gyro, "gyro")?,
        g_sensitivity,
    };
    let id_from_parameters = shape.id.is_none();
    calibration.id = shape.id.unwrap_or_else(|| blob::parameter_id(&calibration));
    let fit = match shape.fit {
        Some(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    };
    Ok(CalibFile {
        path: path.to_path_buf(),
        calibration,
        id_from_parameters,
        orientation,
        fit,
    })
}

impl CalibFile {
    /// The temperature range its terms were fitted over: the intersection of
    /// `temperature_range_c` = [lo, hi] of `[fit.accel]` and `[fit.gyro]`
    /// (`triad calib fit thermal` writes them), or `None` without one.
    pub fn fitted_temperature_range(&self) -> Option<[f64; 2]> {
        let ranges: Vec<[f64; 2]> = ["accel", "gyro"]
            .iter()
            .filter_map(|triad| {
                let r = self
                    .fit
                    .get(*triad)?
                    .get("temperature_range_c")?
                    .as_array()?;
                match r.as_slice() {
                    [lo, hi] => Some([lo.as_float()?, hi.as_float()?]),
                    _ => None,
                }
            })
            .collect();
        let lo = ranges.iter().map(|r| r[0]).reduce(f64::max)?;
        let hi = ranges.iter().map(|r| r[1]).reduce(f64::min)?;
        Some([lo, hi])
    }
}

fn parse_orientation(value: &toml::Value) -> Result<Orientation, String> {
    match value {
        toml::Value::String(name) => Orientation::from_name(name)
            .ok_or_else(|| format!("`{name}` is not one of the 24 right-angle orientations (PX4 names, e.g. ROTATION_YAW_90)")),
        toml::Value::Integer(id) => u8::try_from(*id)
            .map_err(|_| format!("{id} is not a PX4 rotation id"))
            .and_then(|id| Orientation::from_id(id).map_err(|e| e.to_string())),
        other => Err(format!("expected a PX4 rotation name or id, found {}", other.type_str())),
    }
}

/// `LINE:COL: message (in `key`)` from a toml error, on one line.
fn one_line(error: &toml::de::Error, text: &str) -> String {
    let position = error.span().map(|span| position(text, span.start));
    // Without the input, Display gives the message and then "in `a.b`".
    let mut bare = error.clone();
    bare.set_input(None);
    let rendered = bare.to_string();
    let mut lines = rendered.lines().map(str::trim).filter(|l| !l.is_empty());
    let message = lines.next().unwrap_or("invalid TOML").to_string();
    let keys = lines.next().map(|k| format!(" ({k})")).unwrap_or_default();
    format!(" {}{message}{keys}", position.unwrap_or_default())
}

/// The TOML of one triad: `scale_misalignment`, `bias`, optional `temperature`.
fn triad_table(t: &TriadCalibration) -> toml::Table {
    let matrix = |m: &[[f64; 3]; 3]| toml::Value::Array(m.iter().map(vector).collect());
    let mut table = toml::Table::new();
    table.insert("scale_misalignment".into(), matrix(&t.scale_misalignment));
    table.insert("bias".into(), vector(&t.bias));
    if let Some(terms) = &t.temperature {
        let mut temp = toml::Table::new();
        temp.insert("reference_c".into(), toml::Value::Float(terms.reference_c));
        temp.insert("bias_coefficients".into(), matrix(&terms.bias_coefficients));
        temp.insert(
            "scale_misalignment_per_c".into(),
            matrix(&terms.scale_misalignment_per_c),
        );
        table.insert("temperature".into(), toml::Value::Table(temp));
    }
    table
}

/// A TOML array of three floats.
pub fn vector(v: &[f64; 3]) -> toml::Value {
    toml::Value::Array(v.iter().map(|&x| toml::Value::Float(x)).collect())
}

/// Renders a calibration file: `header` as `#` comment lines, no `id` (so
/// the identity is the CRC-32C of the parameters), the orientation when it is
/// not ROTATION_NONE, `[accel]`, `[gyro]`, and `extra` top-level tables
/// (metadata such as `[fit.accel]`, which [`parse`] ignores). The text is
/// parsed back before it is returned: what is written reads back to exactly
/// `calibration`, or this is an error.
pub fn render(
    calibration: &Calibration,
    orientation: Orientation,
    header: &str,
    extra: toml::Table,
) -> anyhow::Result<String> {
    let mut doc = toml::Table::new();
    if orientation != Orientation::RotationNone {
        doc.insert(
            "orientation".into(),
            toml::Value::String(orientation.name().into()),
        );
    }
    doc.insert(
        "accel".into(),
        toml::Value::Table(triad_table(&calibration.accel)),
    );
    let mut gyro = triad_table(&calibration.gyro);
    if let Some(g) = &calibration.g_sensitivity {
        gyro.insert(
            "g_sensitivity".into(),
            toml::Value::Array(g.iter().map(vector).collect()),
        );
    }
    doc.insert("gyro".into(), toml::Value::Table(gyro));
    for (key, value) in extra {
        doc.insert(key, value);
    }
    let body = toml::to_string(&doc).context("rendering the calibration file")?;
    let mut text = String::new();
    for line in header.lines() {
        text.push_str(if line.is_empty() { "#" } else { "# " });
        text.push_str(line);
        text.push('\n');
    }
    text.push('\n');
    text.push_str(&body);
    let back = parse(&text, Path::new("(written file)"))?;
    if back.calibration.accel != calibration.accel
        || back.calibration.gyro != calibration.gyro
        || back.calibration.g_sensitivity != calibration.g_sensitivity
        || back.orientation != orientation
    {
        anyhow::bail!(
            "internal error: the rendered calibration file does not read back to the same values"
        );
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::model::calibration::IDENTITY;

    const MINIMAL: &str = "[accel]\nscale_misalignment = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\nbias = [0.1, 0.0, 0.0]\n\
                           [gyro]\nscale_misalignment = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\nbias = [0.0, 0.0, 0.01]\n";

    fn parsed(text: &str) -> anyhow::Result<CalibFile> {
        parse(text, Path::new("c.toml"))
    }

    #[test]
    fn without_id_the_identity_is_the_parameters_crc() {
        let f = parsed(MINIMAL).unwrap();
        assert!(f.id_from_parameters);
        assert_eq!(f.calibration.id, blob::parameter_id(&f.calibration));
        assert_eq!(f.orientation, Orientation::RotationNone);
        assert_eq!(f.calibration.gyro.bias, [0.0, 0.0, 0.01]);
        let f = parsed(&format!(
            "id = 7\norientation = \"ROTATION_YAW_90\"\n{MINIMAL}"
        ))
        .unwrap();
        assert_eq!((f.calibration.id, f.id_from_parameters), (7, false));
        assert_eq!(
            f.orientation,
            Orientation::from_name("ROTATION_YAW_90").unwrap()
        );
    }

    #[test]
    fn orientations_are_px4_names_or_ids() {
        let by_id = parse_orientation(&toml::Value::Integer(0)).unwrap();
        assert_eq!(by_id, Orientation::RotationNone);
        let err = parse_orientation(&toml::Value::String("ROTATION_YAW_45".into())).unwrap_err();
        assert!(
            err.contains("not one of the 24 right-angle orientations"),
            "{err}"
        );
        assert!(parse_orientation(&toml::Value::Integer(-1))
            .unwrap_err()
            .contains("-1 is not a PX4 rotation id"));
        assert!(parse_orientation(&toml::Value::Float(1.0))
            .unwrap_err()
            .contains("found float"));
    }

    #[test]
    fn toml_errors_are_one_line_with_position_and_key() {
        let text = MINIMAL.replace("bias = [0.1, 0.0, 0.0]\n", "bias = [0.1, 0.0]\n");
        let err = parsed(&text).unwrap_err().to_string();
        assert!(err.starts_with("c.toml: 3:8: invalid length 2"), "{err}");
        assert!(
            err.ends_with("(in `accel.bias`)") && !err.contains('\n'),
            "{err}"
        );
    }

    #[test]
    fn extra_entries_and_rows_are_refused_with_the_key_and_the_count() {
        let err = |from: &str, to: &str| {
            let text = MINIMAL.replacen(from, to, 1);
            assert_ne!(text, MINIMAL, "{from}");
            parsed(&text).unwrap_err().to_string()
        };
        assert_eq!(
            err("bias = [0.1, 0.0, 0.0]", "bias = [0.1, 0.0, 0.0, 0.5]"),
            "c.toml: 3:8: invalid length 4, expected an array of length 3 (in `accel.bias`)"
        );
        assert_eq!(
            err("[0.0, 0.0, 1.0]]", "[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]]"),
            "c.toml: 2:22: invalid length 4, expected an array of length 3 (in `accel.scale_misalignment`)"
        );
        assert_eq!(
            err("[0.0, 1.0, 0.0]", "[0.0, 1.0, 0.0, 9.0]"),
            "c.toml: 2:40: invalid length 4, expected an array of length 3 (in `accel.scale_misalignment`)"
        );
        // A byte-order mark before the first key is not part of it.
        assert!(parsed(&format!("\u{feff}{MINIMAL}")).is_ok());
    }

    #[test]
    fn rendered_files_read_back_to_the_same_calibration() {
        let mut cal = Calibration::identity(0);
        cal.accel.bias = [0.25, -1e-9, 3.0];
        cal.gyro.scale_misalignment = [[1.001, 2e-3, 0.0], [0.0, 0.999, 0.0], [0.0, 0.0, 1.0]];
        let mut extra = toml::Table::new();
        extra.insert("fit".into(), toml::Value::Table(toml::Table::new()));
        let yaw = Orientation::from_name("ROTATION_YAW_90").unwrap();
        let text = render(&cal, yaw, "First line\n\nthird", extra).unwrap();
        assert!(text.starts_with("# First line\n#\n# third\n\n"), "{text}");
        assert!(!text.contains("\nid ="));
        let back = parsed(&text).unwrap();
        assert_eq!(
            (back.calibration.accel, back.calibration.gyro),
            (cal.accel, cal.gyro)
        );
        assert_eq!(back.orientation, yaw);
        assert_eq!(back.calibration.accel.scale_misalignment, IDENTITY);
    }

    #[test]
    fn g_sensitivity_is_the_gyros_and_reads_back() {
        let mut cal = Calibration::identity(0);
        cal.g_sensitivity = Some([[2e-4, -1e-5, 0.0], [3e-6, 1.5e-4, 0.0], [0.0, 0.0, -2e-4]]);
        let text = render(&cal, Orientation::RotationNone, "", toml::Table::new()).unwrap();
        let back = parsed(&text).unwrap();
        assert_eq!(back.calibration.g_sensitivity, cal.g_sensitivity);
        // G changes the identity; a file without it keeps the one it had.
        assert_ne!(back.calibration.id, parsed(MINIMAL).unwrap().calibration.id);
        let g = "g_sensitivity = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n";
        let err = parsed(&MINIMAL.replacen("[gyro]\n", &format!("{g}[gyro]\n"), 1))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("c.toml: 4:17: `accel.g_sensitivity`") && err.contains("[gyro]"),
            "{err}"
        );
        let err = parsed(&format!(
            "{MINIMAL}g_sensitivity = [[0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("invalid length 2") && err.contains("gyro.g_sensitivity"),
            "{err}"
        );
    }

    #[test]
    fn the_fit_table_is_kept_from_the_same_parse() {
        assert!(parsed(MINIMAL).unwrap().fit.is_empty());
        let f = parsed(&format!(
            "\u{feff}{MINIMAL}[fit.gyro]\nmethod = \"static\"\n"
        ))
        .unwrap();
        assert_eq!(f.fit["gyro"]["method"].as_str(), Some("static"));
        // Metadata that is not a table is not a calibration error.
        assert!(parsed(&format!("fit = 3\n{MINIMAL}"))
            .unwrap()
            .fit
            .is_empty());
    }
}
