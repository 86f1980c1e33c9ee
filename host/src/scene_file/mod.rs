//! Scene files: TOML in data-sheet units, converted once into the core's SI
//! [`Scene`]. Every error names the file position (line:column) of the value
//! at fault and why it is wrong.
//!
//! ```toml
//! rate_hz = 100.0
//! duration_s = 600.0             # default length (--seconds overrides)
//! gravity = "9.81 m/s^2"         # optional, default 9.80665 m/s²
//! latitude_deg = 48.1            # optional: turns the Earth rate on
//!
//! [motion]
//! kind = "static"                # static | rate-table | tumble | vibration
//! attitude_deg = [0.0, 0.0, 0.0] # roll, pitch, yaw (static, vibration)
//!
//! [temperature]
//! kind = "constant"              # constant | ramp
//! celsius = 25.0
//!
//! [gyro]
//! grade = "tactical"             # a preset; effects named below override it
//! white_noise = "0.15 deg/sqrt(h)"
//! bias = ["10 deg/h", "-5 deg/h", "0 deg/h"]
//! ```
//!
//! Per-axis values are one quantity (all axes) or an array of three.

pub mod unit;

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use serde::Deserialize;
use toml::Spanned;
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_sim::bias_instability::{BiasInstabilityParams, MAX_TERMS};
use triad_sim::grade::{AccelGrade, GyroGrade};
use triad_sim::motion::{Axis, Environment, Motion};
use triad_sim::scene::{GaussMarkovParams, Scene, TriadEffects};
use triad_sim::temperature_dependence::TemperatureDependence;
use triad_sim::temperature_profile::TemperatureProfile;
use unit::{parse_quantity, Dim};

/// A loaded scene: the SI scene and its default duration.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// The file's `duration_s`, if any.
    pub duration_s: Option<f64>,
    /// Where it came from.
    pub path: PathBuf,
}

type Value = Spanned<toml::Value>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[allow(dead_code)]
    description: Option<String>,
    rate_hz: Spanned<f64>,
    duration_s: Option<Spanned<f64>>,
    gravity: Option<Value>,
    latitude_deg: Option<Spanned<f64>>,
    motion: MotionFile,
    temperature: Option<TemperatureFile>,
    accel: Option<TriadFile>,
    gyro: Option<TriadFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionFile {
    kind: Spanned<String>,
    attitude_deg: Option<Spanned<[f64; 3]>>,
    axis: Option<Spanned<String>>,
    rate: Option<Value>,
    positions: Option<Spanned<u8>>,
    dwell_s: Option<Spanned<f64>>,
    transition_s: Option<Spanned<f64>>,
    direction: Option<Spanned<[f64; 3]>>,
    amplitude: Option<Value>,
    frequency_hz: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TemperatureFile {
    kind: Spanned<String>,
    celsius: Option<Spanned<f64>>,
    from_c: Option<Spanned<f64>>,
    to_c: Option<Spanned<f64>>,
    start_s: Option<Spanned<f64>>,
    duration_s: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TriadFile {
    grade: Option<Spanned<String>>,
    white_noise: Option<Value>,
    random_walk: Option<Value>,
    bias: Option<Value>,
    turn_on_bias: Option<Value>,
    scale_factor: Option<Value>,
    turn_on_scale: Option<Value>,
    misalignment: Option<Value>,
    g_sensitivity: Option<Value>,
    quantisation: Option<Value>,
    saturation: Option<Value>,
    gauss_markov: Option<GaussMarkovFile>,
    bias_instability: Option<BiasInstabilityFile>,
    temperature: Option<TemperatureDependenceFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GaussMarkovFile {
    sigma: Value,
    correlation_time: Value,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BiasInstabilityFile {
    value: Value,
    band_s: Option<Spanned<[f64; 2]>>,
    terms: Option<Spanned<u8>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TemperatureDependenceFile {
    reference_c: Spanned<f64>,
    bias: Option<Value>,
    scale: Option<Value>,
}

/// Turns byte spans into "path:line:column" messages.
struct Source<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Source<'_> {
    fn position(&self, span: &Range<usize>) -> String {
        let before = &self.text[..span.start.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!("{}:{line}:{column}", self.path.display())
    }

    fn error(&self, span: &Range<usize>, message: impl std::fmt::Display) -> anyhow::Error {
        anyhow!("{}: {message}", self.position(span))
    }
}

/// What a field needs: its dimension and whether it may be negative.
#[derive(Clone, Copy)]
struct Field {
    name: &'static str,
    dim: Dim,
    /// Examples of units shown when the unit is wrong.
    example: &'static str,
    signed: bool,
}

/// The SI unit of the triad and examples of its units.
#[derive(Clone, Copy)]
struct TriadKind {
    name: &'static str,
    dim: Dim,
    example: &'static str,
}

const ACCEL: TriadKind = TriadKind {
    name: "accel",
    dim: Dim::ACCEL,
    example: "mg, ug, m/s^2",
};
const GYRO: TriadKind = TriadKind {
    name: "gyro",
    dim: Dim::RATE,
    example: "deg/h, deg/s, rad/s",
};

impl Source<'_> {
    fn quantity(&self, v: &Value, field: Field) -> anyhow::Result<f64> {
        let span = v.span();
        let q = match v.get_ref() {
            toml::Value::String(s) => parse_quantity(s)
                .map_err(|e| self.error(&span, format!("`{}`: {e}", field.name)))?,
            toml::Value::Float(x) if field.dim == Dim::ONE => unit::Quantity {
                si: *x,
                dim: Dim::ONE,
            },
            toml::Value::Integer(x) if field.dim == Dim::ONE => unit::Quantity {
                si: *x as f64,
                dim: Dim::ONE,
            },
            other => {
                return Err(self.error(
                    &span,
                    format!(
                        "`{}` = {other}: give a value with its unit as a string, e.g. \"1.5 {}\"",
                        field.name,
                        field.example.split(',').next().unwrap_or("")
                    ),
                ))
            }
        };
        // Misalignments may be written as angles (small-angle: rad = ratio).
        let dim_ok = q.dim == field.dim || (field.dim == Dim::ONE && q.dim == Dim::ANGLE);
        if !dim_ok {
            return Err(self.error(
                &span,
                format!(
                    "`{}`: the unit has dimension {}, but this field needs {} (units such as {})",
                    field.name, q.dim, field.dim, field.example
                ),
            ));
        }
        if !q.si.is_finite() {
            return Err(self.error(&span, format!("`{}` is not a finite number", field.name)));
        }
        if !field.signed && q.si < 0.0 {
            return Err(self.error(
                &span,
                format!("`{}` = {} must not be negative", field.name, v.get_ref()),
            ));
        }
        Ok(q.si)
    }

    /// One quantity for all three axes, or an array of three.
    fn per_axis(&self, v: &Value, field: Field) -> anyhow::Result<[f64; 3]> {
        match v.get_ref() {
            toml::Value::Array(items) => {
                if items.len() != 3 {
                    return Err(self.error(
                        &v.span(),
                        format!(
                            "`{}` has {} values; give one or three (x, y, z)",
                            field.name,
                            items.len()
                        ),
                    ));
                }
                let mut out = [0.0; 3];
                for (o, item) in out.iter_mut().zip(items) {
                    *o = self.quantity(&Spanned::new(v.span(), item.clone()), field)?;
                }
                Ok(out)
            }
            _ => Ok([self.quantity(v, field)?; 3]),
        }
    }

    /// A 3×3 matrix: one quantity (times I), three (diagonal) or three rows of three.
    fn matrix(&self, v: &Value, field: Field) -> anyhow::Result<[[f64; 3]; 3]> {
        if let toml::Value::Array(rows) = v.get_ref() {
            if rows.iter().all(|r| r.is_array()) {
                if rows.len() != 3 {
                    return Err(self.error(&v.span(), format!("`{}` needs three rows", field.name)));
                }
                let mut m = [[0.0; 3]; 3];
                for (mi, row) in m.iter_mut().zip(rows) {
                    *mi = self.per_axis(&Spanned::new(v.span(), row.clone()), field)?;
                }
                return Ok(m);
            }
        }
        let d = self.per_axis(v, field)?;
        Ok([[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]])
    }

    fn finite(&self, v: &Spanned<f64>, name: &str) -> anyhow::Result<f64> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(&v.span(), format!("`{name}` = {x} is not a finite number")))
        }
    }

    fn non_negative(&self, v: &Spanned<f64>, name: &str) -> anyhow::Result<f64> {
        let x = self.finite(v, name)?;
        if x < 0.0 {
            Err(self.error(&v.span(), format!("`{name}` = {x} must not be negative")))
        } else {
            Ok(x)
        }
    }

    fn positive(&self, v: &Spanned<f64>, name: &str) -> anyhow::Result<f64> {
        let x = self.finite(v, name)?;
        if x <= 0.0 {
            Err(self.error(&v.span(), format!("`{name}` = {x} must be positive")))
        } else {
            Ok(x)
        }
    }
}

fn field(name: &'static str, dim: Dim, example: &'static str, signed: bool) -> Field {
    Field {
        name,
        dim,
        example,
        signed,
    }
}

fn required<'a, T>(
    src: &Source,
    v: &'a Option<T>,
    name: &str,
    kind_span: &Range<usize>,
    kind: &str,
) -> anyhow::Result<&'a T> {
    v.as_ref()
        .ok_or_else(|| src.error(kind_span, format!("motion kind \"{kind}\" needs `{name}`")))
}

impl Source<'_> {
    fn motion(&self, m: &MotionFile) -> anyhow::Result<Motion> {
        let kind = m.kind.get_ref().as_str();
        let ks = m.kind.span();
        let attitude = || -> anyhow::Result<[f64; 3]> {
            Ok(match &m.attitude_deg {
                Some(a) => {
                    let v = *a.get_ref();
                    if v.iter().any(|x| !x.is_finite()) {
                        return Err(self.error(&a.span(), "`attitude_deg` must be finite"));
                    }
                    v.map(deg_to_rad)
                }
                None => [0.0; 3],
            })
        };
        // Fields that belong to other kinds are an error, not silently ignored.
        let allowed: &[&str] = match kind {
            "static" => &["attitude_deg"],
            "rate-table" => &["axis", "rate"],
            "tumble" => &["positions", "dwell_s", "transition_s"],
            "vibration" => &["attitude_deg", "direction", "amplitude", "frequency_hz"],
            _ => {
                return Err(self.error(
                    &ks,
                    format!("unknown motion kind \"{kind}\" (expected static, rate-table, tumble or vibration)"),
                ))
            }
        };
        let present: [(&str, Option<Range<usize>>); 9] = [
            ("attitude_deg", m.attitude_deg.as_ref().map(|v| v.span())),
            ("axis", m.axis.as_ref().map(|v| v.span())),
            ("rate", m.rate.as_ref().map(|v| v.span())),
            ("positions", m.positions.as_ref().map(|v| v.span())),
            ("dwell_s", m.dwell_s.as_ref().map(|v| v.span())),
            ("transition_s", m.transition_s.as_ref().map(|v| v.span())),
            ("direction", m.direction.as_ref().map(|v| v.span())),
            ("amplitude", m.amplitude.as_ref().map(|v| v.span())),
            ("frequency_hz", m.frequency_hz.as_ref().map(|v| v.span())),
        ];
        for (name, span) in present {
            if let Some(span) = span {
                if !allowed.contains(&name) {
                    return Err(self.error(
                        &span,
                        format!("`{name}` does not apply to motion kind \"{kind}\""),
                    ));
                }
            }
        }
        Ok(match kind {
            "static" => Motion::Static {
                attitude: attitude()?,
            },
            "rate-table" => {
                let axis = required(self, &m.axis, "axis", &ks, kind)?;
                let rate = required(self, &m.rate, "rate", &ks, kind)?;
                Motion::RateTable {
                    axis: parse_axis(axis.get_ref()).ok_or_else(|| {
                        self.error(
                            &axis.span(),
                            format!(
                                "axis \"{}\": expected one of +x, -x, +y, -y, +z, -z",
                                axis.get_ref()
                            ),
                        )
                    })?,
                    rate: self
                        .quantity(rate, field("rate", Dim::RATE, "deg/s, rad/s, dps", true))?,
                }
            }
            "tumble" => {
                let p = required(self, &m.positions, "positions", &ks, kind)?;
                if !matches!(*p.get_ref(), 6 | 12 | 24) {
                    return Err(self.error(
                        &p.span(),
                        format!("positions = {}: expected 6, 12 or 24", p.get_ref()),
                    ));
                }
                Motion::Tumble {
                    positions: *p.get_ref(),
                    dwell: self
                        .positive(required(self, &m.dwell_s, "dwell_s", &ks, kind)?, "dwell_s")?,
                    transition: self.non_negative(
                        required(self, &m.transition_s, "transition_s", &ks, kind)?,
                        "transition_s",
                    )?,
                }
            }
            _ => {
                let d = required(self, &m.direction, "direction", &ks, kind)?;
                let direction = *d.get_ref();
                if direction.iter().any(|x| !x.is_finite()) || direction == [0.0; 3] {
                    return Err(
                        self.error(&d.span(), "`direction` must be a finite, non-zero vector")
                    );
                }
                Motion::Vibration {
                    attitude: attitude()?,
                    direction,
                    amplitude: self.quantity(
                        required(self, &m.amplitude, "amplitude", &ks, kind)?,
                        field("amplitude", Dim::ACCEL, "g, mg, m/s^2", false),
                    )?,
                    frequency: self.non_negative(
                        required(self, &m.frequency_hz, "frequency_hz", &ks, kind)?,
                        "frequency_hz",
                    )?,
                }
            }
        })
    }

    fn temperature(&self, t: &TemperatureFile) -> anyhow::Result<TemperatureProfile> {
        let ks = t.kind.span();
        fn need<'a>(
            src: &Source,
            v: &'a Option<Spanned<f64>>,
            name: &str,
            t: &TemperatureFile,
        ) -> anyhow::Result<&'a Spanned<f64>> {
            v.as_ref().ok_or_else(|| {
                src.error(
                    &t.kind.span(),
                    format!("temperature kind \"{}\" needs `{name}`", t.kind.get_ref()),
                )
            })
        }
        let need = |v, name| need(self, v, name, t);
        match t.kind.get_ref().as_str() {
            "constant" => Ok(TemperatureProfile::Constant(
                self.finite(need(&t.celsius, "celsius")?, "celsius")?,
            )),
            "ramp" => Ok(TemperatureProfile::Ramp {
                from: self.finite(need(&t.from_c, "from_c")?, "from_c")?,
                to: self.finite(need(&t.to_c, "to_c")?, "to_c")?,
                start: match &t.start_s {
                    Some(s) => self.non_negative(s, "start_s")?,
                    None => 0.0,
                },
                duration: self.non_negative(need(&t.duration_s, "duration_s")?, "duration_s")?,
            }),
            other => Err(self.error(
                &ks,
                format!("unknown temperature kind \"{other}\" (expected constant or ramp)"),
            )),
        }
    }

    fn triad(&self, t: &TriadFile, kind: TriadKind) -> anyhow::Result<TriadEffects> {
        let q = kind.dim;
        let ex = kind.example;
        let mut e = match &t.grade {
            None => TriadEffects::NONE,
            Some(g) => {
                let name = g.get_ref().as_str();
                let effects = if kind.name == "gyro" {
                    GyroGrade::from_name(name).map(GyroGrade::effects)
                } else {
                    AccelGrade::from_name(name).map(AccelGrade::effects)
                };
                effects.ok_or_else(|| {
                    let names: Vec<&str> = if kind.name == "gyro" {
                        GyroGrade::ALL.iter().map(|g| g.name()).collect()
                    } else {
                        AccelGrade::ALL.iter().map(|g| g.name()).collect()
                    };
                    self.error(
                        &g.span(),
                        format!(
                            "unknown {} grade \"{name}\" (expected {})",
                            kind.name,
                            names.join(", ")
                        ),
                    )
                })?
            }
        };
        let density_ex = if kind.name == "gyro" {
            "deg/sqrt(h), deg/s/sqrt(Hz)"
        } else {
            "ug/sqrt(Hz), m/s/sqrt(h)"
        };
        let rw_ex = if kind.name == "gyro" {
            "deg/h/sqrt(h), deg/s/sqrt(s)"
        } else {
            "m/s/h/sqrt(h), ug/sqrt(s)"
        };
        if let Some(v) = &t.white_noise {
            e.white_noise =
                Some(self.per_axis(v, field("white_noise", q.per_sqrt_hz(), density_ex, false))?);
        }
        if let Some(v) = &t.random_walk {
            e.random_walk =
                Some(self.per_axis(v, field("random_walk", q.per_sqrt_s(), rw_ex, false))?);
        }
        if let Some(v) = &t.bias {
            e.constant_bias = Some(self.per_axis(v, field("bias", q, ex, true))?);
        }
        if let Some(v) = &t.turn_on_bias {
            e.turn_on_bias = Some(self.per_axis(v, field("turn_on_bias", q, ex, false))?);
        }
        if let Some(v) = &t.turn_on_scale {
            e.turn_on_scale =
                Some(self.per_axis(v, field("turn_on_scale", Dim::ONE, "ppm, %", false))?);
        }
        if t.scale_factor.is_some() || t.misalignment.is_some() {
            let mut sigma = [[0.0; 3]; 3];
            if let Some(v) = &t.misalignment {
                let m = self.matrix(v, field("misalignment", Dim::ONE, "mrad, deg, ppm", true))?;
                if (0..3).any(|i| m[i][i] != 0.0) {
                    return Err(self.error(
                        &v.span(),
                        "`misalignment` must have a zero diagonal (scale factors go in `scale_factor`)",
                    ));
                }
                sigma = m;
            }
            if let Some(v) = &t.scale_factor {
                let s = self.per_axis(v, field("scale_factor", Dim::ONE, "ppm, %", true))?;
                for (i, si) in s.into_iter().enumerate() {
                    sigma[i][i] = si;
                }
            }
            e.scale_misalignment = Some(sigma);
        }
        if let Some(v) = &t.g_sensitivity {
            if kind.name != "gyro" {
                return Err(self.error(
                    &v.span(),
                    "`g_sensitivity` is a gyro effect; accelerometers cannot have it",
                ));
            }
            e.g_sensitivity = Some(self.matrix(
                v,
                field(
                    "g_sensitivity",
                    Dim::RATE.div(Dim::ACCEL),
                    "deg/s/g, deg/h/g",
                    true,
                ),
            )?);
        }
        if let Some(v) = &t.quantisation {
            e.quantisation = Some(self.per_axis(v, field("quantisation", q, ex, false))?);
        }
        if let Some(v) = &t.saturation {
            let r = self.per_axis(v, field("saturation", q, ex, false))?;
            if r.iter().any(|&x| x <= 0.0) {
                return Err(self.error(
                    &v.span(),
                    "`saturation` (the measurement range) must be positive",
                ));
            }
            e.saturation = Some(r);
        }
        if let Some(gm) = &t.gauss_markov {
            e.gauss_markov = Some(GaussMarkovParams {
                sigma: self.per_axis(&gm.sigma, field("gauss_markov.sigma", q, ex, false))?,
                correlation_time: {
                    let tc = self.per_axis(
                        &gm.correlation_time,
                        field(
                            "gauss_markov.correlation_time",
                            Dim::TIME,
                            "s, min, h",
                            false,
                        ),
                    )?;
                    if tc.iter().any(|&x| x <= 0.0) {
                        return Err(self.error(
                            &gm.correlation_time.span(),
                            "`correlation_time` must be positive",
                        ));
                    }
                    tc
                },
            });
        }
        if let Some(bi) = &t.bias_instability {
            let b = self.per_axis(&bi.value, field("bias_instability.value", q, ex, false))?;
            let mut p = BiasInstabilityParams::with_default_band(0.0);
            if let Some(band) = &bi.band_s {
                let [lo, hi] = *band.get_ref();
                if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo) {
                    return Err(self.error(
                        &band.span(),
                        format!("band_s = [{lo}, {hi}]: need 0 < shortest ≤ longest (seconds)"),
                    ));
                }
                p.tau_min = lo;
                p.tau_max = hi;
            }
            if let Some(n) = &bi.terms {
                let n_terms = *n.get_ref();
                if n_terms == 0 || n_terms as usize > MAX_TERMS {
                    return Err(self.error(
                        &n.span(),
                        format!("terms = {n_terms}: expected 1..={MAX_TERMS}"),
                    ));
                }
                p.terms = n_terms;
            }
            e.bias_instability = Some(b.map(|b| BiasInstabilityParams { b, ..p }));
        }
        if let Some(td) = &t.temperature {
            e.temperature = Some(TemperatureDependence {
                reference: self.finite(&td.reference_c, "reference_c")?,
                bias_per_degree: match &td.bias {
                    Some(v) => self.per_axis(
                        v,
                        field(
                            "temperature.bias",
                            q.per_kelvin(),
                            "ug/degC, deg/h/degC",
                            true,
                        ),
                    )?,
                    None => [0.0; 3],
                },
                scale_per_degree: match &td.scale {
                    Some(v) => self.per_axis(
                        v,
                        field("temperature.scale", Dim::ONE.per_kelvin(), "ppm/degC", true),
                    )?,
                    None => [0.0; 3],
                },
            });
        }
        Ok(e)
    }
}

fn parse_axis(s: &str) -> Option<Axis> {
    Some(match s {
        "+x" | "x" => Axis::PlusX,
        "-x" => Axis::MinusX,
        "+y" | "y" => Axis::PlusY,
        "-y" => Axis::MinusY,
        "+z" | "z" => Axis::PlusZ,
        "-z" => Axis::MinusZ,
        _ => return None,
    })
}

/// Parses scene text (from `path`, used in messages).
pub fn parse(text: &str, path: &Path) -> anyhow::Result<LoadedScene> {
    let src = Source { path, text };
    let file: SceneFile = toml::from_str(text).map_err(|e| match e.span() {
        Some(span) => src.error(&span, e.message()),
        None => anyhow!("{}: {}", path.display(), e.message()),
    })?;
    let rate_hz = src.positive(&file.rate_hz, "rate_hz")?;
    let duration_s = file
        .duration_s
        .as_ref()
        .map(|d| src.positive(d, "duration_s"))
        .transpose()?;
    let gravity = match &file.gravity {
        Some(g) => {
            let g = src.quantity(g, field("gravity", Dim::ACCEL, "m/s^2, g", false))?;
            if g <= 0.0 {
                bail!(
                    "{}: gravity must be positive",
                    src.position(&file.gravity.as_ref().map(|g| g.span()).unwrap_or(0..0))
                );
            }
            g
        }
        None => STANDARD_GRAVITY,
    };
    let latitude = file
        .latitude_deg
        .as_ref()
        .map(|l| {
            let x = src.finite(l, "latitude_deg")?;
            if x.abs() > 90.0 {
                return Err(src.error(&l.span(), format!("latitude_deg = {x} is outside −90..90")));
            }
            Ok(deg_to_rad(x))
        })
        .transpose()?;
    let scene = Scene {
        rate_hz,
        motion: src.motion(&file.motion)?,
        environment: Environment { gravity, latitude },
        temperature: match &file.temperature {
            Some(t) => src.temperature(t)?,
            None => TemperatureProfile::Constant(25.0),
        },
        accel: match &file.accel {
            Some(t) => src.triad(t, ACCEL)?,
            None => TriadEffects::NONE,
        },
        gyro: match &file.gyro {
            Some(t) => src.triad(t, GYRO)?,
            None => TriadEffects::NONE,
        },
    };
    // The core's own check, as a backstop (its message names the value).
    scene
        .validate()
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(LoadedScene {
        scene,
        duration_s,
        path: path.to_path_buf(),
    })
}

/// Where shipped scenes live: `scenes/` under the current directory, then
/// under the repository root this binary was built from.
pub fn scene_dirs() -> Vec<PathBuf> {
    vec![
        PathBuf::from("scenes"),
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join("scenes"),
    ]
}

/// Resolves NAME (a shipped scene) or FILE (a path) and loads it.
pub fn load(name_or_file: &str) -> anyhow::Result<LoadedScene> {
    let as_path = Path::new(name_or_file);
    let path =
        if as_path.is_file() {
            as_path.to_path_buf()
        } else {
            let candidates: Vec<PathBuf> = scene_dirs()
                .into_iter()
                .map(|d| d.join(format!("{name_or_file}.toml")))
                .collect();
            match candidates.iter().find(|p| p.is_file()) {
                Some(p) => p.clone(),
                None => {
                    bail!(
                "scene `{name_or_file}` is neither a file nor a shipped scene (looked for {})",
                candidates.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
            )
                }
            }
        };
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading scene {}", path.display()))?;
    parse(&text, &path)
}
