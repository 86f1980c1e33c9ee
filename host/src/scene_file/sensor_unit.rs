//! Unit files: one simulated sensor, separate from what happens to it (a
//! [script](super::script)). A unit names its triads' effects as a scene's
//! `[accel]` and `[gyro]` do, plus `turn_on_misalignment`, and a `seed` from
//! which its turn-on errors (bias, scale factor, misalignment) are drawn
//! once: every record of the unit shares them, whatever its noise.
//!
//! ```toml
//! description = "Tactical MEMS IMU, serial 1"
//! seed = 1                               # the turn-on errors
//! [gyro]
//! grade = "tactical"
//! turn_on_bias = "20 deg/h"
//! turn_on_misalignment = "1 mrad"        # σ of each off-diagonal term
//! [gyro.temperature]
//! reference_c = 25.0
//! bias = "1 deg/h/degC"
//! ```

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;
use triad::model::Triad;
use triad_sim::effects::turn_on::fix_turn_on;
use triad_sim::motion::Motion;
use triad_sim::scenes::scene::{Scene, TriadEffects};

use super::build::Builder;
use super::field::field;
use super::parse::{Source, TriadFile};
use super::unit::Dim;
use crate::plumbing::shipped;

/// A unit file's keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UnitFile {
    #[allow(dead_code)]
    description: Option<String>,
    seed: Spanned<u64>,
    accel: Option<TriadFile>,
    gyro: Option<TriadFile>,
}

/// Where a scene's key found in a unit file belongs.
fn hint(key: &str) -> Option<&'static str> {
    matches!(
        key,
        "rate_hz" | "duration_s" | "gravity" | "latitude_deg" | "motion" | "temperature"
    )
    .then_some(
        "that is a script's key (--script): a unit file holds `seed`, `[accel]` and `[gyro]`",
    )
}

/// A loaded unit: its effects with the turn-on errors drawn from its seed
/// and held (no turn-on effect is left to draw per record).
#[derive(Clone, Debug)]
pub struct LoadedUnit {
    /// The accelerometers' effects.
    pub accel: TriadEffects,
    /// The gyros' effects.
    pub gyro: TriadEffects,
    /// The seed the turn-on errors were drawn from.
    pub seed: u64,
    /// Where it came from.
    pub path: PathBuf,
}

/// Parses unit text (from `path`, used in messages).
pub fn parse(text: &str, path: &Path) -> anyhow::Result<LoadedUnit> {
    let src = Source { path, text };
    let mut file: UnitFile = src.read_as(hint)?;
    let mut builder = Builder::new(src);
    let accel_misalignment = builder.turn_on_misalignment(file.accel.as_mut())?;
    let gyro_misalignment = builder.turn_on_misalignment(file.gyro.as_mut())?;
    let accel = builder.triad_or_none(file.accel.as_ref(), Triad::Accel)?;
    let gyro = builder.triad_or_none(file.gyro.as_ref(), Triad::Gyro)?;
    // The effects are checked as a scene's, at the unit file's positions.
    let check = Scene {
        accel,
        gyro,
        ..Scene::new(1.0, Motion::Static { attitude: [0.0; 3] })
    };
    builder.origins.validate(&builder.src, &check)?;
    let seed = *file.seed.get_ref();
    Ok(LoadedUnit {
        accel: fix_turn_on(&accel, Triad::Accel, accel_misalignment, seed),
        gyro: fix_turn_on(&gyro, Triad::Gyro, gyro_misalignment, seed),
        seed,
        path: path.to_path_buf(),
    })
}

/// Loads NAME (a shipped unit) or FILE, by the rule of [`crate::plumbing::shipped`].
pub fn load(name_or_file: &str) -> anyhow::Result<LoadedUnit> {
    super::load_shipped_or_file(name_or_file, "unit", shipped::UNITS, parse)
}

impl Builder<'_> {
    /// Takes `turn_on_misalignment` out of `t` (the scene's reader refuses
    /// it): σ in radians, not negative.
    fn turn_on_misalignment(&mut self, t: Option<&mut TriadFile>) -> anyhow::Result<Option<f64>> {
        let Some(v) = t.and_then(|t| t.turn_on_misalignment.take()) else {
            return Ok(None);
        };
        let sigma = self.src.quantity(
            &v,
            field("turn_on_misalignment", Dim::ONE, "mrad, deg, ppm"),
        )?;
        if sigma.is_nan() || sigma < 0.0 {
            return Err(self.src.error(
                &v.span(),
                format!("`turn_on_misalignment` = {sigma} rad: a σ must not be negative"),
            ));
        }
        Ok(Some(sigma))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        parse(text, Path::new("u.toml")).unwrap_err().to_string()
    }

    #[test]
    fn a_units_turn_on_errors_come_from_its_seed_and_are_held() {
        let text = |seed: u64| {
            format!("seed = {seed}\n[gyro]\nturn_on_bias = \"10 deg/h\"\nturn_on_scale = \"300 ppm\"\nturn_on_misalignment = \"1 mrad\"\n")
        };
        let a = parse(&text(1), Path::new("u.toml")).unwrap();
        let b = parse(&text(1), Path::new("u.toml")).unwrap();
        let c = parse(&text(2), Path::new("u.toml")).unwrap();
        assert_eq!(a.gyro, b.gyro);
        assert_ne!(a.gyro, c.gyro);
        assert!(a.gyro.turn_on_bias.is_none() && a.gyro.turn_on_scale.is_none());
        let m = a.gyro.scale_misalignment.unwrap();
        assert!(m[0][1] != 0.0 && m[2][1] != 0.0 && m[0][0] != 0.0, "{m:?}");
        assert!(a.gyro.constant_bias.unwrap()[0] != 0.0);
        assert!(a.accel.is_none());
    }

    #[test]
    fn what_is_not_a_units_is_refused_with_where_it_belongs() {
        let e = error("seed = 1\nrate_hz = 100.0\n");
        assert!(e.starts_with("u.toml:2:1: unknown field `rate_hz`"), "{e}");
        assert!(e.ends_with("that is a script's key (--script): a unit file holds `seed`, `[accel]` and `[gyro]`"), "{e}");
        let e = error("[gyro]\ngrade = \"tactical\"\n");
        assert!(e.contains("missing field `seed`"), "{e}");
        let e = error("seed = 1\n[gyro]\nwhite_noise = \"-1 deg/sqrt(h)\"\n");
        assert_eq!(
            e,
            "u.toml:3:15: `white_noise` = \"-1 deg/sqrt(h)\" must not be negative"
        );
        let e = error("seed = 1\n[accel]\nturn_on_misalignment = \"-1 mrad\"\n");
        assert_eq!(
            e,
            "u.toml:3:24: `turn_on_misalignment` = -0.001 rad: a σ must not be negative"
        );
        let e = error("seed = -1\n");
        assert!(e.starts_with("u.toml:1:8: "), "{e}");
    }
}
