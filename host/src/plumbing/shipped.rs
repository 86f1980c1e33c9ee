//! What the `triad` binary carries, so that an installed or copied binary
//! needs no source checkout: the shipped scenes, scripts and units (every
//! `scenes/*.toml`, `scenes/scripts/*.toml`, `scenes/units/*.toml`, embedded
//! by `build.rs`) and the default calibration
//! (`calibrations/default.toml`); and the one rule by which a command-line
//! argument names a file or one of these.
//!
//! The rule ([`locate`]): an argument that is an existing file is that file.
//! Otherwise a bare name (no `/`, not ending in `.toml`) is looked up among
//! the shipped ones; anything else is a path, and reading it gives the
//! error. So `static-bench` is the shipped scene unless a file named
//! `static-bench` is in the current directory, and `scenes/static-bench.toml`
//! is always the file.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use triad_sim::grade::{AccelPreset, GyroPreset};

include!(concat!(env!("OUT_DIR"), "/shipped_scenes.rs"));

/// The shipped calibrations: (name, TOML text). `default` is the one the
/// firmware embeds unless told otherwise.
pub const CALIBRATIONS: &[(&str, &str)] = &[(
    "default",
    include_str!("../../../calibrations/default.toml"),
)];

/// Where the text of an argument comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A file on disk.
    File(PathBuf),
    /// A shipped text, by name.
    Shipped {
        /// Its name (`static-bench`, `default`).
        name: &'static str,
        /// Its text.
        text: &'static str,
    },
}

impl Source {
    /// How messages name it: the path, or `shipped:NAME`.
    pub fn shown(&self) -> PathBuf {
        match self {
            Source::File(path) => path.clone(),
            Source::Shipped { name, .. } => PathBuf::from(format!("shipped:{name}")),
        }
    }

    /// Its text; a file that cannot be read is an error naming it.
    pub fn text(&self) -> anyhow::Result<Cow<'static, str>> {
        match self {
            Source::File(path) => std::fs::read_to_string(path)
                .map(Cow::Owned)
                .with_context(|| format!("{}: cannot read", path.display())),
            Source::Shipped { text, .. } => Ok(Cow::Borrowed(text)),
        }
    }
}

/// Applies the rule of this module to `arg`, a `kind` ("scene",
/// "calibration") named on the command line, with `shipped` the texts of
/// that kind.
pub fn locate(
    arg: &Path,
    kind: &str,
    shipped: &[(&'static str, &'static str)],
) -> anyhow::Result<Source> {
    let bare = arg
        .to_str()
        .filter(|s| !s.is_empty() && !s.contains('/') && !s.ends_with(".toml"));
    let Some(name) = bare.filter(|_| !arg.is_file()) else {
        return Ok(Source::File(arg.to_path_buf()));
    };
    match shipped.iter().find(|(n, _)| *n == name) {
        Some(&(name, text)) => Ok(Source::Shipped { name, text }),
        None => bail!(
            "{kind} `{name}`: no such file, and no shipped {kind} of that name (shipped: {}; \
             `triad sim --list` describes them)",
            shipped
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The `description` of a shipped TOML text (empty when it has none).
fn description(text: &str) -> String {
    text.parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("description")?.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// What `triad sim --list` prints: the shipped scenes with their
/// descriptions, the grade presets a scene can name, and the shipped
/// calibrations.
pub fn listing() -> String {
    let width = SCENES
        .iter()
        .chain(SCRIPTS)
        .chain(UNITS)
        .chain(CALIBRATIONS)
        .map(|(n, _)| n.len())
        .max()
        .unwrap_or(0);
    let mut out = String::from("Scenes (triad sim --scene NAME, cargo xtask run --scene NAME):\n");
    for (name, text) in SCENES {
        out.push_str(&format!("  {name:width$}  {}\n", description(text)));
    }
    out.push_str("Scripts (triad sim --unit UNIT --script NAME --record-seed K):\n");
    for (name, text) in SCRIPTS {
        out.push_str(&format!("  {name:width$}  {}\n", description(text)));
    }
    out.push_str("Units (triad sim --unit NAME --script SCRIPT --record-seed K):\n");
    for (name, text) in UNITS {
        out.push_str(&format!("  {name:width$}  {}\n", description(text)));
    }
    let names = |names: Vec<&str>| names.join(", ");
    out.push_str("Grade presets (a scene's `grade` in [gyro] or [accel]):\n");
    out.push_str(&format!(
        "  gyro:  {}\n",
        names(GyroPreset::ALL.iter().map(|p| p.name).collect())
    ));
    out.push_str(&format!(
        "  accel: {}\n",
        names(AccelPreset::ALL.iter().map(|p| p.name).collect())
    ));
    out.push_str(
        "Calibrations (triad correct --calib NAME, triad calib check|pack NAME, calib fit --base NAME):\n",
    );
    for (name, _) in CALIBRATIONS {
        out.push_str(&format!(
            "  {name:width$}  calibrations/{name}.toml of the source, built in\n"
        ));
    }
    out.push_str("A NAME that is an existing file is read from disk instead.\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `*.toml` files of `scenes/` + `sub`: (name, text), sorted.
    fn on_disk(sub: &str) -> Vec<(String, String)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes")
            .join(sub);
        let mut on_disk: Vec<(String, String)> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .map(|p| {
                let name = p.file_stem().unwrap().to_str().unwrap().to_string();
                (name, std::fs::read_to_string(&p).unwrap())
            })
            .collect();
        on_disk.sort();
        on_disk
    }

    /// The tables build.rs writes are the scenes/, scenes/scripts/ and
    /// scenes/units/ directories, every file of them.
    #[test]
    fn every_scene_script_and_unit_file_is_shipped_with_its_text() {
        let owned = |table: &[(&str, &str)]| -> Vec<(String, String)> {
            table
                .iter()
                .map(|(n, t)| (n.to_string(), t.to_string()))
                .collect()
        };
        assert_eq!(owned(SCENES), on_disk(""));
        assert_eq!(owned(SCRIPTS), on_disk("scripts"));
        assert_eq!(owned(UNITS), on_disk("units"));
        assert!(SCENES.iter().any(|(n, _)| *n == "static-bench"));
        assert!(SCRIPTS.iter().any(|(n, _)| *n == "hand-rotations"));
        assert!(UNITS.iter().any(|(n, _)| *n == "tactical-mems"));
    }

    #[test]
    fn a_bare_name_is_shipped_unless_a_file_of_that_name_exists() {
        let found = locate(Path::new("static-bench"), "scene", SCENES).unwrap();
        assert!(matches!(
            found,
            Source::Shipped {
                name: "static-bench",
                ..
            }
        ));
        assert_eq!(found.shown(), PathBuf::from("shipped:static-bench"));

        // A file wins over the shipped name.
        let dir = std::env::temp_dir().join(format!("triad-shipped-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("static-bench");
        std::fs::write(&file, "x").unwrap();
        let found = locate(&file, "scene", SCENES).unwrap();
        assert_eq!(found, Source::File(file.clone()));
        std::fs::remove_dir_all(&dir).unwrap();

        // Path-like arguments are paths even when missing: reading says why.
        for arg in ["scenes/static-bench.toml", "static-bench.toml", "./x"] {
            let found = locate(Path::new(arg), "scene", SCENES).unwrap();
            assert_eq!(found, Source::File(PathBuf::from(arg)));
            let err = found.text().unwrap_err().to_string();
            assert_eq!(err, format!("{arg}: cannot read"));
        }
    }

    #[test]
    fn an_unknown_name_lists_the_shipped_ones() {
        let err = locate(Path::new("nope"), "calibration", CALIBRATIONS)
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "calibration `nope`: no such file, and no shipped calibration of that name \
             (shipped: default; `triad sim --list` describes them)"
        );
    }

    #[test]
    fn the_listing_names_every_scene_preset_and_calibration() {
        let list = listing();
        for (name, text) in SCENES
            .iter()
            .chain(SCRIPTS)
            .chain(UNITS)
            .chain(CALIBRATIONS)
        {
            assert!(list.contains(&format!("  {name} ")), "{name} in\n{list}");
            let d = description(text);
            assert!(list.contains(&d), "{d:?} in\n{list}");
        }
        assert!(
            description(SCENES[0].1).len() > 10,
            "scenes describe themselves"
        );
        for grade in ["rate-grade", "navigation", "automotive"] {
            assert!(list.contains(grade), "{grade}");
        }
    }
}
