//! `triad sim`: simulate what a sensor triad measures in a scene, or what a
//! unit measures in a script, and write it as CSV (`t,ax,ay,az,gx,gy,gz,temp`,
//! SI units), streaming in constant memory; or (`--pack`) write the scene as
//! the blob the emulated board embeds.
//!
//! A scene is a new sensor on every run (its turn-on errors drawn from
//! `--seed`, as is its noise). A unit (`--unit`) is one sensor: its turn-on
//! errors come from its file's `seed`, and each record of it
//! (`--script`, `--record-seed K`) has fresh noise, from K and the unit's
//! seed; `--truth-calib` writes what a perfect calibration of it would hold.

pub mod truth_calibration;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail};
use triad_sim::chips::source::TrueSample;
use triad_sim::scenes::scene::Scene;
use triad_sim::scenes::simulator::Simulator;

use crate::plumbing::distinct::{self, named};
use crate::plumbing::interrupt;
use crate::plumbing::number::{positive, readable, RATE_WORDS};
use crate::plumbing::outfile::{self, OutFile};
use crate::plumbing::progress::{Progress, Unit};
use crate::plumbing::stdio::note;
use crate::scene_file::sensor_unit::{self, LoadedUnit};
use crate::scene_file::{self, script, LoadedScene};
use triad_sim::effects::rng::mix64;

/// Default of `--max-samples`: 10⁸ samples, some 15 GB of CSV (rows of
/// about 150 bytes) and a few minutes of work; above it a run is refused
/// unless asked for, so a slip such as `--seconds 1e12` cannot fill a disk.
pub const DEFAULT_MAX_SAMPLES: u64 = 100_000_000;

/// Arguments of `triad sim`.
#[derive(clap::Args)]
pub struct SimArgs {
    /// A shipped scene's name (built into triad; `--list` shows them) or a
    /// scene file. An existing file of that name wins.
    #[arg(long, value_name = "NAME|FILE", conflicts_with_all = ["unit", "script"])]
    pub scene: Option<String>,
    /// A shipped unit's name or a unit file: one sensor, its turn-on errors
    /// drawn once from the file's `seed` (needs --script and --record-seed).
    #[arg(long, value_name = "NAME|FILE")]
    pub unit: Option<String>,
    /// A shipped script's name or a script file: what happens to the --unit
    /// (motion, temperature, rate, length).
    #[arg(long, value_name = "NAME|FILE")]
    pub script: Option<String>,
    /// With --unit: the seed of this record's noise (each record of a unit
    /// its own; the turn-on errors stay the unit's).
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub record_seed: Option<u64>,
    /// With --unit: write the unit's true (I+Σ), b and temperature terms as
    /// a calibration file (`triad correct --calib`, `triad calib verify`).
    #[arg(long, value_name = "CAL.toml")]
    pub truth_calib: Option<PathBuf>,
    /// List the shipped scenes, grade presets and calibrations, and exit.
    #[arg(long, exclusive = true)]
    pub list: bool,
    /// Seconds to simulate (default: the scene's `duration_s`).
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Sample rate in Hz (default: the scene's `rate_hz`).
    #[arg(long, allow_negative_numbers = true)]
    pub rate: Option<f64>,
    /// With --scene: the seed of every random stream [default: 1].
    #[arg(long, allow_negative_numbers = true)]
    pub seed: Option<u64>,
    /// The measured samples (CSV; `-`: standard output).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Instead of simulating: write the scene (with --rate and --seed) as
    /// the binary blob the emulated board embeds (`cargo xtask run --scene`).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["out", "truth"])]
    pub pack: Option<PathBuf>,
    /// Also write the truth (same columns, no errors; `-`: standard output).
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Refuse runs of more samples than this (seconds × rate).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_SAMPLES, allow_negative_numbers = true)]
    pub max_samples: u64,
}

/// The CSV header of simulated files.
pub const HEADER: &str = "t,ax,ay,az,gx,gy,gz,temp";

/// Writes one row. `{}` prints the shortest decimal that reads back to the
/// same f64, so files are exact and identical on every machine.
pub fn write_row(w: &mut impl Write, t: f64, s: &TrueSample) -> std::io::Result<()> {
    let [ax, ay, az] = s.specific_force;
    let [gx, gy, gz] = s.angular_rate;
    writeln!(w, "{t},{ax},{ay},{az},{gx},{gy},{gz},{}", s.temperature)
}

/// Runs `triad sim`.
pub fn run(args: SimArgs) -> anyhow::Result<ExitCode> {
    if args.list {
        let listing = crate::plumbing::shipped::listing();
        crate::plumbing::stdio::print(&listing)?;
        return Ok(ExitCode::SUCCESS);
    }
    let (loaded, seed, unit) = what_to_simulate(&args)?;
    let outputs: Vec<_> = [
        ("--out", &args.out),
        ("--truth", &args.truth),
        ("--pack", &args.pack),
        ("--truth-calib", &args.truth_calib),
    ]
    .into_iter()
    .filter_map(|(what, p)| p.as_deref().map(|p| named(what, p)))
    .collect();
    let mut inputs = vec![named(
        if unit.is_some() {
            "--script"
        } else {
            "--scene"
        },
        &loaded.path,
    )];
    if let Some(u) = &unit {
        inputs.push(named("--unit", &u.path));
    }
    distinct::check(&inputs, &outputs)?;
    let mut scene = loaded.scene;
    if let Some(rate) = args.rate {
        scene.rate_hz = positive("--rate", rate, RATE_WORDS)?;
    }
    if let Some(path) = &args.pack {
        return pack(&scene, seed, path, &loaded.path);
    }
    let Some(out_path) = args.out.as_ref() else {
        bail!("--out FILE: where the samples go (or --pack FILE for the firmware's blob)");
    };
    let total = sample_count(args.seconds, &loaded, scene.rate_hz, args.max_samples)?;
    let sim =
        Simulator::new(&scene, seed).map_err(|e| anyhow!("{}: {e}", loaded.path.display()))?;
    let truth_calib = match (&unit, &args.truth_calib) {
        (Some(u), Some(path)) => Some((path, truth_calibration::render(u)?)),
        _ => None,
    };
    simulate(sim, total, out_path, args.truth.as_deref())?;
    if let Some((path, text)) = truth_calib {
        outfile::write_whole(path, text.as_bytes())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The scene to simulate, the seed of its random streams, and the unit
/// when it is a unit's record: `--scene` (and `--seed`), or `--unit`,
/// `--script` and `--record-seed` (the unit's turn-on errors are fixed
/// already; the streams' seed mixes K with the unit's seed, so that two
/// units given the same K do not share their noise).
fn what_to_simulate(args: &SimArgs) -> anyhow::Result<(LoadedScene, u64, Option<LoadedUnit>)> {
    let unit_only = |given: bool, flag: &str, why: &str| -> anyhow::Result<()> {
        if given && args.unit.is_none() {
            bail!("{flag} is a unit's record's option: {why}; give --unit UNIT --script SCRIPT --record-seed K");
        }
        Ok(())
    };
    unit_only(
        args.script.is_some(),
        "--script",
        "a script says what happens to a unit (--unit), which it does not name",
    )?;
    unit_only(
        args.record_seed.is_some(),
        "--record-seed",
        "a scene's streams all come from --seed",
    )?;
    unit_only(
        args.truth_calib.is_some(),
        "--truth-calib",
        "a scene draws its turn-on errors anew from each --seed, so it has no one true calibration",
    )?;
    let Some(unit_name) = &args.unit else {
        let Some(scene) = &args.scene else {
            bail!(
                "give --scene NAME|FILE, or --unit UNIT --script SCRIPT --record-seed K \
                 (`triad sim --list` names the shipped ones)"
            );
        };
        return Ok((scene_file::load(scene)?, args.seed.unwrap_or(1), None));
    };
    if args.seed.is_some() {
        bail!(
            "--seed is a scene's; with --unit the unit file's `seed` fixes the turn-on errors \
             and --record-seed K the record's noise"
        );
    }
    let Some(script) = &args.script else {
        bail!(
            "--unit needs --script: the unit is the sensor, the script what happens to it \
             (shipped scripts: {})",
            shipped_names(crate::plumbing::shipped::SCRIPTS)
        );
    };
    let Some(k) = args.record_seed else {
        bail!(
            "--unit needs --record-seed K: the seed of this record's noise (give each record \
             of a unit its own K, or their noise is the same)"
        );
    };
    let unit = sensor_unit::load(unit_name)?;
    let mut loaded = script::load(script)?;
    loaded.scene.accel = unit.accel;
    loaded.scene.gyro = unit.gyro;
    let seed = record_stream_seed(unit.seed, k);
    Ok((loaded, seed, Some(unit)))
}

/// The seed of a unit's record's streams: K mixed with the unit's seed.
fn record_stream_seed(unit_seed: u64, k: u64) -> u64 {
    mix64(mix64(unit_seed) ^ k)
}

/// The names of shipped files, comma-separated.
fn shipped_names(table: &[(&str, &str)]) -> String {
    table.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// Samples to write: `--seconds` (else the scene's `duration_s`) at
/// `rate_hz`, at most `max_samples`.
fn sample_count(
    seconds: Option<f64>,
    loaded: &LoadedScene,
    rate_hz: f64,
    max_samples: u64,
) -> anyhow::Result<u64> {
    let (seconds, from) = match (seconds, loaded.duration_s) {
        (Some(s), _) => (s, "--seconds".to_string()),
        (None, Some(s)) => (s, format!("{} duration_s", loaded.path.display())),
        (None, None) => bail!(
            "scene {} has no duration_s; give --seconds",
            loaded.path.display()
        ),
    };
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!(
            "{from} {}: must be a non-negative number",
            readable(seconds)
        );
    }
    let total = (seconds * rate_hz).round();
    if total > max_samples as f64 {
        bail!(
            "{from} {} at {} Hz is {} samples, above the limit of {max_samples} \
             (--max-samples N raises it; each sample is about 150 bytes of CSV)",
            readable(seconds),
            readable(rate_hz),
            readable(total)
        );
    }
    Ok(total as u64)
}

/// A CSV output with its header written.
fn create(path: &Path) -> anyhow::Result<OutFile> {
    let mut out = OutFile::create(path)?;
    writeln!(out, "{HEADER}").map_err(|e| out.error(e))?;
    Ok(out)
}

/// Steps `sim` `total` times, writing the measurements to `out_path` and,
/// when asked, the truth to `truth_path`. Both are opened before either is
/// written, and put in place only when both are whole.
fn simulate(
    mut sim: Simulator,
    total: u64,
    out_path: &Path,
    truth_path: Option<&Path>,
) -> anyhow::Result<()> {
    let mut out = create(out_path)?;
    let mut truth = truth_path.map(create).transpose()?;
    let interrupted = interrupt::flag();
    // About a second of work: 2 M samples.
    let progress = Progress::new(total, 2_000_000, Unit::Samples);
    for k in 0..total {
        let s = sim.step();
        write_row(&mut out, s.t, &s.measured).map_err(|e| out.error(e))?;
        if let Some(w) = truth.as_mut() {
            write_row(w, s.t, &s.truth).map_err(|e| w.error(e))?;
        }
        if k & 0xffff == 0 {
            progress.update(k);
            if interrupt::requested(&interrupted) {
                bail!("interrupted at sample {k} of {total}: nothing written");
            }
        }
    }
    progress.finish();
    out.commit()?;
    if let Some(w) = truth {
        w.commit()?;
    }
    Ok(())
}

/// `triad sim --pack`: the scene checked as the simulator checks it, then
/// written as the blob of `triad_sim::scenes::scene_blob`.
fn pack(scene: &Scene, seed: u64, path: &Path, source: &Path) -> anyhow::Result<ExitCode> {
    use triad_sim::scenes::scene_blob::{encode, MAX_BLOB_LEN};
    Simulator::new(scene, seed).map_err(|e| anyhow!("{}: {e}", source.display()))?;
    let mut blob = [0u8; MAX_BLOB_LEN];
    let len = encode(scene, seed, &mut blob).map_err(|e| anyhow!("{}: {e}", source.display()))?;
    outfile::write_whole(path, &blob[..len])?;
    note!(
        "{}: scene {} at {} Hz, seed {seed}: {len} bytes",
        path.display(),
        source.display(),
        scene.rate_hz
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad_sim::motion::Motion;

    const MAX: u64 = DEFAULT_MAX_SAMPLES;

    fn loaded(duration_s: Option<f64>) -> LoadedScene {
        LoadedScene {
            scene: Scene::new(100.0, Motion::Static { attitude: [0.0; 3] }),
            duration_s,
            path: PathBuf::from("s.toml"),
        }
    }

    #[test]
    fn rows_are_the_shortest_exact_decimals() {
        let s = TrueSample {
            specific_force: [0.1, -0.0, 9.80665],
            angular_rate: [1e-20, 2.5, -3.0],
            temperature: 25.0,
        };
        let mut out = Vec::new();
        write_row(&mut out, 0.01, &s).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "0.01,0.1,-0,9.80665,0.00000000000000000001,2.5,-3,25\n"
        );
        assert_eq!(HEADER.split(',').count(), 8);
    }

    #[test]
    fn the_sample_count_comes_from_seconds_or_the_scene() {
        assert_eq!(
            sample_count(Some(1.5), &loaded(Some(9.0)), 100.0, MAX).unwrap(),
            150
        );
        assert_eq!(
            sample_count(None, &loaded(Some(2.0)), 100.0, MAX).unwrap(),
            200
        );
        assert_eq!(
            sample_count(Some(0.0), &loaded(None), 100.0, MAX).unwrap(),
            0
        );
        let err = sample_count(None, &loaded(None), 100.0, MAX).unwrap_err();
        assert_eq!(
            err.to_string(),
            "scene s.toml has no duration_s; give --seconds"
        );
        let err = sample_count(Some(-1.0), &loaded(None), 100.0, MAX).unwrap_err();
        assert!(err.to_string().contains("non-negative"));
        let err = sample_count(Some(1e300), &loaded(None), 100.0, MAX).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--seconds 1e300 at 100 Hz is 1e302 samples, above the limit of 100000000 \
             (--max-samples N raises it; each sample is about 150 bytes of CSV)"
        );
        // The limit counts samples, so a high rate is bounded as well.
        let err = sample_count(None, &loaded(Some(60.0)), 1e12, MAX).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("s.toml duration_s 60 at 1000000000000 Hz is 60000000000000 samples"),
            "{err}"
        );
        assert_eq!(
            sample_count(Some(2.0), &loaded(None), 100.0, 200).unwrap(),
            200
        );
        assert!(sample_count(Some(2.01), &loaded(None), 100.0, 200).is_err());
    }
}
