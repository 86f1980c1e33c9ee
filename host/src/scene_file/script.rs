//! Script files: what happens to a simulated [unit](super::sensor_unit),
//! its motion, environment, temperature, sample rate and length: a scene
//! without `[accel]` and `[gyro]`. `triad sim --unit U --script S` runs one.

use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use super::parse::{MotionFile, SceneFile, Source, TemperatureFile, Value};
use super::LoadedScene;
use crate::plumbing::shipped;

/// A script file's keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptFile {
    description: Option<String>,
    rate_hz: Spanned<f64>,
    duration_s: Option<Spanned<f64>>,
    gravity: Option<Value>,
    latitude_deg: Option<Spanned<f64>>,
    motion: MotionFile,
    temperature: Option<TemperatureFile>,
}

/// Where a unit's key found in a script belongs.
fn hint(key: &str) -> Option<&'static str> {
    match key {
        "accel" | "gyro" => Some(
            "the sensor's effects are the unit's (--unit UNIT.toml); a script says what happens to it",
        ),
        "seed" => Some(
            "the turn-on errors' seed is the unit file's; each record's noise is --record-seed",
        ),
        _ => None,
    }
}

/// Parses script text (from `path`, used in messages): a scene whose
/// triads have no effects, for a unit's to be put in.
pub fn parse(text: &str, path: &Path) -> anyhow::Result<LoadedScene> {
    let src = Source { path, text };
    let file: ScriptFile = src.read_as(hint)?;
    let file = SceneFile {
        description: file.description,
        rate_hz: file.rate_hz,
        duration_s: file.duration_s,
        gravity: file.gravity,
        latitude_deg: file.latitude_deg,
        motion: file.motion,
        temperature: file.temperature,
        accel: None,
        gyro: None,
    };
    super::built(src, &file)
}

/// Loads NAME (a shipped script) or FILE, by the rule of [`crate::plumbing::shipped`].
pub fn load(name_or_file: &str) -> anyhow::Result<LoadedScene> {
    super::load_shipped_or_file(name_or_file, "script", shipped::SCRIPTS, parse)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad_sim::motion::Motion;
    use triad_sim::scenes::temperature_profile::TemperatureProfile;

    fn error(text: &str) -> String {
        parse(text, Path::new("s.toml")).unwrap_err().to_string()
    }

    #[test]
    fn a_script_is_a_scene_without_triads() {
        let text = "rate_hz = 50.0\nduration_s = 9.0\n[motion]\nkind = \"hand\"\nposes = 12\nseed = 3\ndwell_s = 2.0\nturn_s = 1.5\n[temperature]\nkind = \"soak\"\nlevels_c = [-10.0, 25.0, 60.0]\nhold_s = 3.0\n";
        let s = parse(text, Path::new("s.toml")).unwrap();
        assert_eq!(s.duration_s, Some(9.0));
        assert_eq!(
            s.scene.motion,
            Motion::Hand {
                poses: 12,
                seed: 3,
                dwell: 2.0,
                turn: 1.5
            }
        );
        assert!(matches!(
            s.scene.temperature,
            TemperatureProfile::Soak {
                count: 3,
                hold: 3.0,
                ..
            }
        ));
        assert!(s.scene.accel.is_none() && s.scene.gyro.is_none());
    }

    #[test]
    fn what_is_not_a_scripts_is_refused_with_where_it_belongs() {
        let hand =
            "rate_hz = 50.0\n[motion]\nkind = \"hand\"\nseed = 1\ndwell_s = 2.0\nturn_s = 1.0\n";
        let e = error(&format!("{hand}poses = 24\n[gyro]\ngrade = \"tactical\"\n"));
        assert!(e.starts_with("s.toml:8:2: unknown field `gyro`"), "{e}");
        assert!(e.ends_with("the sensor's effects are the unit's (--unit UNIT.toml); a script says what happens to it"), "{e}");
        let e = error(&format!("seed = 4\n{hand}poses = 24\n"));
        assert!(e.ends_with("each record's noise is --record-seed"), "{e}");
        let e = error(&format!("{hand}poses = 11\n"));
        assert_eq!(e, "s.toml:7:9: poses = 11: expected 12..=24 (a rig-free fit wants at least 12 gravity directions)");
        let e = error(&format!("{hand}poses = 12\nturn_s = 0.0\n").replace("turn_s = 1.0\n", ""));
        assert_eq!(e, "s.toml:7:10: `turn_s` = 0 must be positive");
        let e = error("rate_hz = 1.0\n[motion]\nkind = \"hand\"\nposes = 12\n");
        assert_eq!(e, "s.toml:3:8: motion kind \"hand\" needs `seed`");
        let set = "rate_hz = 1.0\n[motion]\nkind = \"rate-table-set\"\nrate = \"30 deg/s\"\n";
        let e = error(&format!("{set}run_s = 10.0\nrest_s = -1.0\n"));
        assert_eq!(e, "s.toml:6:10: `rest_s` = -1 must not be negative");
        let e = error(&format!("{set}run_s = 10.0\nrest_s = 1.0\naxis = \"z\"\n"));
        assert_eq!(
            e,
            "s.toml:7:8: `axis` does not apply to motion kind \"rate-table-set\""
        );
        let soak = "rate_hz = 1.0\n[motion]\nkind = \"static\"\n[temperature]\nkind = \"soak\"\nhold_s = 1.0\n";
        let e = error(&format!("{soak}levels_c = [1.0]\n"));
        assert_eq!(
            e,
            "s.toml:7:12: levels_c has 1 temperatures: a soak has 2..=4"
        );
        let e = error(&format!("{soak}levels_c = [1.0, nan]\n"));
        assert_eq!(e, "s.toml:7:12: `levels_c` must be finite temperatures");
        let e = error("rate_hz = 1.0\n[motion]\nkind = \"static\"\n[temperature]\nkind = \"soak\"\nlevels_c = [1.0, 2.0]\n");
        assert_eq!(e, "s.toml:5:8: temperature kind \"soak\" needs `hold_s`");
    }
}
