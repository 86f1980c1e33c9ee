//! `--json`: the fitted terms with their uncertainties (data-sheet units and
//! SI), whether the data support each (`significant`, its `z`), the τ range
//! that decided it and its share of σ²(τ) there, or its upper limit; the
//! fit's statistics; the grade with each parameter's place in THEORY.md's
//! tables; and the curve of every column. A column
//! without a fit has `"fit": null`, `"terms": {}`, `"grade": null` and its
//! reason in `"no_fit"`.

use serde_json::{json, Map, Value};
use triad::model::Triad;
use triad::units;
use triad_lab::allan::gls::SIGNIFICANCE_Z;
use triad_lab::allan::grade::{Placement, Verdict};
use triad_lab::allan::noise_terms::{NoiseFit, Term, TermEstimate};

use super::compute::{Analysis, ColumnResult};
use super::fit::{datasheet, si_unit, NoFit};
use super::grade::{grade_of, reported, ColumnGrade, GradeInput};
use super::AllanArgs;

/// The whole report.
pub fn report(args: &AllanArgs, a: &Analysis) -> Value {
    let columns: Vec<Value> = a
        .columns
        .iter()
        .map(|c| column(c, &args.grade_input))
        .collect();
    json!({
        "input": crate::plumbing::input::name(&args.input),
        "samples": a.samples,
        "rate_hz": a.rate,
        "rate_from": a.rate_source,
        "confidence": args.confidence,
        "tau": if args.all_tau { "every m" } else { "octave" },
        "columns": columns,
    })
}

/// One column: its terms, grade, fit statistics and curve.
fn column(col: &ColumnResult, inputs: &[GradeInput]) -> Value {
    let terms = col
        .fit
        .as_ref()
        .map_or_else(|_| Map::new(), |fit| terms(col.triad, fit));
    let grade = grade_of(col, inputs).map(|g| match g {
        Ok(g) => grade(&g),
        Err(why) => json!({"grade": null, "error": why.to_string()}),
    });
    let curve: Vec<_> = col
        .points
        .iter()
        .map(|p| json!({"tau": p.tau, "oadev": p.avar.sqrt(), "ci_low": p.ci.0, "ci_high": p.ci.1, "edf": p.edf, "stride": p.stride}))
        .collect();
    let fit = col.fit.as_ref().ok().map(|f| {
        json!({
            "method": "generalised least squares, covariance of the overlapping estimates",
            "chi2": f.chi2,
            "dof": f.dof,
            "sigma_scale": f.inflation,
            "significance_z": SIGNIFICANCE_Z,
        })
    });
    let no_fit = col.fit.as_ref().err().map(|e| match e {
        NoFit::NoNoise => json!({"reason": "no noise detected", "message": e.to_string()}),
        NoFit::TooFewPoints { count, needed } => json!({
            "reason": "too few tau points", "points": count, "needed": needed, "message": e.to_string()
        }),
        NoFit::Failed(_) => json!({"reason": "failed", "message": e.to_string()}),
    });
    json!({
        "column": col.name,
        "kind": col.triad.name(),
        "unit": si_unit(col.triad),
        "terms": terms,
        "grade": grade,
        "fit": fit,
        "no_fit": no_fit,
        "curve": curve,
    })
}

/// The grade: overall (with the grades it lies between in a gap of the
/// table), what decides it, and each parameter with its unit, its place and
/// the cells of the rows involved.
fn grade(g: &ColumnGrade) -> Value {
    let c = &g.classification;
    let between = match c.overall {
        Placement::Between { worse, better } => {
            json!([g.table.grades[worse], g.table.grades[better]])
        }
        _ => Value::Null,
    };
    let parameters: Vec<Value> = c
        .assessments()
        .map(|a| {
            let fits = match a.verdict {
                Verdict::Fits(mask) => json!((0..g.table.grades.len())
                    .filter(|i| mask & (1 << i) != 0)
                    .map(|i| g.table.grades[i])
                    .collect::<Vec<_>>()),
                Verdict::Placed(_) => Value::Null,
            };
            let place = match a.verdict {
                Verdict::Placed(p) => json!(p.describe(g.table).to_string()),
                Verdict::Fits(_) => Value::Null,
            };
            json!({
                "parameter": a.parameter.name(),
                "value": a.value,
                "unit": g.unit(a.parameter),
                "grade": place,
                "fits": fits,
                "verdict": g.verdict(a),
            })
        })
        .collect();
    let limits: Vec<&str> = g.limits.iter().map(|t| t.symbol()).collect();
    json!({
        "grade": g.name(),
        "between": between,
        "decided_by": g.decided_by(),
        "table": g.table.name,
        "upper_limits": limits,
        "parameters": parameters,
    })
}

/// One term: value, σ, unit, the test and the τ range that decided it.
fn term(e: &TermEstimate, factor: f64, unit: &str) -> Value {
    let (limit, is_limit) = reported(e);
    let range = if e.significant {
        json!([e.tau_range.0, e.tau_range.1])
    } else {
        Value::Null
    };
    json!({
        "value": e.value * factor,
        "sigma": e.sigma * factor,
        "unit": unit,
        "significant": e.significant,
        "z": e.z,
        "upper_limit": if is_limit { json!(limit * factor) } else { Value::Null },
        "tau_range_s": range,
        "share": e.share,
        "fitted": e.in_support,
        "si": e.value,
        "si_sigma": e.sigma,
    })
}

/// Each term by its symbol; an accelerometer's N also as a velocity random walk.
fn terms(triad: Triad, fit: &NoiseFit) -> Map<String, Value> {
    let mut terms = Map::new();
    for t in Term::ALL {
        let (f, unit) = datasheet(triad, t);
        terms.insert(t.symbol().to_string(), term(fit.term(t), f, unit));
    }
    if triad == Triad::Accel {
        let f = units::SQRT_SECONDS_PER_HOUR;
        terms.insert(
            "N_vrw".into(),
            term(fit.term(Term::WhiteNoise), f, "m/s/sqrt(h)"),
        );
    }
    terms
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::table::tests::column;
    use crate::allan::tests::args;

    #[test]
    fn the_report_carries_the_run_and_each_column() {
        let a = Analysis {
            samples: 100,
            rate: 10.0,
            rate_source: "t column",
            columns: vec![column("gx", Triad::Gyro), column("ay", Triad::Accel)],
        };
        let v = report(&args("in.csv"), &a);
        assert_eq!(v["input"], "in.csv");
        assert_eq!(v["samples"], 100);
        assert_eq!(v["tau"], "octave");
        assert_eq!(v["rate_from"], "t column");
        let c = &v["columns"][1];
        assert_eq!(c["column"], "ay");
        assert_eq!(c["kind"], "accel");
        assert_eq!(c["unit"], "m/s^2");
        // No fit: no terms, no grade, no fit statistics, the reason; the curve is there.
        assert_eq!(c["terms"], json!({}));
        assert!(c["grade"].is_null() && c["fit"].is_null());
        assert_eq!(c["no_fit"]["reason"], "no noise detected");
        assert_eq!(c["curve"][0]["oadev"], 2.0);
        assert_eq!(c["curve"].as_array().map(Vec::len), Some(2));
    }
}
