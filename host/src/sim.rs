//! `triad sim`: simulate what a sensor triad measures in a scene and write it
//! as CSV (`t,ax,ay,az,gx,gy,gz,temp`, SI units), streaming in constant memory.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

use anyhow::{bail, Context};
use triad_sim::simulator::Simulator;
use triad_sim::source::TrueSample;

use crate::progress::{Progress, Unit};
use crate::scene_file;

/// Arguments of `triad sim`.
#[derive(clap::Args)]
pub struct SimArgs {
    /// A shipped scene's name (scenes/NAME.toml) or a scene file.
    #[arg(long)]
    pub scene: String,
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
    #[arg(long, required_unless_present = "pack")]
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
pub fn run(args: SimArgs) -> anyhow::Result<std::process::ExitCode> {
    let loaded = scene_file::load(&args.scene)?;
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
    let seconds = match (args.seconds, loaded.duration_s) {
        (Some(s), _) | (None, Some(s)) => s,
        (None, None) => bail!(
            "scene {} has no duration_s; give --seconds",
            loaded.path.display()
        ),
    };
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!("--seconds {seconds}: must be a non-negative number");
    }
    let total = (seconds * scene.rate_hz).round();
    if total > u64::MAX as f64 / 2.0 {
        bail!(
            "--seconds {seconds} at {} Hz is too many samples",
            scene.rate_hz
        );
    }
    let total = total as u64;
    let mut sim = Simulator::new(&scene, args.seed)
        .map_err(|e| anyhow::anyhow!("{}: {e}", loaded.path.display()))?;

    let mut out = create(out_path)?;
    let mut truth = args.truth.as_ref().map(create).transpose()?;
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
    Ok(std::process::ExitCode::SUCCESS)
}

/// `triad sim --pack`: the scene checked as the simulator checks it, then
/// written as the blob of `triad_sim::scene_blob`.
fn pack(
    scene: &triad_sim::scene::Scene,
    seed: u64,
    path: &std::path::Path,
    source: &std::path::Path,
) -> anyhow::Result<std::process::ExitCode> {
    use triad_sim::scene_blob::{encode, MAX_BLOB_LEN};
    Simulator::new(scene, seed).map_err(|e| anyhow::anyhow!("{}: {e}", source.display()))?;
    let mut blob = [0u8; MAX_BLOB_LEN];
    let len =
        encode(scene, seed, &mut blob).map_err(|e| anyhow::anyhow!("{}: {e}", source.display()))?;
    std::fs::write(path, &blob[..len]).with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
        "{}: scene {} at {} Hz, seed {seed}: {len} bytes",
        path.display(),
        source.display(),
        scene.rate_hz
    );
    Ok(std::process::ExitCode::SUCCESS)
}
