//! The report on stdout: the record, then per column its τ range, the fit
//! (generalised least squares, its χ² and the test a term must pass), each
//! term in data-sheet units — with its uncertainty, its z and the τ range
//! that decided it when the data support it, else its upper limit — and the
//! grade by THEORY.md's tables with each parameter's place in them, or why
//! the column has none.

use std::io::Write;

use triad_lab::allan::gls::SIGNIFICANCE_Z;
use triad_lab::allan::noise_terms::{NoiseFit, Term};

use super::compute::{Analysis, ColumnResult};
use super::fit::{datasheet, si_unit};
use super::grade::{figure, grade_of, reported, ColumnGrade, UPPER_LIMIT_SIGMAS};
use super::AllanArgs;

/// Writes the report of `a` to `w`.
pub fn write(w: &mut impl Write, args: &AllanArgs, a: &Analysis) -> anyhow::Result<()> {
    writeln!(
        w,
        "{}: {} samples at {} Hz ({}), {} s; {} tau, {:.1} % confidence intervals",
        crate::plumbing::input::name(&args.input),
        a.samples,
        a.rate,
        a.rate_source,
        a.samples as f64 / a.rate,
        if args.all_tau { "every" } else { "octave" },
        100.0 * args.confidence
    )?;
    for col in &a.columns {
        write_column(w, args, col)?;
    }
    Ok(())
}

/// One column: its heading, its fit, its terms and its grade.
fn write_column(w: &mut impl Write, args: &AllanArgs, col: &ColumnResult) -> anyhow::Result<()> {
    let (first, last) = (col.points.first(), col.points.last());
    writeln!(
        w,
        "\n{} ({}, {}): tau {} .. {} s",
        col.name,
        col.triad.name(),
        si_unit(col.triad),
        first.map_or(f64::NAN, |p| p.tau),
        last.map_or(f64::NAN, |p| p.tau)
    )?;
    let fit = match &col.fit {
        Ok(fit) => fit,
        Err(why) => {
            writeln!(w, "  {why}")?;
            return Ok(());
        }
    };
    writeln!(
        w,
        "  fit: generalised least squares on {} octaves, chi2 {:.1} for {} dof (sigmas x{:.2}); a term is reported at z >= {SIGNIFICANCE_Z}",
        fit.dof + fit.terms.iter().filter(|e| e.in_support).count(),
        fit.chi2,
        fit.dof,
        fit.inflation
    )?;
    write_terms(w, col, fit)?;
    match grade_of(col, &args.grade_input) {
        None => {}
        Some(Err(why)) => writeln!(w, "  grade: none ({why})")?,
        Some(Ok(g)) => write_grade(w, &g)?,
    }
    Ok(())
}

/// The grade line, then a line per parameter graded with the table's cells.
fn write_grade(w: &mut impl Write, g: &ColumnGrade) -> anyhow::Result<()> {
    let note = if g.limits.is_empty() {
        String::new()
    } else {
        let symbols: Vec<&str> = g.limits.iter().map(|t| t.symbol()).collect();
        format!(
            "; {} not detected: graded on its upper limit",
            symbols.join(" and ")
        )
    };
    writeln!(
        w,
        "  grade: {} (decided by {}){note}",
        g.name(),
        g.decided_by()
    )?;
    for a in g.classification.assessments() {
        writeln!(
            w,
            "    {} {} {}: {}",
            a.parameter.name(),
            figure(a.value),
            g.unit(a.parameter),
            g.verdict(a)
        )?;
    }
    Ok(())
}

/// A line per term: symbol, name, then value ± sigma, z and τ range in
/// data-sheet units, or the upper limit of a term the data do not support.
fn write_terms(w: &mut impl Write, col: &ColumnResult, fit: &NoiseFit) -> anyhow::Result<()> {
    for t in Term::ALL {
        let (f, unit) = datasheet(col.triad, t);
        let e = fit.term(t);
        if e.significant {
            writeln!(
                w,
                "  {} {:<17} {:>12.4e} ± {:.2e} {unit}  (z {:.1}; decided by tau {:.3e} .. {:.3e} s)",
                t.symbol(),
                term_name(t),
                e.value * f,
                e.sigma * f,
                e.z,
                e.tau_range.0,
                e.tau_range.1
            )?;
        } else {
            let (limit, _) = reported(e);
            writeln!(
                w,
                "  {} {:<17} not detected: < {:.2e} {unit} ({UPPER_LIMIT_SIGMAS}-sigma upper limit, z {:.1})",
                t.symbol(),
                term_name(t),
                limit * f,
                e.z
            )?;
        }
    }
    Ok(())
}

/// A term's name in the report.
pub fn term_name(t: Term) -> &'static str {
    match t {
        Term::Quantisation => "quantisation",
        Term::WhiteNoise => "white noise",
        Term::BiasInstability => "bias instability",
        Term::RandomWalk => "rate random walk",
        Term::RateRamp => "rate ramp",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::table::tests::column;
    use crate::allan::tests::args;
    use triad::model::Triad;

    #[test]
    fn the_report_names_the_record_and_each_column() {
        let a = Analysis {
            samples: 100,
            rate: 10.0,
            rate_source: "--rate",
            columns: vec![column("gz", Triad::Gyro)],
        };
        let mut out = Vec::new();
        write(&mut out, &args("rec.csv"), &a).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "rec.csv: 100 samples at 10 Hz (--rate), 10 s; octave tau, 68.3 % confidence intervals"
        );
        assert_eq!(lines[1], "");
        assert_eq!(lines[2], "gz (gyro, rad/s): tau 0.1 .. 0.2 s");
        assert!(lines[3].starts_with("  no noise detected"), "{}", lines[3]);
    }

    #[test]
    fn every_term_has_a_distinct_name() {
        let names: std::collections::HashSet<_> = Term::ALL.iter().map(|&t| term_name(t)).collect();
        assert_eq!(names.len(), Term::ALL.len());
        assert_eq!(term_name(Term::RandomWalk), "rate random walk");
    }
}
