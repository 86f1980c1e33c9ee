//! `triad convert IN OUT`: a recording of any format [`record`] reads, as
//! triad's CSV (`t,ax,ay,az,gx,gy,gz[,temp]`, SI, every number exact) or as
//! MCAP with sensor_msgs/msg/Imu in ROS 2 CDR ([`record::mcap_out`]), which
//! ROS 2 tools and Foxglove open. The output is written whole or not at all.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;

use crate::plumbing::distinct::{self, named};
use crate::plumbing::outfile::OutFile;
use crate::plumbing::stdio;
use crate::record::{self, mcap_out::McapWriter, to_csv, Opened};

/// The output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// triad's CSV.
    Csv,
    /// MCAP, sensor_msgs/msg/Imu in CDR (a ROS 2 bag's storage).
    Mcap,
}

/// Arguments of `triad convert`.
#[derive(clap::Args)]
pub struct ConvertArgs {
    /// The recording: triad CSV, EuRoC/TUM-VI CSV, imu_tk text, ROS 1 bag,
    /// ROS 2 bag (directory, .mcap or .db3), MCAP, PX4 ULog (found from its content).
    pub input: PathBuf,
    /// The output (`-`: standard output).
    pub output: PathBuf,
    /// The output's format (default: MCAP for a name ending .mcap, else CSV).
    #[arg(long, value_enum)]
    pub to: Option<Target>,
}

/// Runs `triad convert`.
pub fn run(args: ConvertArgs) -> anyhow::Result<ExitCode> {
    distinct::check(
        &[named("input", &args.input)],
        &[named("output", &args.output)],
    )?;
    let target = args.to.unwrap_or_else(|| target_of(&args.output));
    let opened = record::open(&args.input, &record::options::global())?;
    let source = opened.source.clone();
    let samples = convert(opened, &args.output, target)?;
    let topic = source
        .topic
        .map(|t| format!(", topic {t}"))
        .unwrap_or_default();
    let note = format!(
        "{samples} samples of {} ({}{topic}) written to {}\n",
        source.name,
        source.format.name(),
        args.output.display()
    );
    stdio::report(&note, crate::plumbing::outfile::is_stdout(&args.output))?;
    Ok(ExitCode::SUCCESS)
}

/// The format a name asks for: MCAP for `.mcap`, else CSV.
fn target_of(path: &Path) -> Target {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
    {
        Target::Mcap
    } else {
        Target::Csv
    }
}

/// Writes the samples of `opened` to `path` as `target`; their count.
pub fn convert(opened: Opened, path: &Path, target: Target) -> anyhow::Result<u64> {
    let Opened { source, mut reader } = opened;
    let out = OutFile::create(path)?;
    let mut count = 0u64;
    let out = match target {
        Target::Csv => {
            let mut out = out;
            writeln!(out, "{}", to_csv::header(source.channels)).map_err(|e| out.error(e))?;
            while let Some(chunk) = reader.next_chunk()? {
                for s in &chunk {
                    to_csv::row(&mut out, source.channels, s)
                        .map_err(|e| anyhow!("writing {}: {e}", path.display()))?;
                }
                count += chunk.len() as u64;
            }
            out
        }
        Target::Mcap => {
            let mut writer = McapWriter::new(out, source.channels)?;
            while let Some(chunk) = reader.next_chunk()? {
                for s in &chunk {
                    writer
                        .write(s)
                        .map_err(|e| anyhow!("writing {}: {e}", path.display()))?;
                }
                count += chunk.len() as u64;
            }
            writer
                .finish()
                .map_err(|e| anyhow!("writing {}: {e}", path.display()))?
        }
    };
    if count == 0 {
        anyhow::bail!("{}: no samples: nothing written", source.name);
    }
    out.commit()?;
    Ok(count)
}
