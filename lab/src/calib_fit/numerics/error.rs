//! Why a numerical step of a fit failed: what every fit's own error wraps
//! (a value that is not finite, a system the data do not determine, an
//! iteration that did not converge).

use core::fmt;

use crate::calib_fit::numerics::qr::LsError;

/// Why a fit's numerics refused its input or found no solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NumericsError {
    /// An input value is NaN or infinite.
    NonFinite {
        /// The segment (0-based).
        segment: usize,
        /// The value.
        value: f64,
    },
    /// JᵀJ is too badly conditioned: some parameter combination is not determined.
    IllConditioned {
        /// κ of the column-scaled Jacobian (κ(JᵀJ) is its square).
        condition: f64,
        /// The largest accepted.
        limit: f64,
    },
    /// The least-squares problem is rank deficient.
    LeastSquares(LsError),
    /// Levenberg–Marquardt did not converge.
    NoConvergence {
        /// Iterations run.
        iterations: u32,
    },
}

impl From<LsError> for NumericsError {
    fn from(e: LsError) -> Self {
        NumericsError::LeastSquares(e)
    }
}

/// The first value of `values` that is not finite, as the refusal of `segment`.
pub fn check_finite<'a>(
    segment: usize,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), NumericsError> {
    match values.into_iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(NumericsError::NonFinite { segment, value }),
        None => Ok(()),
    }
}

impl fmt::Display for NumericsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            NumericsError::NonFinite { segment, value } => {
                write!(
                    f,
                    "segment {}: value {value} is not a finite number",
                    segment + 1
                )
            }
            NumericsError::IllConditioned { condition, limit } => write!(
                f,
                "the data do not determine the parameters: condition number {condition:.3e} of the \
                 scaled Jacobian exceeds {limit:.0e} (add orientations spread over the sphere)"
            ),
            NumericsError::LeastSquares(e) => write!(f, "{e}"),
            NumericsError::NoConvergence { iterations } => {
                write!(f, "the fit did not converge in {iterations} iterations")
            }
        }
    }
}

/// Refuses a `condition` number (of the column-scaled Jacobian) above `limit`, or NaN.
pub fn check_condition(condition: f64, limit: f64) -> Result<(), NumericsError> {
    if condition.is_nan() || condition > limit {
        return Err(NumericsError::IllConditioned { condition, limit });
    }
    Ok(())
}
