//! The sensor grade of a column by the grade tables of THEORY.md
//! (`triad_sim::grade::table`, classified by `triad_lab::allan::grade`):
//! its fitted white noise and bias instability in the tables' units, with
//! the scale-factor instability, range and bandwidth of its triad when
//! `--grade-input` gives them. A term the data do not support is graded on
//! its upper limit ([`reported`]): the grade is then one the sensor is known
//! to meet, not one an undetected term happens to allow. A column without a
//! fit (no noise, too few points) has no grade.

use std::str::FromStr;

use triad::model::Triad;
use triad_lab::allan::grade::{classify, Assessment, Classification, GradeError, Verdict};
use triad_lab::allan::noise_terms::{Term, TermEstimate};
use triad_sim::grade::{Parameter, Table, ACCEL_TABLE, GYRO_TABLE};

use super::compute::ColumnResult;
use super::fit::datasheet;

/// Standard deviations of c above the estimate that bound an undetected term.
pub const UPPER_LIMIT_SIGMAS: f64 = 2.0;

/// A term's reported value (SI): the estimate when the data support it,
/// else its upper limit √(c + 2σ_c); and whether it is that limit.
pub fn reported(e: &TermEstimate) -> (f64, bool) {
    if e.significant {
        (e.value, false)
    } else {
        let bound = e.squared.max(0.0) + UPPER_LIMIT_SIGMAS * e.squared_sigma;
        (bound.max(0.0).sqrt(), true)
    }
}

/// The grade table of a triad.
pub fn table(triad: Triad) -> &'static Table {
    match triad {
        Triad::Gyro => &GYRO_TABLE,
        Triad::Accel => &ACCEL_TABLE,
    }
}

/// A parameter Allan variance does not measure, given on the command line
/// (`--grade-input gyro.range=500`), in its row's unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradeInput {
    /// The triad whose columns it applies to.
    pub triad: Triad,
    /// The parameter.
    pub parameter: Parameter,
    /// Its value in the row's unit.
    pub value: f64,
}

/// The parameters `--grade-input` takes, by their key.
const INPUT_KEYS: [(&str, Parameter); 3] = [
    (
        "scale-factor-instability",
        Parameter::ScaleFactorInstability,
    ),
    ("range", Parameter::Range),
    ("bandwidth", Parameter::Bandwidth),
];

/// The keys `--grade-input` takes, with their units: its help text.
pub fn input_keys() -> String {
    let mut keys = Vec::new();
    for triad in [Triad::Gyro, Triad::Accel] {
        for (key, p) in INPUT_KEYS {
            let unit = table(triad).row(p).map_or("?", |r| r.unit);
            keys.push(format!("{}.{key} ({unit})", triad.name()));
        }
    }
    keys.join(", ")
}

impl FromStr for GradeInput {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let expected = || format!("expected TRIAD.KEY=NUMBER, KEY one of {}", input_keys());
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| format!("\"{s}\": {}", expected()))?;
        let (triad, name) = key
            .split_once('.')
            .ok_or_else(|| format!("\"{key}\": {}", expected()))?;
        let triad = match triad {
            "gyro" => Triad::Gyro,
            "accel" => Triad::Accel,
            _ => return Err(format!("\"{triad}\" is not gyro or accel; {}", expected())),
        };
        let parameter = INPUT_KEYS
            .iter()
            .find(|(k, _)| *k == name)
            .map(|(_, p)| *p)
            .ok_or_else(|| format!("\"{name}\" is not a key; {}", expected()))?;
        let value: f64 = value
            .trim()
            .parse()
            .map_err(|_| format!("\"{value}\" is not a number (the row's unit is implied)"))?;
        if !(value.is_finite() && value >= 0.0) {
            return Err(format!(
                "{key} = {value}: must be a finite, non-negative number"
            ));
        }
        Ok(GradeInput {
            triad,
            parameter,
            value,
        })
    }
}

/// A column's grade: the classification by its triad's table and the
/// parameters graded on an upper limit.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnGrade {
    /// The table it was graded by.
    pub table: &'static Table,
    /// The classification.
    pub classification: Classification,
    /// The Allan terms not detected, graded on their upper limit.
    pub limits: Vec<Term>,
}

impl ColumnGrade {
    /// The overall grade in words ("tactical", "between tactical and aviation").
    pub fn name(&self) -> String {
        self.classification.overall.describe(self.table).to_string()
    }

    /// The parameters that decide it, in words ("white noise", "white
    /// noise and bias instability", "a, b and c").
    pub fn decided_by(&self) -> String {
        let names: Vec<&str> = self
            .classification
            .decided_by()
            .map(Parameter::name)
            .collect();
        match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => names.concat(),
        }
    }

    /// The unit of a parameter's row.
    pub fn unit(&self, p: Parameter) -> &'static str {
        self.table.row(p).map_or("", |r| r.unit)
    }

    /// What the table says of one parameter, with the cells involved:
    /// "aviation (< 0.05)", "between tactical (1–10) and aviation (< 0.1)",
    /// "worse than rate grade (> 10)", "fits rate grade (50–1000), aviation (50–300)".
    pub fn verdict(&self, a: &Assessment) -> String {
        let cell = |i: usize| {
            let name = self.table.grades.get(i).copied().unwrap_or("?");
            match self.table.cell(a.parameter, i) {
                Some(c) => format!("{name} ({c})"),
                None => name.to_string(),
            }
        };
        use triad_lab::allan::grade::Placement;
        match a.verdict {
            Verdict::Placed(Placement::In(i)) => cell(i),
            Verdict::Placed(Placement::Between { worse, better }) => {
                format!("between {} and {}", cell(worse), cell(better))
            }
            Verdict::Placed(Placement::Worse) => format!("worse than {}", cell(0)),
            Verdict::Fits(mask) => {
                let fits: Vec<String> = (0..self.table.grades.len())
                    .filter(|i| mask & (1 << i) != 0)
                    .map(cell)
                    .collect();
                if fits.is_empty() {
                    "fits no grade's row".into()
                } else {
                    format!("fits {}", fits.join(", "))
                }
            }
        }
    }
}

/// The grade of a column, with the inputs given for its triad; None without a fit.
pub fn grade_of(
    col: &ColumnResult,
    inputs: &[GradeInput],
) -> Option<Result<ColumnGrade, GradeError>> {
    let fit = col.fit.as_ref().ok()?;
    let mut values = Vec::new();
    let mut limits = Vec::new();
    for (term, p) in [
        (Term::WhiteNoise, Parameter::Noise),
        (Term::BiasInstability, Parameter::BiasInstability),
    ] {
        let (v, is_limit) = reported(fit.term(term));
        values.push((p, v * datasheet(col.triad, term).0));
        if is_limit {
            limits.push(term);
        }
    }
    values.extend(
        inputs
            .iter()
            .filter(|i| i.triad == col.triad)
            .map(|i| (i.parameter, i.value)),
    );
    let table = table(col.triad);
    Some(classify(table, &values).map(|classification| ColumnGrade {
        table,
        classification,
        limits,
    }))
}

/// A value of a grade line with 4 significant digits, in exponent form
/// outside 1e-3 … 1e5.
pub fn figure(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if (-3.0..5.0).contains(&magnitude) {
        let decimals = (3.0 - magnitude).max(0.0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::fit::NoFit;
    use triad::units;

    fn column_with(n: f64, b: f64) -> ColumnResult {
        let term = |value: f64| TermEstimate {
            value,
            sigma: value / 100.0,
            squared: value * value,
            squared_sigma: value * value / 50.0,
            in_support: true,
            z: 50.0,
            significant: true,
            ..TermEstimate::ZERO
        };
        let mut fit = triad_lab::allan::noise_terms::NoiseFit {
            terms: [TermEstimate::ZERO; 5],
            chi2: 1.0,
            dof: 1,
            inflation: 1.0,
        };
        fit.terms[Term::WhiteNoise as usize] = term(n);
        fit.terms[Term::BiasInstability as usize] = term(b);
        ColumnResult {
            name: "gx".into(),
            triad: Triad::Gyro,
            points: Vec::new(),
            fit: Ok(fit),
        }
    }

    #[test]
    fn grades_come_from_data_sheet_values() {
        // A tactical gyro: ARW 0.1 °/√h, bias instability 3 °/h.
        let n = units::arw_deg_per_sqrt_h_to_si(0.1);
        let b = units::deg_per_h_to_rad_per_s(3.0);
        let g = grade_of(&column_with(n, b), &[]).unwrap().unwrap();
        assert_eq!(g.name(), "tactical");
        assert_eq!(g.decided_by(), "white noise and bias instability");
        let sf: GradeInput = "gyro.scale-factor-instability=0.05".parse().unwrap();
        let g = grade_of(&column_with(n, b), &[sf]).unwrap().unwrap();
        assert_eq!(
            g.decided_by(),
            "white noise, bias instability and scale-factor instability"
        );
        // In the gap of the bias-instability row.
        let b = units::deg_per_h_to_rad_per_s(0.5);
        let n = units::arw_deg_per_sqrt_h_to_si(0.01);
        let g = grade_of(&column_with(n, b), &[]).unwrap().unwrap();
        assert_eq!(g.name(), "between tactical and aviation");
        assert_eq!(g.decided_by(), "bias instability");
        let a = g.classification.of(Parameter::BiasInstability).unwrap();
        assert_eq!(g.verdict(a), "between tactical (1–10) and aviation (< 0.1)");
        // A scale-factor instability given for the gyros decides.
        let input: GradeInput = "gyro.scale-factor-instability=0.5".parse().unwrap();
        let other: GradeInput = "accel.range=16".parse().unwrap();
        let g = grade_of(
            &column_with(n, units::deg_per_h_to_rad_per_s(0.03)),
            &[input, other],
        )
        .unwrap()
        .unwrap();
        assert_eq!(
            (g.name().as_str(), g.decided_by().as_str()),
            ("rate grade", "scale-factor instability")
        );
        assert!(
            g.classification.of(Parameter::Range).is_none(),
            "accel input on a gyro"
        );
    }

    #[test]
    fn figures_have_four_significant_digits() {
        assert_eq!(figure(0.14985), "0.1499");
        assert_eq!(figure(300.0), "300.0");
        assert_eq!(figure(20029.0), "20029");
        assert_eq!(figure(0.0015), "0.001500");
        assert_eq!(figure(0.0005), "5.000e-4");
        assert_eq!(figure(2.5e-5), "2.500e-5");
        assert_eq!(figure(0.0), "0");
    }

    #[test]
    fn grade_inputs_are_read_or_refused_with_the_reason() {
        let i: GradeInput = "accel.bandwidth=200".parse().unwrap();
        assert_eq!(
            (i.triad, i.parameter, i.value),
            (Triad::Accel, Parameter::Bandwidth, 200.0)
        );
        for (bad, why) in [
            ("gyro.range", "expected TRIAD.KEY=NUMBER"),
            ("mag.range=1", "\"mag\" is not gyro or accel"),
            ("gyro.cost=1", "\"cost\" is not a key"),
            ("gyro.range=fast", "\"fast\" is not a number"),
            ("gyro.range=-3", "must be a finite, non-negative number"),
        ] {
            let e = bad.parse::<GradeInput>().unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
        }
        assert!(input_keys().contains("gyro.scale-factor-instability (%)"));
        assert!(input_keys().contains("accel.scale-factor-instability (ppm)"));
    }

    #[test]
    fn the_tables_units_are_the_reports_units() {
        for triad in [Triad::Gyro, Triad::Accel] {
            let t = table(triad);
            assert_eq!(
                t.row(Parameter::Noise).unwrap().unit,
                datasheet(triad, Term::WhiteNoise).1
            );
            assert_eq!(
                t.row(Parameter::BiasInstability).unwrap().unit,
                datasheet(triad, Term::BiasInstability).1
            );
        }
    }

    #[test]
    fn no_fit_no_grade() {
        let col = ColumnResult {
            name: "gx".into(),
            triad: Triad::Gyro,
            points: Vec::new(),
            fit: Err(NoFit::NoNoise),
        };
        assert!(grade_of(&col, &[]).is_none());
    }
}
