//! `triad calib fit accel|gyro`: fit (I+Σ) and b to recorded data and write
//! the calibration file the firmware and `triad correct` read.
//!
//! ```text
//! triad calib fit accel --positions IN.csv [--positions IN2.csv ...] [--segments 0-10,12-22]
//!                       [--gravity 9.80665] [--min-static 2] [--base CAL.toml] --out CAL.toml
//! triad calib fit accel --axis-aligned --positions TUMBLE.csv ... --out CAL.toml   (cube faces: full I+Σ)
//! triad calib fit gyro --rate-table IN.csv [...] --rates "z:+30,z:-30,x:+30,y:+30"
//!                       [--segments ...] [--base CAL.toml] --out CAL.toml
//! triad calib fit gyro --static IN.csv [--latitude DEG] [--base CAL.toml] --out CAL.toml
//! triad calib fit thermal REC.csv [REC2.csv ...] [--bias-only] [--base CAL.toml] --out CAL.toml
//! ```
//!
//! The fitted triad replaces the one in `--base` (default: identity); the
//! other triad, the orientation and the base's `[fit.*]` statistics of the
//! other triad are kept. The fitted triad's temperature terms are dropped (a
//! fit at one temperature says nothing about them). The fit statistics go in
//! `[fit.accel]` / `[fit.gyro]`, which the loader ignores. The file has no
//! `id`: its identity is the CRC-32C of the parameters. The written file is
//! validated as `triad calib check` does before it is written.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use triad::model::{Calibration, Orientation, Triad, TriadCalibration};

use super::{fit_accel, fit_gyro, fit_imu, fit_thermal, Ranges};
use crate::calib::file as calib_file;
use crate::plumbing::distinct::{self, named, Named};
use crate::plumbing::input;
use crate::plumbing::outfile;
use crate::plumbing::stdio;

/// Arguments of `triad calib fit`.
#[derive(clap::Args)]
pub struct FitArgs {
    #[command(subcommand)]
    command: FitCommand,
}

#[derive(clap::Subcommand)]
enum FitCommand {
    /// Accelerometer (I+Σ) and b from static records in unknown orientations.
    Accel(fit_accel::AccelArgs),
    /// Gyroscope (I+Σ) and b from rate-table runs, or its bias from a static record.
    Gyro(fit_gyro::GyroArgs),
    /// Both triads from one record turned by hand between static poses, no rig:
    /// the accelerometer from the poses, the gyroscope by integrating it
    /// between them (Tedaldi, Pretto and Menegatti, ICRA 2014).
    Imu(fit_imu::ImuArgs),
    /// Both triads' temperature terms from records over a temperature range:
    /// the accelerometer's (I+Σ) linear and b cubic in ΔT from poses in
    /// unknown orientations, the gyroscope's bias cubic in ΔT.
    Thermal(fit_thermal::ThermalArgs),
}

/// Where the result goes and what it starts from.
#[derive(clap::Args)]
pub struct Output {
    /// A calibration file to start from (its other triad and orientation are kept); default: identity.
    #[arg(long)]
    pub base: Option<PathBuf>,
    /// The calibration file to write (TOML; `-`: standard output, the
    /// report then going to stderr).
    #[arg(long)]
    pub out: PathBuf,
    /// The sensor's ranges the written file is validated at.
    #[command(flatten)]
    pub ranges: Ranges,
}

impl Output {
    /// Before any work: the ranges in range, `--out` none of the `inputs`
    /// (nor `--base`), its directory there to write in, and the base read
    /// (once: a file, or a shipped calibration such as `default`).
    pub fn prepare(&self, inputs: &[Named]) -> anyhow::Result<Base> {
        self.ranges.check()?;
        let mut all = inputs.to_vec();
        if let Some(base) = &self.base {
            all.push(named("--base", base));
        }
        distinct::check(&all, &[named("--out", &self.out)])?;
        outfile::probe(&self.out)?;
        Base::of(self.base.as_deref())
    }
}

/// `paths` named by the option that gave them.
pub fn inputs<'a>(what: &'a str, paths: &'a [PathBuf]) -> Vec<Named<'a>> {
    paths.iter().map(|p| named(what, p)).collect()
}

/// Runs `triad calib fit`.
pub fn run(args: FitArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        FitCommand::Accel(a) => fit_accel::run(a),
        FitCommand::Gyro(g) => fit_gyro::run(g),
        FitCommand::Imu(i) => fit_imu::run(i),
        FitCommand::Thermal(t) => fit_thermal::run(t),
    }
}

/// The files, for messages: all of them up to three, else first … last (N files).
pub fn names(paths: &[PathBuf]) -> String {
    match paths {
        [first, .., last] if paths.len() > 3 => {
            format!(
                "{} … {} ({} files)",
                first.display(),
                last.display(),
                paths.len()
            )
        }
        _ => paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The input files as a TOML array of strings (`stdin` for `-`).
pub fn file_list<P: AsRef<Path>>(paths: &[P]) -> toml::Value {
    toml::Value::Array(
        paths
            .iter()
            .map(|p| toml::Value::String(input::name(p.as_ref())))
            .collect(),
    )
}

/// What a fit starts from: the calibration, the orientation, the earlier
/// fits' statistics, and a sentence saying where they came from.
pub struct Base {
    /// The base calibration (the identity without `--base`).
    pub calibration: Calibration,
    /// Its mounting orientation.
    pub orientation: Orientation,
    /// Its `[fit]` table.
    fit_meta: toml::Table,
    note: String,
    /// The gyroscope's g-sensitivity a fit of the gyroscope found (the
    /// base's own is dropped with the gyroscope it was fitted with).
    g_sensitivity: Option<[[f64; 3]; 3]>,
}

impl Base {
    /// The base with `triad` already fitted as `fitted` and its statistics
    /// `fit_table` (a fit of both triads writes the second through
    /// [`write_calibration`] on this).
    pub fn with_fitted(
        mut self,
        triad: Triad,
        fitted: TriadCalibration,
        fit_table: toml::Table,
    ) -> Base {
        self.calibration = with_triad(self.calibration, triad, fitted);
        self.fit_meta
            .insert(triad.name().into(), toml::Value::Table(fit_table));
        self
    }

    /// The base with the gyroscope's g-sensitivity `g` found by the fit
    /// that fits the gyroscope ([`write_calibration`] applies it with it).
    pub fn with_g_sensitivity(mut self, g: Option<[[f64; 3]; 3]>) -> Base {
        self.g_sensitivity = g;
        self
    }

    /// The calibration read from `path` (`--base`), or the identity.
    fn of(path: Option<&Path>) -> anyhow::Result<Base> {
        let Some(path) = path else {
            return Ok(Base {
                calibration: Calibration::identity(0),
                orientation: Orientation::RotationNone,
                fit_meta: toml::Table::new(),
                note: "The other triad is the identity (no --base given).".to_string(),
                g_sensitivity: None,
            });
        };
        let file = calib_file::load(path)?;
        Ok(Base {
            calibration: file.calibration,
            orientation: file.orientation,
            fit_meta: file.fit,
            g_sensitivity: None,
            note: format!(
                "The other triad and the orientation are those of {}.",
                path.display()
            ),
        })
    }
}

/// `calibration` with its `triad` replaced by `fitted`.
pub fn with_triad(
    mut calibration: Calibration,
    triad: Triad,
    fitted: TriadCalibration,
) -> Calibration {
    match triad {
        Triad::Accel => calibration.accel = fitted,
        Triad::Gyro => calibration.gyro = fitted,
    }
    calibration
}

/// Puts `fitted` into `base` (from [`Output::prepare`]) as its `triad`,
/// validates it like `triad calib check`, and writes it with the fit's
/// statistics (`fit_table`, as `[fit.accel]` or `[fit.gyro]`) under
/// `header`; then prints the fit's `report` (on stderr when the file goes
/// to stdout). A rejected fit prints the report and writes nothing.
pub fn write_calibration(
    output: &Output,
    mut base: Base,
    triad: Triad,
    fitted: TriadCalibration,
    header: &str,
    fit_table: toml::Table,
    report: &str,
) -> anyhow::Result<ExitCode> {
    let to_stdout = outfile::is_stdout(&output.out);
    let show = |text: &str| stdio::report(text, to_stdout);
    let mut calibration = with_triad(base.calibration, triad, fitted);
    if triad == Triad::Gyro {
        // A G belongs to the gyro fit that found it: the bias of a fit
        // without one has absorbed G·f at its orientation.
        calibration.g_sensitivity = base.g_sensitivity;
    }
    let (a, g) = output.ranges.full_scale_si();
    if let Err(e) = triad::model::Corrector::new_si(&calibration, a, g, base.orientation) {
        show(report)?;
        anyhow::bail!(
            "the fitted calibration is rejected, {} not written: {e}",
            output.out.display()
        );
    }
    base.fit_meta
        .insert(triad.name().into(), toml::Value::Table(fit_table));
    let mut extra = toml::Table::new();
    extra.insert("fit".into(), toml::Value::Table(base.fit_meta));
    let text = calib_file::render(
        &calibration,
        base.orientation,
        &format!("{header}\n{}", base.note),
        extra,
    )?;
    outfile::write_whole(&output.out, text.as_bytes())?;
    if to_stdout {
        show(report)?;
    } else {
        show(&format!("{report}wrote {}\n", output.out.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn many_files_are_named_by_the_first_and_the_last() {
        let paths: Vec<PathBuf> = ["a.csv", "b.csv", "c.csv", "d.csv"]
            .iter()
            .map(PathBuf::from)
            .collect();
        assert_eq!(names(&paths[..3]), "a.csv, b.csv, c.csv");
        assert_eq!(names(&paths), "a.csv … d.csv (4 files)");
        assert_eq!(names(&[]), "");
        let list = file_list(&paths[..2]);
        assert_eq!(list.as_array().map(Vec::len), Some(2));
        assert_eq!(list[1].as_str(), Some("b.csv"));
        assert_eq!(file_list(&[Path::new("-")])[0].as_str(), Some("stdin"));
    }

    #[test]
    fn the_fitted_triad_replaces_only_its_own() {
        let fitted = TriadCalibration {
            scale_misalignment: [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]],
            bias: [1.0, 2.0, 3.0],
            temperature: None,
        };
        let base = Calibration::identity(7);
        let c = with_triad(base, Triad::Gyro, fitted);
        assert_eq!(c.gyro, fitted);
        assert_eq!(c.accel, base.accel);
        let c = with_triad(base, Triad::Accel, fitted);
        assert_eq!((c.accel, c.gyro), (fitted, base.gyro));
    }
}
