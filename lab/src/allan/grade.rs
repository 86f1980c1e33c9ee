//! The sensor grade by the tables of ../shared/THEORY.md
//! ([`triad_sim::grade::table`]): per parameter, the grade whose row holds
//! the value; overall, the worst of them, and the parameter(s) that decide it.
//!
//! - An error parameter (noise, bias instability, scale-factor instability;
//!   [`Parameter::ranks`]) is placed in the best grade whose cell holds it; a
//!   value better than the best row counts as the best grade; one worse than
//!   every row is [`Placement::Worse`]; one in a gap of the table (gyro bias
//!   instability 0.1–1 °/h; accelerometer noise 10–50 µg/√Hz) is
//!   [`Placement::Between`] the grade whose cell lies wholly above it and the
//!   one whose cell lies wholly below: the classifier does not force a grade.
//! - The overall grade is the worst placement of the error parameters (a
//!   sensor is only as good as its worst term; "between X and Y" ranks
//!   between X and Y), and the parameters at that placement decide it.
//! - Range, bandwidth, shock and cost describe a grade but do not rank a
//!   sensor (a 300 °/s range is both rate grade and aviation): for them the
//!   classifier lists every grade whose cell holds the value.
//!
//! Allan variance measures the white noise and the bias instability; the
//! other parameters come from elsewhere (a rate table, a data sheet) when given.

use triad_sim::grade::{Parameter, Table};

/// The most parameters one classification takes (one per [`Parameter`]).
pub const MAX_PARAMETERS: usize = 7;

/// Where an error parameter's value places the sensor (grade indices into
/// the table's grades, worst first).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Worse than every row of the table.
    Worse,
    /// In this grade (the best whose cell holds the value, or better than every row).
    In(usize),
    /// In a gap of the table, between two grades.
    Between {
        /// The grade whose cell lies wholly above the value (worse).
        worse: usize,
        /// The grade whose cell lies wholly below it (better).
        better: usize,
    },
}

impl Placement {
    /// The order of placements: worse than every row, the worst grade, the
    /// gap above the next, the next grade, ...
    pub fn rank(self) -> usize {
        match self {
            Placement::Worse => 0,
            Placement::In(i) => 2 * i + 1,
            Placement::Between { worse, .. } => 2 * worse + 2,
        }
    }

    /// The placement in words, by `table`'s grade names.
    pub fn describe(self, table: &Table) -> Described<'_> {
        Described {
            placement: self,
            table,
        }
    }
}

/// A placement with its table, for display ("tactical", "between tactical
/// and aviation", "worse than rate grade").
#[derive(Clone, Copy, Debug)]
pub struct Described<'a> {
    placement: Placement,
    table: &'a Table,
}

impl core::fmt::Display for Described<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let name = |i: usize| self.table.grades.get(i).copied().unwrap_or("?");
        match self.placement {
            Placement::Worse => write!(f, "worse than {}", name(0)),
            Placement::In(i) => f.write_str(name(i)),
            Placement::Between { worse, better } => {
                write!(f, "between {} and {}", name(worse), name(better))
            }
        }
    }
}

/// What the tables say of one parameter's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// An error parameter: its placement.
    Placed(Placement),
    /// A descriptive parameter: bit i set when grade i's cell holds the value.
    Fits(u8),
}

/// One parameter's value (in its row's unit) and what the table says of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Assessment {
    /// The parameter.
    pub parameter: Parameter,
    /// Its value, in the row's unit.
    pub value: f64,
    /// The table's verdict.
    pub verdict: Verdict,
}

/// A sensor's grade.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Classification {
    /// The overall placement: the worst of the error parameters'.
    pub overall: Placement,
    assessments: [Option<Assessment>; MAX_PARAMETERS],
}

impl Classification {
    /// Every parameter given, in the order given.
    pub fn assessments(&self) -> impl Iterator<Item = &Assessment> {
        self.assessments.iter().flatten()
    }

    /// The error parameters whose placement is the overall one.
    pub fn decided_by(&self) -> impl Iterator<Item = Parameter> + '_ {
        self.assessments().filter_map(move |a| match a.verdict {
            Verdict::Placed(p) if p.rank() == self.overall.rank() => Some(a.parameter),
            _ => None,
        })
    }

    /// The assessment of `parameter`, if it was given.
    pub fn of(&self, parameter: Parameter) -> Option<&Assessment> {
        self.assessments().find(|a| a.parameter == parameter)
    }
}

/// Why a sensor cannot be classified.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GradeError {
    /// The table has no row for the parameter (the accelerometer table has no cost).
    NoRow(Parameter),
    /// The value is negative, infinite or NaN.
    BadValue {
        /// The parameter.
        parameter: Parameter,
        /// Its value.
        value: f64,
    },
    /// A parameter given twice.
    Repeated(Parameter),
    /// No error parameter given: nothing ranks the sensor.
    NothingRanks,
}

impl core::fmt::Display for GradeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GradeError::NoRow(p) => write!(f, "the grade table has no {} row", p.name()),
            GradeError::BadValue { parameter, value } => write!(
                f,
                "{} = {value} cannot be graded: it must be a finite, non-negative number",
                parameter.name()
            ),
            GradeError::Repeated(p) => write!(f, "{} given twice", p.name()),
            GradeError::NothingRanks => write!(
                f,
                "no noise, bias instability or scale-factor instability given: nothing ranks the sensor"
            ),
        }
    }
}

/// The placement of an error parameter's value `x` in its row (`cells`, worst grade first).
pub fn place(cells: &[triad_sim::grade::Cell], x: f64) -> Placement {
    let n = cells.len();
    if let Some(i) = (0..n).rev().find(|&i| cells[i].holds(x)) {
        return Placement::In(i);
    }
    let worse = (0..n).rev().find(|&i| cells[i].above(x));
    let better = (0..n).find(|&i| cells[i].below(x));
    match (worse, better) {
        (Some(worse), Some(better)) => Placement::Between { worse, better },
        // Better than every row: the best grade.
        (Some(_), None) => Placement::In(n.saturating_sub(1)),
        _ => Placement::Worse,
    }
}

/// The grade by `table` of a sensor whose parameters have the given values
/// (each in its row's unit, each at most once).
pub fn classify(table: &Table, values: &[(Parameter, f64)]) -> Result<Classification, GradeError> {
    let mut assessments = [None; MAX_PARAMETERS];
    let mut overall: Option<Placement> = None;
    for (k, &(parameter, value)) in values.iter().enumerate() {
        let row = table.row(parameter).ok_or(GradeError::NoRow(parameter))?;
        if !(value.is_finite() && value >= 0.0) {
            return Err(GradeError::BadValue { parameter, value });
        }
        if values[..k].iter().any(|v| v.0 == parameter) || k >= MAX_PARAMETERS {
            return Err(GradeError::Repeated(parameter));
        }
        let verdict = if parameter.ranks() {
            let p = place(row.cells, value);
            if overall.is_none_or(|o| p.rank() < o.rank()) {
                overall = Some(p);
            }
            Verdict::Placed(p)
        } else {
            let fits = row
                .cells
                .iter()
                .enumerate()
                .filter(|(_, c)| c.holds(value))
                .fold(0u8, |m, (i, _)| m | (1 << i));
            Verdict::Fits(fits)
        };
        assessments[k] = Some(Assessment {
            parameter,
            value,
            verdict,
        });
    }
    Ok(Classification {
        overall: overall.ok_or(GradeError::NothingRanks)?,
        assessments,
    })
}
