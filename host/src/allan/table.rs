//! `--out`: the curve of every column as a CSV table
//! `column,tau,oadev,ci_low,ci_high,m,terms,edf,noise,adev,decides` (SI
//! units); `decides` names the reported noise terms whose deciding τ range
//! holds the point (`N`, `B;K`, …; empty for none).

use std::io::Write;
use std::path::Path;

use triad_lab::allan::noise_terms::Term;

use super::compute::ColumnResult;
use crate::plumbing::outfile::OutFile;

/// The table's header line.
pub const HEADER: &str = "column,tau,oadev,ci_low,ci_high,m,terms,edf,noise,adev,decides";

/// Writes the table of `columns` for `path`: whole, to be put in place
/// with [`OutFile::commit`].
pub fn write(path: &Path, columns: &[ColumnResult]) -> anyhow::Result<OutFile> {
    let mut out = OutFile::create(path)?;
    render(&mut out, columns).map_err(|e| out.error(e))?;
    Ok(out)
}

/// Writes the table of `columns` to `w`.
pub fn render(w: &mut impl Write, columns: &[ColumnResult]) -> std::io::Result<()> {
    writeln!(w, "{HEADER}")?;
    for col in columns {
        for p in &col.points {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{}",
                col.name,
                p.tau,
                p.avar.sqrt(),
                p.ci.0,
                p.ci.1,
                p.m,
                p.terms,
                p.edf,
                p.noise.name(),
                p.avar_non_overlapping.sqrt(),
                decides(col, p.tau)
            )?;
        }
    }
    Ok(())
}

/// The reported terms whose deciding τ range holds `tau`, `;`-separated.
fn decides(col: &ColumnResult, tau: f64) -> String {
    let Ok(fit) = &col.fit else {
        return String::new();
    };
    Term::ALL
        .into_iter()
        .filter(|&t| {
            let e = fit.term(t);
            e.significant && e.tau_range.0 <= tau && tau <= e.tau_range.1
        })
        .map(|t| t.symbol())
        .collect::<Vec<_>>()
        .join(";")
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::allan::curve::Point;
    use triad::model::Triad;
    use triad_lab::allan::edf::NoiseType;

    /// A column with two points (σ = 2, then 1) and no fit.
    pub(crate) fn column(name: &str, triad: Triad) -> ColumnResult {
        let point = |m: u64, avar: f64| Point {
            m,
            tau: m as f64 / 10.0,
            avar,
            avar_non_overlapping: f64::NAN,
            terms: 9,
            stride: 1,
            noise: NoiseType::from_slope(-1.0),
            edf: 4.5,
            ci: (0.5, 3.0),
        };
        ColumnResult {
            name: name.into(),
            triad,
            points: vec![point(1, 4.0), point(2, 1.0)],
            fit: Err(crate::allan::fit::NoFit::NoNoise),
        }
    }

    #[test]
    fn one_row_per_point_in_the_documented_columns() {
        let mut out = Vec::new();
        render(
            &mut out,
            &[column("gx", Triad::Gyro), column("az", Triad::Accel)],
        )
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 5);
        assert_eq!(lines[0], HEADER);
        let noise = NoiseType::from_slope(-1.0).name();
        assert_eq!(lines[1], format!("gx,0.1,2,0.5,3,1,9,4.5,{noise},NaN,"));
        assert!(lines[4].starts_with("az,0.2,1,"));
    }
}
