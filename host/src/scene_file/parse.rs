//! TOML → raw fields: the shape of a scene file (unknown keys and wrong
//! types are errors here), each value with its byte span, and the
//! [`Source`] that turns spans into `path:line:column` messages.

use std::ops::Range;
use std::path::Path;

use anyhow::anyhow;
use serde::Deserialize;
use toml::Spanned;

/// A value whose type depends on the field (a quantity with its unit, a
/// number, an array of either).
pub(super) type Value = Spanned<toml::Value>;

/// The file's top level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneFile {
    #[allow(dead_code)]
    pub description: Option<String>,
    pub rate_hz: Spanned<f64>,
    pub duration_s: Option<Spanned<f64>>,
    pub gravity: Option<Value>,
    pub latitude_deg: Option<Spanned<f64>>,
    pub motion: MotionFile,
    pub temperature: Option<TemperatureFile>,
    pub accel: Option<TriadFile>,
    pub gyro: Option<TriadFile>,
}

/// `[motion]`: the fields of every kind (each kind allows its own).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MotionFile {
    pub kind: Spanned<String>,
    pub attitude_deg: Option<Spanned<[f64; 3]>>,
    pub axis: Option<Spanned<String>>,
    pub rate: Option<Value>,
    pub positions: Option<Spanned<u8>>,
    pub dwell_s: Option<Spanned<f64>>,
    pub transition_s: Option<Spanned<f64>>,
    pub direction: Option<Spanned<[f64; 3]>>,
    pub amplitude: Option<Value>,
    pub frequency_hz: Option<Spanned<f64>>,
    pub poses: Option<Spanned<u8>>,
    pub seed: Option<Spanned<u64>>,
    pub turn_s: Option<Spanned<f64>>,
    pub run_s: Option<Spanned<f64>>,
    pub rest_s: Option<Spanned<f64>>,
}

/// `[temperature]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TemperatureFile {
    pub kind: Spanned<String>,
    pub celsius: Option<Spanned<f64>>,
    pub from_c: Option<Spanned<f64>>,
    pub to_c: Option<Spanned<f64>>,
    pub start_s: Option<Spanned<f64>>,
    pub duration_s: Option<Spanned<f64>>,
    pub levels_c: Option<Spanned<Vec<f64>>>,
    pub hold_s: Option<Spanned<f64>>,
}

/// `[accel]` or `[gyro]`: a grade preset and the effects that override it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TriadFile {
    pub grade: Option<Spanned<String>>,
    pub white_noise: Option<Value>,
    pub random_walk: Option<Value>,
    pub bias: Option<Value>,
    pub turn_on_bias: Option<Value>,
    pub scale_factor: Option<Value>,
    pub turn_on_scale: Option<Value>,
    pub misalignment: Option<Value>,
    pub g_sensitivity: Option<Value>,
    pub angle_quantisation: Option<Value>,
    pub velocity_quantisation: Option<Value>,
    pub output_lsb: Option<Value>,
    /// The old name of `output_lsb`, still read.
    pub quantisation: Option<Value>,
    pub saturation: Option<Value>,
    /// A unit file's key (σ of the misalignment drawn once from the unit's
    /// seed); a scene refuses it.
    pub turn_on_misalignment: Option<Value>,
    pub gauss_markov: Option<GaussMarkovFile>,
    pub bias_instability: Option<BiasInstabilityFile>,
    pub temperature: Option<TemperatureDependenceFile>,
    pub ring_laser: Option<RingLaserFile>,
    pub fibre_optic: Option<FibreOpticFile>,
}

/// `[gyro.ring_laser]`: a ring laser gyro's cavity, lock-in and dither.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RingLaserFile {
    pub area: Value,
    pub path_length: Value,
    pub wavelength: Option<Value>,
    pub lock_in: Value,
    pub dither_rate: Option<Value>,
    pub dither_frequency_hz: Option<Spanned<f64>>,
}

/// `[gyro.fibre_optic]`: a fibre-optic gyro's coil, source and readout.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FibreOpticFile {
    pub turns: Spanned<f64>,
    pub coil_diameter: Value,
    pub wavelength: Value,
    pub readout: Spanned<String>,
    pub reference_c: Option<Spanned<f64>>,
    pub area_per_degree: Option<Value>,
    pub wavelength_per_degree: Option<Value>,
}

/// `[accel.gauss_markov]`, `[gyro.gauss_markov]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GaussMarkovFile {
    pub sigma: Value,
    pub correlation_time: Value,
}

/// `[accel.bias_instability]`, `[gyro.bias_instability]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BiasInstabilityFile {
    pub value: Value,
    pub band_s: Option<Spanned<[f64; 2]>>,
    pub terms: Option<Spanned<u8>>,
}

/// `[accel.temperature]`, `[gyro.temperature]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TemperatureDependenceFile {
    pub reference_c: Spanned<f64>,
    pub bias: Option<Value>,
    pub scale: Option<Value>,
}

/// The file's text and path: turns byte spans into "path:line:column" messages.
pub(super) struct Source<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl Source<'_> {
    /// "path:line:column" of the span's start.
    pub fn position(&self, span: &Range<usize>) -> String {
        let before = &self.text[..span.start.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!("{}:{line}:{column}", self.path.display())
    }

    /// "path:line:column: message".
    pub fn error(&self, span: &Range<usize>, message: impl std::fmt::Display) -> anyhow::Error {
        anyhow!("{}: {message}", self.position(span))
    }

    /// The file's fields; TOML errors (syntax, unknown keys, wrong types) at their position.
    pub fn read(&self) -> anyhow::Result<SceneFile> {
        self.read_as(|_| None)
    }

    /// The fields of a file of shape `T`; an unknown key's error gains
    /// `hint(key)` when there is one (where the key belongs instead).
    pub fn read_as<T: serde::de::DeserializeOwned>(
        &self,
        hint: impl Fn(&str) -> Option<&'static str>,
    ) -> anyhow::Result<T> {
        toml::from_str(self.text).map_err(|e| {
            let mut message = e.message().to_string();
            let unknown = message
                .strip_prefix("unknown field `")
                .and_then(|rest| rest.split('`').next());
            if let Some(h) = unknown.and_then(&hint) {
                message = format!("{message}; {h}");
            }
            match e.span() {
                Some(span) => self.error(&span, message),
                None => anyhow!("{}: {message}", self.path.display()),
            }
        })
    }

    /// A plain number that must be finite and positive (a field the scene
    /// itself does not hold, such as the file's default `duration_s`).
    pub fn positive(&self, v: &Spanned<f64>, name: &str) -> anyhow::Result<f64> {
        let x = *v.get_ref();
        if !x.is_finite() {
            Err(self.error(&v.span(), format!("`{name}` = {x} is not a finite number")))
        } else if x <= 0.0 {
            Err(self.error(&v.span(), format!("`{name}` = {x} must be positive")))
        } else {
            Ok(x)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(text: &str) -> Source<'_> {
        Source {
            path: Path::new("s.toml"),
            text,
        }
    }

    #[test]
    fn spans_become_lines_and_columns() {
        let src = source("a = 1\nbé = 2\n");
        assert_eq!(src.position(&(0..1)), "s.toml:1:1");
        // Columns count characters, not bytes.
        assert_eq!(src.position(&(12..13)), "s.toml:2:6");
        assert_eq!(src.position(&(999..1000)), "s.toml:3:1");
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_errors_at_their_place() {
        let text = "rate_hz = 1.0\n[motion]\nkind = \"static\"\nspin = 1\n";
        let err = source(text).read().err().unwrap().to_string();
        assert!(err.starts_with("s.toml:4:1: unknown field `spin`"), "{err}");
        let err = source("rate_hz = \"fast\"\n")
            .read()
            .err()
            .unwrap()
            .to_string();
        assert!(err.starts_with("s.toml:1:11: invalid type"), "{err}");
        let file = source("rate_hz = 5.0\n[motion]\nkind = \"static\"\n")
            .read()
            .unwrap();
        assert_eq!(*file.rate_hz.get_ref(), 5.0);
        assert!(file.gyro.is_none());
    }

    #[test]
    fn positive_numbers_are_checked() {
        let src = source("x = 0.0");
        let v = |x: f64| Spanned::new(4..7, x);
        assert_eq!(src.positive(&v(2.5), "x").unwrap(), 2.5);
        let zero = src.positive(&v(0.0), "x").unwrap_err().to_string();
        assert_eq!(zero, "s.toml:1:5: `x` = 0 must be positive");
        let inf = src.positive(&v(f64::INFINITY), "x").unwrap_err();
        assert_eq!(
            inf.to_string(),
            "s.toml:1:5: `x` = inf is not a finite number"
        );
    }
}
