//! `triad allan`: overlapping Allan deviation of rate columns of a CSV, with
//! χ² confidence intervals, the jointly fitted noise terms of IEEE Std 952
//! (Q, N, B, K, R) in data-sheet units, and the sensor grade.
//!
//! Octave τ (the default) streams: the file is read once (one thread splits
//! and parses, the others integrate, the columns shared among the cores;
//! an MCAP bag's rows are made by the threads that decode its chunks,
//! `mcap_rows`),
//! each column feeds, a block of rows at a time, [`octave_blocks`] for the
//! fully overlapping octaves up to m = 2^17 (the estimator of
//! [`OctaveAccumulator`](triad_lab::allan::accumulate::OctaveAccumulator),
//! each octave one vectorised loop over the block, over a buffer that keeps
//! the last 2^18 cumulative sums and grows to at most 2^20) and, above, up
//! to m_max (2^24 by default, or from `--max-tau`), one
//! [`StridedBlocks`](octave_blocks::StridedBlocks) each: the overlapping
//! estimator of [`StridedOctave`](triad_lab::allan::strided::StridedOctave)
//! with its terms every m/2^17 samples (τ ≥ 2^18·τ₀, 655 s at 400 Hz), over
//! the sums taken every m/2^17 samples, a buffer of at most 2^19.
//! Memory is therefore at most 8 MiB for the octaves up to 2^17 and 4 MiB
//! per octave above, per column (36 MiB at the default m_max) whatever the
//! record's length, and time is
//! linear in N. `--all-tau` holds the whole
//! record in memory (8·N bytes per column) and
//! costs O(N) per τ, O(N·m_max) in all, so its largest m defaults to 2^14
//! (change it with `--max-tau`).
//!
//! Each sample has the mean of the first [`OFFSET_ROWS`](compute::OFFSET_ROWS) rows of its column
//! subtracted before it is integrated, so a mean far above the noise (1 g on
//! an accelerometer) costs no digits (see `triad_lab::allan::accumulate`).
//!
//! The modules, in the order of the work: [`columns`] (the header and the
//! columns analysed), `rows`, `record_rows`, `mcap_rows` and `time` (the
//! rows of a CSV, of a recording's samples, of an MCAP's chunks, and the t
//! column),
//! [`compute`] (streaming the deviations), [`curve`] (the points and their
//! intervals), [`fit`] (the noise terms), [`grade`], and the outputs
//! [`summary`], [`table`], [`json`] and [`plot`].

pub mod columns;
pub mod compute;
pub mod curve;
pub mod fit;
pub mod grade;
pub mod json;
pub mod kalibr;
mod mcap_rows;
pub mod octave_blocks;
mod parallel;
pub mod plot;
mod record_rows;
mod rows;
pub mod summary;
pub mod table;
mod time;

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::bail;
use triad_lab::allan::edf::ONE_SIGMA;

use crate::plumbing::distinct::{self, named, Named};
use crate::plumbing::number::{positive, readable, RATE_WORDS};
use crate::plumbing::outfile::{self, is_stdout};
use crate::plumbing::stdio;

/// Arguments of `triad allan`.
#[derive(clap::Args)]
pub struct AllanArgs {
    /// Input CSV with a header (e.g. `t,ax,ay,az,gx,gy,gz,temp` as `triad sim` writes; SI units; `-`: stdin),
    /// or a recording: EuRoC/TUM-VI CSV, imu_tk text, ROS 1 or 2 bag, MCAP, PX4 ULog (README: Recordings).
    pub input: PathBuf,
    /// Columns to analyse, comma-separated (default: every column whose name
    /// starts with `g` (gyro, rad/s) or `a` (accel, m/s²)).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Sample rate in Hz (default: from the `t` column, which must then be uniform).
    #[arg(long, allow_hyphen_values = true)]
    pub rate: Option<f64>,
    /// Write the table `column,tau,oadev,ci_low,ci_high,m,terms,edf,noise,adev` (SI units;
    /// `-`: standard output, the summary then going to stderr).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write a log-log plot of σ(τ) with confidence bars and the fitted terms (SVG; `-`: standard output).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Print the fitted terms, their uncertainties and the grade as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the noise model Kalibr reads (YAML: noise densities and random
    /// walks in SI, the worst axis per triad; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    pub kalibr: Option<PathBuf>,
    /// Every τ = m·τ₀ (m = 1, 2, 3, … up to 2^14 or --max-tau) instead of
    /// octaves; holds the record in memory, costs N per τ.
    #[arg(long)]
    pub all_tau: bool,
    /// Longest averaging time, seconds (default 2^24 samples; octaves above
    /// 2^17 samples take their terms every m/2^17 samples: at most 4 MiB per octave per column).
    #[arg(long, allow_hyphen_values = true)]
    pub max_tau: Option<f64>,
    /// Confidence level of the intervals (default 0.6827, one sigma).
    #[arg(long, default_value_t = ONE_SIGMA, allow_negative_numbers = true)]
    pub confidence: f64,
    /// A grade-table parameter Allan variance does not measure, graded with
    /// the fitted terms of its triad's columns (repeatable), a number in the
    /// table's unit: gyro.scale-factor-instability (%), gyro.range (deg/s),
    /// gyro.bandwidth (Hz), accel.scale-factor-instability (ppm), accel.range
    /// (g), accel.bandwidth (Hz).
    #[arg(long, value_name = "TRIAD.KEY=NUMBER", allow_hyphen_values = true)]
    pub grade_input: Vec<grade::GradeInput>,
}

/// Runs `triad allan`: the outputs checked before the file is read, all of
/// them written whole before any is put in place, then the summary (or
/// JSON) printed, on stderr when an output went to stdout.
pub fn run(args: AllanArgs) -> anyhow::Result<ExitCode> {
    check(&args)?;
    let outputs: Vec<Named> = [
        ("--out", &args.out),
        ("--plot", &args.plot),
        ("--kalibr", &args.kalibr),
    ]
    .into_iter()
    .filter_map(|(what, p)| p.as_deref().map(|p| named(what, p)))
    .collect();
    distinct::check(&[named("input", &args.input)], &outputs)?;
    let to_stdout = outputs.iter().find(|o| is_stdout(o.path));
    if let (Some(o), true) = (to_stdout, args.json) {
        bail!(
            "--json and {} - both want standard output: give {} a file",
            o.what,
            o.what
        );
    }
    for o in &outputs {
        outfile::probe(o.path)?;
    }
    crate::plumbing::heap::keep_freed_blocks();
    let analysis = compute::analyse(&args)?;
    let mut files = Vec::new();
    if let Some(path) = &args.out {
        files.push(table::write(path, &analysis.columns)?);
    }
    if let Some(path) = &args.plot {
        files.push(plot::write_svg(path, &analysis.columns)?);
    }
    if let Some(path) = &args.kalibr {
        files.push(kalibr::write(path, &analysis, &args.input)?);
    }
    for file in files {
        file.commit()?;
    }
    let mut text = Vec::new();
    if args.json {
        let v = json::report(&args, &analysis);
        writeln!(text, "{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        summary::write(&mut text, &args, &analysis)?;
    }
    stdio::report(&String::from_utf8_lossy(&text), to_stdout.is_some())?;
    Ok(ExitCode::SUCCESS)
}

/// The options that must be in range before the file is read.
fn check(args: &AllanArgs) -> anyhow::Result<()> {
    if !(args.confidence > 0.0 && args.confidence < 1.0) {
        bail!(
            "--confidence {}: must lie strictly between 0 and 1",
            readable(args.confidence)
        );
    }
    if let Some(r) = args.rate {
        positive("--rate", r, RATE_WORDS)?;
    }
    if let Some(t) = args.max_tau {
        positive("--max-tau", t, "must be a positive number of seconds")?;
    }
    for (k, a) in args.grade_input.iter().enumerate() {
        if args.grade_input[..k]
            .iter()
            .any(|b| (b.triad, b.parameter) == (a.triad, a.parameter))
        {
            bail!(
                "--grade-input gives the {} {} twice",
                a.triad.name(),
                a.parameter.name()
            );
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Arguments as the command line gives them for `input` and nothing else.
    pub(crate) fn args(input: &str) -> AllanArgs {
        AllanArgs {
            input: PathBuf::from(input),
            columns: None,
            rate: None,
            out: None,
            plot: None,
            json: false,
            kalibr: None,
            all_tau: false,
            max_tau: None,
            confidence: ONE_SIGMA,
            grade_input: Vec::new(),
        }
    }

    #[test]
    fn out_of_range_options_are_refused_before_reading() {
        assert!(check(&args("x.csv")).is_ok());
        let mut a = args("x.csv");
        a.confidence = 1.0;
        assert!(check(&a)
            .unwrap_err()
            .to_string()
            .contains("--confidence 1"));
        let mut a = args("x.csv");
        a.rate = Some(0.0);
        assert!(check(&a).unwrap_err().to_string().contains("--rate 0"));
        let mut a = args("x.csv");
        a.max_tau = Some(f64::NAN);
        assert!(check(&a).unwrap_err().to_string().contains("--max-tau NaN"));
        let mut a = args("x.csv");
        a.grade_input = vec![
            "gyro.range=300".parse().unwrap(),
            "accel.range=16".parse().unwrap(),
        ];
        assert!(check(&a).is_ok());
        a.grade_input.push("gyro.range=400".parse().unwrap());
        let e = check(&a).unwrap_err().to_string();
        assert!(e.contains("gyro measurement range twice"), "{e}");
    }

    #[test]
    fn the_help_names_every_grade_input_key() {
        use clap::Args;
        let help = AllanArgs::augment_args(clap::Command::new("allan"))
            .render_long_help()
            .to_string()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        assert!(help.contains(&grade::input_keys()), "{help}");
    }
}
