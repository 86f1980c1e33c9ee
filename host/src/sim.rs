//! `triad sim`: simulate what a sensor triad measures in a scene and write it
//! as CSV (`t,ax,ay,az,gx,gy,gz,temp`, SI units), streaming in constant
//! memory; or (`--pack`) write the scene as the blob the emulated board embeds.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context};
use triad_sim::scene::Scene;
use triad_sim::simulator::Simulator;
use triad_sim::source::TrueSample;

use crate::progress::{Progress, Unit};
use crate::scene_file::{self, LoadedScene};

/// Arguments of `triad sim`.
#[derive(clap::Args)]
pub struct SimArgs {
    /// A shipped scene's name (built into triad; `--list` shows them) or a
    /// scene file. An existing file of that name wins.
    #[arg(long, value_name = "NAME|FILE", required_unless_present = "list")]
    pub scene: Option<String>,
    /// List the shipped scenes, grade presets and calibrations, and exit.
    #[arg(long, exclusive = true)]
    pub list: bool,
    /// Seconds to simulate (default: the scene's `duration_s`).
    #[arg(long)]
    pub seconds: Option<f64>,
    /// Sample rate in Hz (default: the scene's `rate_hz`).
    #[arg(long)]
    pub rate: Option<f64>,
    /// Seed of every random stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The measured samples (CSV).
    #[arg(long, required_unless_present_any = ["pack", "list"])]
    pub out: Option<PathBuf>,
    /// Instead of simulating: write the scene (with --rate and --seed) as
    /// the binary blob the emulated board embeds (`cargo xtask run --scene`).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["out", "truth"])]
    pub pack: Option<PathBuf>,
    /// Also write the truth (same columns, no errors).
    #[arg(long)]
    pub truth: Option<PathBuf>,
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

fn create(path: &PathBuf) -> anyhow::Result<BufWriter<File>> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = BufWriter::with_capacity(1 << 16, file);
    writeln!(w, "{HEADER}")?;
    Ok(w)
}

/// Runs `triad sim`.
pub fn run(args: SimArgs) -> anyhow::Result<ExitCode> {
    let Some(scene) = args.scene.as_deref().filter(|_| !args.list) else {
        let listing = crate::shipped::listing();
        std::io::stdout()
            .lock()
            .write_all(listing.as_bytes())
            .context("writing to stdout")?;
        return Ok(ExitCode::SUCCESS);
    };
    let loaded = scene_file::load(scene)?;
    let mut scene = loaded.scene;
    if let Some(rate) = args.rate {
        if !(rate.is_finite() && rate > 0.0) {
            bail!("--rate {rate}: the sample rate must be a positive number of Hz");
        }
        scene.rate_hz = rate;
    }
    if let Some(path) = &args.pack {
        return pack(&scene, args.seed, path, &loaded.path);
    }
    let Some(out_path) = args.out.as_ref() else {
        bail!("--out FILE: where the samples go (or --pack FILE for the firmware's blob)");
    };
    let total = sample_count(args.seconds, &loaded, scene.rate_hz)?;
    let sim =
        Simulator::new(&scene, args.seed).map_err(|e| anyhow!("{}: {e}", loaded.path.display()))?;
    simulate(sim, total, out_path, args.truth.as_ref())?;
    Ok(ExitCode::SUCCESS)
}

/// Samples to write: `--seconds` (else the scene's `duration_s`) at `rate_hz`.
fn sample_count(seconds: Option<f64>, loaded: &LoadedScene, rate_hz: f64) -> anyhow::Result<u64> {
    let seconds = match (seconds, loaded.duration_s) {
        (Some(s), _) | (None, Some(s)) => s,
        (None, None) => bail!(
            "scene {} has no duration_s; give --seconds",
            loaded.path.display()
        ),
    };
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!("--seconds {seconds}: must be a non-negative number");
    }
    let total = (seconds * rate_hz).round();
    if total > u64::MAX as f64 / 2.0 {
        bail!("--seconds {seconds} at {rate_hz} Hz is too many samples");
    }
    Ok(total as u64)
}

/// Steps `sim` `total` times, writing the measurements to `out_path` and,
/// when asked, the truth to `truth_path`.
fn simulate(
    mut sim: Simulator,
    total: u64,
    out_path: &PathBuf,
    truth_path: Option<&PathBuf>,
) -> anyhow::Result<()> {
    let mut out = create(out_path)?;
    let mut truth = truth_path.map(create).transpose()?;
    // About a second of work: 2 M samples.
    let progress = Progress::new(total, 2_000_000, Unit::Samples);
    for k in 0..total {
        let s = sim.step();
        write_row(&mut out, s.t, &s.measured)
            .with_context(|| format!("writing {}", out_path.display()))?;
        if let Some(w) = truth.as_mut() {
            write_row(w, s.t, &s.truth)?;
        }
        if k & 0xffff == 0 {
            progress.update(k);
        }
    }
    out.flush()
        .with_context(|| format!("writing {}", out_path.display()))?;
    if let Some(mut w) = truth {
        w.flush()?;
    }
    progress.finish();
    Ok(())
}

/// `triad sim --pack`: the scene checked as the simulator checks it, then
/// written as the blob of `triad_sim::scene_blob`.
fn pack(scene: &Scene, seed: u64, path: &Path, source: &Path) -> anyhow::Result<ExitCode> {
    use triad_sim::scene_blob::{encode, MAX_BLOB_LEN};
    Simulator::new(scene, seed).map_err(|e| anyhow!("{}: {e}", source.display()))?;
    let mut blob = [0u8; MAX_BLOB_LEN];
    let len = encode(scene, seed, &mut blob).map_err(|e| anyhow!("{}: {e}", source.display()))?;
    std::fs::write(path, &blob[..len]).with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
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
            sample_count(Some(1.5), &loaded(Some(9.0)), 100.0).unwrap(),
            150
        );
        assert_eq!(sample_count(None, &loaded(Some(2.0)), 100.0).unwrap(), 200);
        assert_eq!(sample_count(Some(0.0), &loaded(None), 100.0).unwrap(), 0);
        let err = sample_count(None, &loaded(None), 100.0).unwrap_err();
        assert_eq!(
            err.to_string(),
            "scene s.toml has no duration_s; give --seconds"
        );
        let err = sample_count(Some(-1.0), &loaded(None), 100.0).unwrap_err();
        assert!(err.to_string().contains("non-negative"));
        let err = sample_count(Some(1e300), &loaded(None), 100.0).unwrap_err();
        assert!(err.to_string().contains("too many samples"));
    }
}
