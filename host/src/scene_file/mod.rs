//! Scene files: TOML in data-sheet units, converted once into the
//! simulator's SI [`Scene`]. Every error names the file position
//! (line:column) of the value at fault and why it is wrong.
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
//!
//! The work, in order: `parse` (TOML → fields, unknown keys and wrong
//! types), `field` with [`unit`](mod@unit) (each value in SI, its unit checked),
//! `build`, `motion` and `effects` (fields → scene), and `origin` (the
//! simulator's own check of the scene, [`Scene::validate`], reported at the
//! file's positions: the values are checked once, by the simulator).

mod build;
mod effects;
mod field;
mod motion;
mod optics;
mod origin;
mod parse;
pub mod script;
pub mod sensor_unit;
pub mod unit;

use std::path::{Path, PathBuf};

use triad_sim::scenes::scene::Scene;

use crate::plumbing::shipped;
use build::Builder;
use parse::Source;

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

/// Parses scene text (from `path`, used in messages).
pub fn parse(text: &str, path: &Path) -> anyhow::Result<LoadedScene> {
    let src = Source { path, text };
    let file = src.read()?;
    built(src, &file)
}

/// The scene of `file`, read from `src`, with its default duration.
fn built(src: Source, file: &parse::SceneFile) -> anyhow::Result<LoadedScene> {
    let path = src.path.to_path_buf();
    let mut builder = Builder::new(src);
    let duration_s = builder.duration(file)?;
    let scene = builder.scene(file)?;
    Ok(LoadedScene {
        scene,
        duration_s,
        path,
    })
}

/// Loads NAME (a shipped scene) or FILE, by the rule of [`crate::plumbing::shipped`].
pub fn load(name_or_file: &str) -> anyhow::Result<LoadedScene> {
    load_shipped_or_file(name_or_file, "scene", shipped::SCENES, parse)
}

/// Loads NAME (one of `table`, files of `kind`) or FILE with `parse`.
fn load_shipped_or_file<T>(
    name_or_file: &str,
    kind: &str,
    table: &[(&'static str, &'static str)],
    parse: fn(&str, &Path) -> anyhow::Result<T>,
) -> anyhow::Result<T> {
    let source = shipped::locate(Path::new(name_or_file), kind, table)?;
    let text = source.text()?;
    parse(&text, &source.shown())
}

#[cfg(test)]
mod tests {
    use super::*;

    const STATIC: &str = "rate_hz = 10.0\n[motion]\nkind = \"static\"\n";

    fn error(text: &str) -> String {
        parse(text, Path::new("s.toml")).unwrap_err().to_string()
    }

    /// Every value the simulator checks, wrong, is reported at its place in
    /// the file's words (a value the simulator renamed would lose its place).
    #[test]
    fn the_simulators_check_is_reported_at_the_file_position() {
        let triad = |t: &str, body: &str| format!("{STATIC}[{t}]\n{body}\n");
        let cases: Vec<(String, &str)> = vec![
            ("rate_hz = 0.0\n[motion]\nkind = \"static\"\n".into(), "s.toml:1:11: `rate_hz` = 0 must be positive"),
            ("rate_hz = 1.0\ngravity = \"-1 g\"\n[motion]\nkind = \"static\"\n".into(), "s.toml:2:11: `gravity` = \"-1 g\" must not be negative"),
            ("rate_hz = 1.0\ngravity = \"0 g\"\n[motion]\nkind = \"static\"\n".into(), "s.toml:2:11: gravity must be positive"),
            ("rate_hz = 1.0\nlatitude_deg = nan\n[motion]\nkind = \"static\"\n".into(), "s.toml:2:16: `latitude_deg` = NaN is not a finite number"),
            ("rate_hz = 1.0\n[motion]\nkind = \"static\"\nattitude_deg = [0.0, inf, 0.0]\n".into(), "s.toml:4:16: `attitude_deg` must be finite"),
            ("rate_hz = 1.0\n[motion]\nkind = \"tumble\"\npositions = 7\ndwell_s = 1.0\ntransition_s = 1.0\n".into(), "s.toml:4:13: positions = 7: expected 6, 12 or 24"),
            ("rate_hz = 1.0\n[motion]\nkind = \"tumble\"\npositions = 6\ndwell_s = 0.0\ntransition_s = 1.0\n".into(), "s.toml:5:11: `dwell_s` = 0 must be positive"),
            ("rate_hz = 1.0\n[motion]\nkind = \"tumble\"\npositions = 6\ndwell_s = 1.0\ntransition_s = -1.0\n".into(), "s.toml:6:16: `transition_s` = -1 must not be negative"),
            ("rate_hz = 1.0\n[motion]\nkind = \"vibration\"\ndirection = [0.0, 0.0, 0.0]\namplitude = \"1 g\"\nfrequency_hz = 1.0\n".into(), "s.toml:4:13: `direction` must be a finite, non-zero vector"),
            ("rate_hz = 1.0\n[motion]\nkind = \"vibration\"\ndirection = [0.0, 0.0, 1.0]\namplitude = \"-1 g\"\nfrequency_hz = 1.0\n".into(), "s.toml:5:13: `amplitude` = \"-1 g\" must not be negative"),
            ("rate_hz = 1.0\n[motion]\nkind = \"vibration\"\ndirection = [0.0, 0.0, 1.0]\namplitude = \"1 g\"\nfrequency_hz = -1.0\n".into(), "s.toml:6:16: `frequency_hz` = -1 must not be negative"),
            (format!("{STATIC}[temperature]\nkind = \"constant\"\ncelsius = nan\n"), "s.toml:6:11: `celsius` = NaN is not a finite number"),
            (format!("{STATIC}[temperature]\nkind = \"ramp\"\nfrom_c = inf\nto_c = 1.0\nduration_s = 1.0\n"), "s.toml:6:10: `from_c` = inf is not a finite number"),
            (format!("{STATIC}[temperature]\nkind = \"ramp\"\nfrom_c = 0.0\nto_c = nan\nduration_s = 1.0\n"), "s.toml:7:8: `to_c` = NaN is not a finite number"),
            (format!("{STATIC}[temperature]\nkind = \"ramp\"\nfrom_c = 0.0\nto_c = 1.0\nstart_s = -2.0\nduration_s = 1.0\n"), "s.toml:8:11: `start_s` = -2 must not be negative"),
            (format!("{STATIC}[temperature]\nkind = \"ramp\"\nfrom_c = 0.0\nto_c = 1.0\nduration_s = -1.0\n"), "s.toml:8:14: `duration_s` = -1 must not be negative"),
            (triad("gyro", "white_noise = \"-1 deg/sqrt(h)\""), "s.toml:5:15: `white_noise` = \"-1 deg/sqrt(h)\" must not be negative"),
            (triad("accel", "random_walk = \"-1 ug/sqrt(s)\""), "s.toml:5:15: `random_walk` = \"-1 ug/sqrt(s)\" must not be negative"),
            (triad("gyro", "turn_on_bias = [\"1 deg/h\", \"-1 deg/h\", \"0 deg/h\"]"), "s.toml:5:16: `turn_on_bias` = \"-1 deg/h\" must not be negative"),
            (triad("accel", "turn_on_scale = \"-1 ppm\""), "s.toml:5:17: `turn_on_scale` = \"-1 ppm\" must not be negative"),
            (triad("accel", "quantisation = \"-1 mg\""), "s.toml:5:16: `quantisation` = \"-1 mg\" must not be negative"),
            (triad("accel", "output_lsb = \"-1 mg\""), "s.toml:5:14: `output_lsb` = \"-1 mg\" must not be negative"),
            (triad("gyro", "angle_quantisation = \"-2 arcsec\""), "s.toml:5:22: `angle_quantisation` = \"-2 arcsec\" must not be negative"),
            (triad("accel", "velocity_quantisation = \"-1 mm/s\""), "s.toml:5:25: `velocity_quantisation` = \"-1 mm/s\" must not be negative"),
            (triad("gyro", "saturation = \"0 dps\""), "s.toml:5:14: `saturation` (the measurement range) must be positive"),
            (triad("accel", "g_sensitivity = \"0.01 deg/s/g\""), "s.toml:5:17: `g_sensitivity` is a gyro effect; accelerometers cannot have it"),
            (triad("gyro", "[gyro.gauss_markov]\nsigma = \"-1 deg/h\"\ncorrelation_time = \"1 s\""), "s.toml:6:9: `gauss_markov.sigma` = \"-1 deg/h\" must not be negative"),
            (triad("gyro", "[gyro.gauss_markov]\nsigma = \"1 deg/h\"\ncorrelation_time = \"0 s\""), "s.toml:7:20: `correlation_time` must be positive"),
            (triad("accel", "[accel.bias_instability]\nvalue = \"-1 ug\""), "s.toml:6:9: `bias_instability.value` = \"-1 ug\" must not be negative"),
            (triad("gyro", "[gyro.bias_instability]\nvalue = \"1 deg/h\"\nband_s = [0.0, 1.0]"), "s.toml:7:10: band_s = [0, 1]: need 0 < shortest ≤ longest (seconds)"),
            (triad("gyro", "[gyro.bias_instability]\nvalue = \"1 deg/h\"\nband_s = [1.0, inf]"), "s.toml:7:10: band_s = [1, inf]: need 0 < shortest ≤ longest (seconds)"),
            (triad("accel", "[accel.bias_instability]\nvalue = \"1 ug\"\nband_s = [10.0, 1.0]"), "s.toml:7:10: band_s = [10, 1]: need 0 < shortest ≤ longest (seconds)"),
            (triad("gyro", "[gyro.bias_instability]\nvalue = \"1 deg/h\"\nterms = 0"), "s.toml:7:9: terms = 0: expected 1..=16"),
            (triad("accel", "[accel.temperature]\nreference_c = nan"), "s.toml:6:15: `reference_c` = NaN is not a finite number"),
        ];
        for (text, expected) in cases {
            assert_eq!(error(&text), expected, "{text}");
        }
    }

    #[test]
    fn what_is_about_the_file_is_checked_here() {
        let triad = |t: &str, body: &str| format!("{STATIC}[{t}]\n{body}\n");
        let e = error(&triad("gyro", "grade = \"best\""));
        assert_eq!(e, "s.toml:5:9: unknown gyro grade \"best\" (expected rate-grade, tactical, aviation, navigation, tactical-fog, aviation-rlg, aviation-fog, navigation-rlg)");
        let e = error(&triad("accel", "grade = \"rate-grade\""));
        assert!(
            e.contains("unknown accel grade \"rate-grade\" (expected automotive,"),
            "{e}"
        );
        let e = error(&triad("gyro", "misalignment = \"1 mrad\""));
        assert!(
            e.ends_with(
                "`misalignment` must have a zero diagonal (scale factors go in `scale_factor`)"
            ),
            "{e}"
        );
        let e = error("rate_hz = 1.0\nlatitude_deg = -91.0\n[motion]\nkind = \"static\"\n");
        assert_eq!(e, "s.toml:2:16: latitude_deg = -91 is outside −90..90");
        let e = error("rate_hz = 1.0\n[motion]\nkind = \"static\"\naxis = \"z\"\n");
        assert_eq!(
            e,
            "s.toml:4:8: `axis` does not apply to motion kind \"static\""
        );
        let e = error("rate_hz = 1.0\nduration_s = 0.0\n[motion]\nkind = \"static\"\n");
        assert_eq!(e, "s.toml:2:14: `duration_s` = 0 must be positive");
        let e = error(&triad("gyro", "velocity_quantisation = \"1 mm/s\""));
        assert_eq!(e, "s.toml:5:25: `velocity_quantisation` is not a gyro key: its integral is quantised by `angle_quantisation`");
        let e = error(&triad("accel", "angle_quantisation = \"1 arcsec\""));
        assert!(
            e.ends_with("is quantised by `velocity_quantisation`"),
            "{e}"
        );
        let e = error(&triad("gyro", "angle_quantisation = \"1 deg/s\""));
        assert!(
            e.contains("angle_quantisation"),
            "a rate is not an angle: {e}"
        );
        let e = error(&triad(
            "accel",
            "output_lsb = \"1 mg\"\nquantisation = \"1 mg\"",
        ));
        assert_eq!(
            e,
            "s.toml:6:16: `quantisation` is the old name of `output_lsb`: give one of them"
        );
    }

    #[test]
    fn optics_sections_read_into_si_and_replace_the_presets() {
        let rlg = "[gyro.ring_laser]\narea = \"15.588457 cm^2\"\npath_length = \"18 cm\"\nlock_in = \"0.1 deg/s\"\ndither_rate = \"100 deg/s\"\ndither_frequency_hz = 400.0\n";
        let text = format!("{STATIC}[gyro]\ngrade = \"aviation-fog\"\n{rlg}");
        let g = parse(&text, Path::new("s.toml")).unwrap().scene.gyro;
        assert!(g.fibre_optic.is_none(), "the preset's optics are replaced");
        let r = g.ring_laser.unwrap();
        assert!((r.area - 15.588457e-4).abs() < 1e-12 && (r.path_length - 0.18).abs() < 1e-15);
        assert_eq!(r.wavelength, 632.8e-9);
        assert!((r.lock_in - 0.1f64.to_radians()).abs() < 1e-15);
        let d = r.dither.unwrap();
        assert!((d.peak_rate - 100f64.to_radians()).abs() < 1e-12 && d.frequency == 400.0);
        // Without the dither keys: undithered.
        let text = format!("{STATIC}[gyro.ring_laser]\narea = \"1 cm^2\"\npath_length = \"4 cm\"\nwavelength = \"633 nm\"\nlock_in = \"100 deg/h\"\n");
        let r = parse(&text, Path::new("s.toml"))
            .unwrap()
            .scene
            .gyro
            .ring_laser
            .unwrap();
        assert!(r.dither.is_none() && (r.wavelength - 633e-9).abs() < 1e-20);
        let fog = "[gyro.fibre_optic]\nturns = 1061\ncoil_diameter = \"6 cm\"\nwavelength = \"1550 nm\"\nreadout = \"open\"\nwavelength_per_degree = \"400 ppm/degC\"\n";
        let f = parse(&format!("{STATIC}{fog}"), Path::new("s.toml"))
            .unwrap()
            .scene
            .gyro
            .fibre_optic
            .unwrap();
        assert_eq!(
            (f.turns, f.readout, f.reference),
            (1061.0, triad_sim::optics::fibre_optic::Loop::Open, 25.0)
        );
        assert!((f.coil_area - std::f64::consts::PI * 9e-4).abs() < 1e-15);
        assert!((f.wavelength_per_degree - 400e-6).abs() < 1e-18 && f.area_per_degree == 0.0);
    }

    #[test]
    fn optics_sections_refuse_what_is_wrong_at_its_place() {
        let rl = |body: &str| {
            format!(
                "{STATIC}[gyro.ring_laser]\narea = \"1 cm^2\"\npath_length = \"4 cm\"\n{body}\n"
            )
        };
        let e = error(&rl("lock_in = \"-1 deg/s\""));
        assert_eq!(
            e,
            "s.toml:7:11: `ring_laser.lock_in` = \"-1 deg/s\" must not be negative"
        );
        let e = error(&rl("lock_in = \"1 deg/s\"\ndither_rate = \"100 deg/s\""));
        assert_eq!(
            e,
            "s.toml:8:15: `dither_rate` needs `dither_frequency_hz` (both, or neither: no dither)"
        );
        let e = error(&rl(
            "lock_in = \"1 deg/s\"\ndither_rate = \"100 deg/s\"\ndither_frequency_hz = 0.0",
        ));
        assert_eq!(e, "s.toml:9:23: `dither_frequency_hz` = 0 must be positive");
        let e = error(&rl("lock_in = \"1 deg/s\"\nwavelength = \"0 nm\""));
        assert!(
            e.starts_with("s.toml:8:14: `ring_laser.wavelength` = \"0 nm\""),
            "{e}"
        );
        let e = error(&rl("lock_in = \"1 deg\""));
        assert!(
            e.contains("`ring_laser.lock_in`: the unit has dimension rad"),
            "{e}"
        );
        let e = error(&format!("{STATIC}[accel.ring_laser]\narea = \"1 cm^2\"\npath_length = \"4 cm\"\nlock_in = \"1 deg/s\"\n"));
        assert_eq!(
            e,
            "s.toml:5:8: `ring_laser` is a gyro model; accelerometers cannot have it"
        );
        let fo = |body: &str| {
            format!("{STATIC}[gyro.fibre_optic]\nturns = 100\ncoil_diameter = \"6 cm\"\nwavelength = \"1550 nm\"\n{body}\n")
        };
        let e = error(&fo("readout = \"half\""));
        assert_eq!(
            e,
            "s.toml:8:11: readout = \"half\": expected \"open\" or \"closed\" (loop)"
        );
        let e = error(&fo("readout = \"open\"\n[gyro.ring_laser]\narea = \"1 cm^2\"\npath_length = \"4 cm\"\nlock_in = \"1 deg/s\""));
        assert_eq!(
            e,
            "s.toml:6:17: a gyro is a ring laser or a fibre-optic gyro, not both"
        );
        let e = error(&format!("{STATIC}[gyro.fibre_optic]\nturns = 0\ncoil_diameter = \"6 cm\"\nwavelength = \"1550 nm\"\nreadout = \"open\"\n"));
        assert_eq!(e, "s.toml:5:9: `turns` = 0 must be positive");
        let e = error(&format!("{STATIC}[gyro.fibre_optic]\nturns = 10\ncoil_diameter = \"-6 cm\"\nwavelength = \"1550 nm\"\nreadout = \"open\"\n"));
        assert_eq!(e, "s.toml:6:17: `coil_diameter` must be positive");
    }

    #[test]
    fn quantisation_keys_read_into_si() {
        let text = format!(
            "{STATIC}[gyro]\nangle_quantisation = \"2 arcsec\"\nquantisation = \"0.061 mdps\"\n[accel]\nvelocity_quantisation = \"1 mm/s\"\noutput_lsb = \"1 mg\"\n"
        );
        let loaded = parse(&text, Path::new("s.toml")).unwrap();
        let (g, a) = (loaded.scene.gyro, loaded.scene.accel);
        let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
        assert!((g.increment_quantisation.unwrap()[0] / (2.0 * arcsec) - 1.0).abs() < 1e-15);
        let mdps = std::f64::consts::PI / 180.0 * 1e-3;
        assert!((g.output_lsb.unwrap()[2] / (0.061 * mdps) - 1.0).abs() < 1e-15);
        assert_eq!(a.increment_quantisation, Some([1e-3; 3]));
        assert!((a.output_lsb.unwrap()[1] / 9.80665e-3 - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_scene_reads_into_si() {
        let text = format!(
            "duration_s = 5.0\n{STATIC}[gyro]\ngrade = \"tactical\"\nbias = [\"3600 deg/h\", \"0 deg/h\", \"-3600 deg/h\"]\nscale_factor = \"100 ppm\"\nmisalignment = [[0, \"1 mrad\", 0], [0, 0, 0], [0, 0, 0]]\n"
        );
        let loaded = parse(&text, Path::new("s.toml")).unwrap();
        assert_eq!(loaded.duration_s, Some(5.0));
        let g = loaded.scene.gyro;
        let deg = std::f64::consts::PI / 180.0;
        let b = g.constant_bias.unwrap();
        assert!((b[0] - deg).abs() < 1e-15 && b[1] == 0.0 && (b[2] + deg).abs() < 1e-15);
        let sm = g.scale_misalignment.unwrap();
        assert_eq!((sm[0][0], sm[0][1], sm[1][0]), (100.0 * 1e-6, 1e-3, 0.0));
        // The preset's white noise is kept; the accelerometer has no effect.
        assert!(g.white_noise.is_some());
        assert!(loaded.scene.accel.is_none());
    }

    #[test]
    fn names_load_shipped_scenes_and_unknown_ones_are_named() {
        let loaded = load("static-bench").unwrap();
        assert_eq!(loaded.path, PathBuf::from("shipped:static-bench"));
        assert!(loaded.duration_s.is_some());
        let err = load("no-such-scene").unwrap_err().to_string();
        assert!(
            err.starts_with("scene `no-such-scene`: no such file"),
            "{err}"
        );
        assert!(load("tumble-6").is_ok());
    }
}
