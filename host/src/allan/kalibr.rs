//! `triad allan --kalibr imu.yaml`: the noise model Kalibr (and most
//! visual-inertial estimators: OpenVINS, VINS-Fusion, ORB-SLAM3) reads, from
//! the fitted terms: per triad, the continuous-time white-noise density N
//! (`*_noise_density`) and the random-walk coefficient K (`*_random_walk`),
//! in SI units, the worst axis of the triad.
//!
//! IEEE 952's N is Kalibr's noise density and its K Kalibr's random walk,
//! with the same units ((rad/s)/√Hz and (rad/s²)/√Hz for the gyro; m/s² and
//! m/s³ per √Hz for the accelerometer): no factor between them. A term the
//! data do not resolve has no estimate to give; Kalibr needs a number, so
//! the file gives its upper limit (the estimate plus 2σ, as the report does)
//! and says so beside it. A triad with no fitted column is refused: the
//! file would have to invent its numbers.

use std::io::Write;
use std::path::Path;

use anyhow::bail;
use triad::model::Triad;
use triad_lab::allan::noise_terms::Term;

use super::compute::{Analysis, ColumnResult};
use super::grade::reported;
use crate::plumbing::outfile::OutFile;

/// One Kalibr entry: the worst axis's value and where it came from.
struct Entry {
    value: f64,
    column: String,
    upper_limit: bool,
    sigma: f64,
}

/// The worst (largest reported) `term` among the triad's fitted columns.
fn worst(columns: &[&ColumnResult], term: Term) -> Option<Entry> {
    columns
        .iter()
        .filter_map(|c| {
            let fit = c.fit.as_ref().ok()?;
            let e = fit.term(term);
            let (value, upper_limit) = reported(e);
            Some(Entry {
                value,
                column: c.name.clone(),
                upper_limit,
                sigma: e.sigma,
            })
        })
        .max_by(|a, b| a.value.total_cmp(&b.value))
}

/// The triad's Kalibr names and units.
fn names(triad: Triad) -> [(&'static str, &'static str, Term); 2] {
    match triad {
        Triad::Accel => [
            (
                "accelerometer_noise_density",
                "m/s^2/sqrt(Hz)",
                Term::WhiteNoise,
            ),
            (
                "accelerometer_random_walk",
                "m/s^3/sqrt(Hz)",
                Term::RandomWalk,
            ),
        ],
        Triad::Gyro => [
            (
                "gyroscope_noise_density",
                "rad/s/sqrt(Hz)",
                Term::WhiteNoise,
            ),
            (
                "gyroscope_random_walk",
                "rad/s^2/sqrt(Hz)",
                Term::RandomWalk,
            ),
        ],
    }
}

/// Renders the YAML of `analysis` (read from `input`).
pub fn render(w: &mut impl Write, analysis: &Analysis, input: &Path) -> anyhow::Result<()> {
    writeln!(
        w,
        "# IMU noise model for Kalibr, written by `triad allan --kalibr` from {}",
        input.display()
    )?;
    writeln!(
        w,
        "# ({} samples at {} Hz). Continuous-time densities: IEEE 952's N and K,",
        analysis.samples, analysis.rate
    )?;
    writeln!(
        w,
        "# the worst axis of each triad. Kalibr's documentation advises inflating"
    )?;
    writeln!(
        w,
        "# them for a moving sensor (vibration, temperature): these are the bench's."
    )?;
    for triad in [Triad::Accel, Triad::Gyro] {
        let columns: Vec<&ColumnResult> = analysis
            .columns
            .iter()
            .filter(|c| c.triad == triad && c.fit.is_ok())
            .collect();
        if columns.is_empty() {
            bail!(
                "--kalibr: no {} column has fitted noise terms (give --columns with the three \
                 axes of both triads, or a longer record): Kalibr needs both triads",
                triad.name()
            );
        }
        for (name, unit, term) in names(triad) {
            let Some(e) = worst(&columns, term) else {
                continue;
            };
            let how = if e.upper_limit {
                format!(
                    "not resolved by the record: upper limit (estimate + 2σ), worst axis {}",
                    e.column
                )
            } else {
                format!("worst axis {} (σ {:.3e})", e.column, e.sigma)
            };
            writeln!(w, "{name}: {:.6e}  # [{unit}] {how}", e.value)?;
        }
    }
    writeln!(w, "update_rate: {}  # [Hz]", analysis.rate)?;
    writeln!(w, "rostopic: /imu0")?;
    Ok(())
}

/// Writes the Kalibr file (whole or not at all).
pub fn write(path: &Path, analysis: &Analysis, input: &Path) -> anyhow::Result<OutFile> {
    let mut out = OutFile::create(path)?;
    let mut text = Vec::new();
    render(&mut text, analysis, input)?;
    out.write_all(&text).map_err(|e| out.error(e))?;
    Ok(out)
}
