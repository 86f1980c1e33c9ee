//! The sensor grade of a column: its fitted white noise and bias
//! instability, in data-sheet units, placed in the grade tables
//! (`triad_lab::allan::grade`). A term the data do not support is graded on
//! its upper limit ([`reported`]): the grade is then one the sensor is
//! known to meet, not one an undetected term happens to allow. A column
//! without a fit (no noise, too few points) has no grade.

use triad::model::Triad;
use triad_lab::allan::grade::{classify_accel, classify_gyro};
use triad_lab::allan::noise_terms::{Term, TermEstimate};

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

/// The grade line of a column: (grade name, decided by); None without a fit.
pub fn grade_of(col: &ColumnResult) -> Option<(String, &'static str)> {
    let fit = col.fit.as_ref().ok()?;
    let (n, _) = reported(fit.term(Term::WhiteNoise));
    let (b, _) = reported(fit.term(Term::BiasInstability));
    Some(grade(col.triad, n, b))
}

/// The grade of a triad whose white noise is `n` and bias instability `b`
/// (SI units): (grade name, decided by).
pub fn grade(triad: Triad, n: f64, b: f64) -> (String, &'static str) {
    let (fn_, _) = datasheet(triad, Term::WhiteNoise);
    let (fb, _) = datasheet(triad, Term::BiasInstability);
    match triad {
        Triad::Gyro => {
            let c = classify_gyro(n * fn_, b * fb);
            (
                c.grade
                    .map_or("below rate grade".into(), |g| g.name().into()),
                c.decided_by.name(),
            )
        }
        Triad::Accel => {
            let c = classify_accel(n * fn_, b * fb);
            (
                c.grade
                    .map_or("below automotive grade".into(), |g| g.name().into()),
                c.decided_by.name(),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::units;

    #[test]
    fn grades_come_from_data_sheet_values() {
        // A tactical gyro: ARW 0.1 °/√h, bias instability 1 °/h.
        let n = 0.1 / units::arw_si_to_deg_per_sqrt_h(1.0);
        let b = 1.0 / units::rad_per_s_to_deg_per_h(1.0);
        let (g, _) = grade(Triad::Gyro, n, b);
        assert_eq!(g, "tactical");
        // A bias instability worse than every row decides.
        let (g, by) = grade(Triad::Gyro, n, 1e4 * b);
        assert_eq!((g.as_str(), by), ("below rate grade", "bias instability"));
        let (g, by) = grade(Triad::Accel, 1.0, 1.0);
        assert_eq!(g, "below automotive grade");
        assert_eq!(by, "white noise and bias instability");
    }

    #[test]
    fn no_fit_no_grade() {
        let col = ColumnResult {
            name: "gx".into(),
            triad: Triad::Gyro,
            points: Vec::new(),
            fit: Err(crate::allan::fit::NoFit::NoNoise),
        };
        assert!(grade_of(&col).is_none());
    }
}
