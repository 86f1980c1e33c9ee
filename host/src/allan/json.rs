//! `--json`: the fitted terms with their uncertainties (data-sheet units and
//! SI), the grade and the curve of every column.

use serde_json::{json, Map, Value};
use triad::model::Triad;
use triad::units;
use triad_lab::allan::noise_terms::{NoiseFit, Term};

use super::compute::{Analysis, ColumnResult};
use super::fit::{datasheet, si_unit};
use super::grade::grade_of;
use super::AllanArgs;

/// The whole report.
pub fn report(args: &AllanArgs, a: &Analysis) -> Value {
    let columns: Vec<Value> = a.columns.iter().map(column).collect();
    json!({
        "input": crate::input::name(&args.input),
        "samples": a.samples,
        "rate_hz": a.rate,
        "rate_from": a.rate_source,
        "confidence": args.confidence,
        "tau": if args.all_tau { "every m" } else { "octave" },
        "columns": columns,
    })
}

/// One column: its terms, grade, fit statistics and curve.
fn column(col: &ColumnResult) -> Value {
    let terms = col
        .fit
        .as_ref()
        .map_or_else(Map::new, |fit| terms(col.triad, fit));
    let grade = grade_of(col).map(|(g, d)| json!({"grade": g, "decided_by": d}));
    let curve: Vec<_> = col
        .points
        .iter()
        .map(|p| json!({"tau": p.tau, "oadev": p.avar.sqrt(), "ci_low": p.ci.0, "ci_high": p.ci.1, "edf": p.edf}))
        .collect();
    json!({
        "column": col.name,
        "kind": col.triad.name(),
        "unit": si_unit(col.triad),
        "terms": terms,
        "grade": grade,
        "fit": col.fit.map(|f| json!({"chi2": f.chi2, "dof": f.dof})),
        "curve": curve,
    })
}

/// Each term by its symbol; an accelerometer's N also as a velocity random walk.
fn terms(triad: Triad, fit: &NoiseFit) -> Map<String, Value> {
    let mut terms = Map::new();
    for t in Term::ALL {
        let (f, unit) = datasheet(triad, t);
        let e = fit.term(t);
        terms.insert(
            t.symbol().to_string(),
            json!({
                "value": e.value * f,
                "sigma": e.sigma * f,
                "unit": unit,
                "fitted": e.in_support,
                "si": e.value,
                "si_sigma": e.sigma,
            }),
        );
    }
    if triad == Triad::Accel {
        let e = fit.term(Term::WhiteNoise);
        let f = units::SQRT_SECONDS_PER_HOUR;
        terms.insert(
            "N_vrw".into(),
            json!({"value": e.value * f, "sigma": e.sigma * f, "unit": "m/s/sqrt(h)", "fitted": e.in_support}),
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
        // No fit: no terms, no grade, no fit statistics; the curve is there.
        assert_eq!(c["terms"], json!({}));
        assert!(c["grade"].is_null() && c["fit"].is_null());
        assert_eq!(c["curve"][0]["oadev"], 2.0);
        assert_eq!(c["curve"].as_array().map(Vec::len), Some(2));
    }
}
