//! The sample interval: the `t` column's uniformity check as the rows come,
//! and the sample rate at the end (from `--rate` or the span of `t`).

use anyhow::bail;

/// Relative jitter of the t column's step tolerated before t is called non-uniform.
const T_JITTER: f64 = 0.01;

/// The uniformity check of the t column.
pub(crate) struct TimeCheck {
    first: f64,
    last: f64,
    step: Option<f64>,
}

impl TimeCheck {
    /// The check from the first row's t.
    pub(crate) fn new(t0: f64) -> Self {
        Self {
            first: t0,
            last: t0,
            step: None,
        }
    }

    /// Checks the next row's t (at `line_no`) against the first step.
    pub(crate) fn next(&mut self, t: f64, line_no: u64) -> anyhow::Result<()> {
        self.next_at(t, || format!("line {line_no}"))
    }

    /// Checks the next row's t (at the place `at` says) against the first step.
    pub(crate) fn next_at(&mut self, t: f64, at: impl Fn() -> String) -> anyhow::Result<()> {
        let dt = t - self.last;
        match self.step {
            None => {
                // Also catches NaN: only a positive step passes.
                if dt.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    bail!(
                        "{}: t = {t} after {}: t must increase (non-positive sample period {dt} s)",
                        at(),
                        self.last
                    );
                }
                self.step = Some(dt);
            }
            Some(step) => {
                // Rounding of printed times: a few ulps of t, plus the jitter allowance.
                let tol = T_JITTER * step + 8.0 * f64::EPSILON * t.abs();
                if (dt - step).abs() > tol {
                    bail!(
                        "{}: t = {t} after {}: step {dt} s differs from the sample period {step} s by more than {} % (non-uniform t: a gap or jitter; resample or give --rate)",
                        at(),
                        self.last,
                        100.0 * T_JITTER
                    );
                }
            }
        }
        self.last = t;
        Ok(())
    }
}

/// The rate to size the ring with before the record is read to its end:
/// `--rate`, else one over t's first step, else 1 Hz.
pub(crate) fn provisional_rate(rate: Option<f64>, time: Option<&TimeCheck>) -> f64 {
    match (rate, time) {
        (Some(r), _) => r,
        (None, Some(TimeCheck { step: Some(s), .. })) => 1.0 / s,
        _ => 1.0,
    }
}

/// The sample rate of `samples` rows and where it came from: `--rate`, else
/// the span of the t column. `name` is the file, in messages.
pub(crate) fn sample_rate(
    rate: Option<f64>,
    time: Option<&TimeCheck>,
    samples: u64,
    name: &str,
) -> anyhow::Result<(f64, &'static str)> {
    match (rate, time) {
        (Some(r), _) => Ok((r, "--rate")),
        (None, Some(tc)) => {
            let span = tc.last - tc.first;
            let r = (samples - 1) as f64 / span;
            if !(r.is_finite() && r > 0.0) {
                bail!("{name}: the t column spans {span} s: no positive sample rate");
            }
            Ok((r, "t column"))
        }
        (None, None) => bail!("{name}: no rows"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checked(ts: &[f64]) -> anyhow::Result<TimeCheck> {
        let mut tc = TimeCheck::new(ts[0]);
        for (i, &t) in ts.iter().enumerate().skip(1) {
            tc.next(t, i as u64 + 2)?;
        }
        Ok(tc)
    }

    #[test]
    fn uniform_t_passes_and_gives_the_rate() {
        let tc = checked(&[0.0, 0.1, 0.2, 0.30000000000000004, 0.4]).unwrap();
        let (rate, from) = sample_rate(None, Some(&tc), 5, "f").unwrap();
        assert!((rate - 10.0).abs() < 1e-12 && from == "t column");
        assert_eq!(provisional_rate(None, Some(&tc)), 10.0);
        assert_eq!(
            sample_rate(Some(3.0), Some(&tc), 5, "f").unwrap(),
            (3.0, "--rate")
        );
    }

    #[test]
    fn a_gap_or_a_step_back_is_an_error_at_its_line() {
        let gap = checked(&[0.0, 1.0, 2.0, 3.5]).err().unwrap().to_string();
        assert!(
            gap.starts_with("line 5: t = 3.5 after 2: step 1.5 s"),
            "{gap}"
        );
        assert!(gap.contains("non-uniform t"), "{gap}");
        let back = checked(&[1.0, 1.0]).err().unwrap().to_string();
        assert!(back.contains("t must increase"), "{back}");
        // Within the 1 % jitter allowance.
        assert!(checked(&[0.0, 1.0, 2.005]).is_ok());
    }

    #[test]
    fn without_rows_or_span_there_is_no_rate() {
        assert_eq!(provisional_rate(None, None), 1.0);
        let err = sample_rate(None, None, 0, "f.csv").unwrap_err().to_string();
        assert_eq!(err, "f.csv: no rows");
        let one = TimeCheck::new(2.0);
        let err = sample_rate(None, Some(&one), 1, "f.csv").unwrap_err();
        assert!(err.to_string().contains("spans 0 s"), "{err}");
    }
}
