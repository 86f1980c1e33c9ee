//! Sample times as loggers write them: stamps that repeat (a clock coarser
//! than the sample period: 10 ms stamps at 200 Hz), jitter (stamps taken by
//! a host when a USB packet arrives), lines out of order, small gaps (lost
//! frames) and large ones (the logger paused).
//!
//! The method: the line order is the sample order, and the stamps are noisy
//! readings of a clock that ticks once per sample. The sample period T is
//! the median of the mean periods of consecutive windows of [`WINDOW`]
//! stamps (a window's mean is within one clock quantum / [`WINDOW`] of T
//! however coarse the stamps; the median ignores the few windows with a gap
//! or an outlier). A step of more than [`GAP_PERIODS`] periods splits the
//! record into parts, which fits treat as separate records (no motion is
//! integrated across one). Within a part, sample k gets t̂ = t₀ + k·T, t₀
//! the median of tₖ − k·T; the largest departure |tₖ − t̂ₖ| is reported
//! (smaller gaps, whose lost samples are not inserted, show there). A
//! record is refused only when it cannot be timed at all: fewer than two
//! samples, a stamp that is not a number, or no positive period (every
//! stamp the same); then pass the rate instead ([`from_rate`]).
//!
//! Pure functions on slices, no allocation: the caller owns the buffers.

use core::ops::Range;

/// Stamps per window of the period estimate.
pub const WINDOW: usize = 32;

/// A step between stamps of more than this many periods splits the record.
pub const GAP_PERIODS: f64 = 10.0;

/// Where the stamps jump ahead of the line by more than this many periods
/// (and more than the clock's quantum) between two samples, samples were
/// lost: a small gap, counted, not split.
pub const SMALL_GAP_PERIODS: f64 = 1.5;

/// What the repair found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeBase {
    /// The sample period, s.
    pub period: f64,
    /// Parts the record was split into at large gaps (1: none).
    pub parts: usize,
    /// Stamps equal to the previous one.
    pub repeated: usize,
    /// Stamps before the previous one.
    pub backwards: usize,
    /// Jumps of the stamps ahead of the line by more than
    /// [`SMALL_GAP_PERIODS`] periods (and the clock's quantum) within a part.
    pub small_gaps: usize,
    /// The largest |stamp − repaired time|, s.
    pub largest_departure: f64,
    /// The sample (0-based) where it is.
    pub departure_at: usize,
    /// True when the times came from a given rate, not from stamps.
    pub from_rate: bool,
}

impl TimeBase {
    /// A straight line at `period` with nothing repaired yet.
    fn line(period: f64, from_rate: bool) -> TimeBase {
        TimeBase {
            period,
            parts: 1,
            repeated: 0,
            backwards: 0,
            small_gaps: 0,
            largest_departure: 0.0,
            departure_at: 0,
            from_rate,
        }
    }

    /// True when the stamps needed more than a straight line through them:
    /// repeated or backward stamps, gaps, or a departure over half a period.
    pub fn repaired(&self) -> bool {
        !self.from_rate
            && (self.repeated + self.backwards + self.small_gaps > 0
                || self.parts > 1
                || self.largest_departure > 0.5 * self.period)
    }
}

/// Why a record cannot be timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeError {
    /// Fewer than two samples.
    TooFew {
        /// Samples.
        samples: usize,
    },
    /// A stamp is not a finite number.
    NotFinite {
        /// The sample (0-based).
        sample: usize,
    },
    /// No positive period: the stamps do not advance.
    NoPeriod {
        /// Samples.
        samples: usize,
        /// The first stamp.
        first: f64,
        /// The last stamp.
        last: f64,
    },
    /// A given rate is not a positive finite number.
    InvalidRate {
        /// The rate, Hz.
        rate: f64,
    },
    /// The caller's buffers are shorter than the record.
    BufferTooShort {
        /// Samples.
        samples: usize,
    },
}

impl core::fmt::Display for TimeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            TimeError::TooFew { samples } => write!(
                f,
                "{samples} sample(s): cannot tell the sample rate from fewer than 2 stamps; pass --rate HZ"
            ),
            TimeError::NotFinite { sample } => write!(
                f,
                "sample {}: the time stamp is not a finite number",
                sample + 1
            ),
            TimeError::NoPeriod {
                samples,
                first,
                last,
            } => write!(
                f,
                "the {samples} time stamps do not advance (first {first}, last {last}): cannot tell the sample \
                 rate from them; pass --rate HZ (the rate the unit was configured to)"
            ),
            TimeError::InvalidRate { rate } => {
                write!(f, "--rate {rate}: must be a positive number of Hz")
            }
            TimeError::BufferTooShort { samples } => {
                write!(f, "the output buffers hold fewer than {samples} samples")
            }
        }
    }
}

/// The median of `v` (reordered), NaN when empty.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// The sample period of `stamps` (n ≥ 2): the median of the mean periods
/// of consecutive windows of [`WINDOW`] steps; `scratch` holds at least
/// n / [`WINDOW`] + 1 values.
pub fn period(stamps: &[f64], scratch: &mut [f64]) -> f64 {
    let steps = stamps.len().saturating_sub(1);
    let w = WINDOW.min(steps).max(1);
    let windows = (steps / w).min(scratch.len());
    for (k, s) in scratch[..windows].iter_mut().enumerate() {
        *s = (stamps[(k + 1) * w] - stamps[k * w]) / w as f64;
    }
    median(&mut scratch[..windows])
}

/// Repairs `stamps` (s, in line order) into `times` (same length): one
/// straight line t₀ + k·T per part, the record split where a step exceeds
/// [`GAP_PERIODS`] periods; the first sample of each part goes to
/// `part_starts` (as long as the record), and [`part`] reads them back (the first [`TimeBase::parts`] entries).
pub fn repair(
    stamps: &[f64],
    times: &mut [f64],
    part_starts: &mut [usize],
) -> Result<TimeBase, TimeError> {
    let n = stamps.len();
    if n < 2 {
        return Err(TimeError::TooFew { samples: n });
    }
    if times.len() < n || part_starts.len() < n {
        return Err(TimeError::BufferTooShort { samples: n });
    }
    if let Some(sample) = stamps.iter().position(|t| !t.is_finite()) {
        return Err(TimeError::NotFinite { sample });
    }
    let period = period(stamps, times);
    if !(period > 0.0 && period.is_finite()) {
        return Err(TimeError::NoPeriod {
            samples: n,
            first: stamps[0],
            last: stamps[n - 1],
        });
    }
    // The clock's quantum: the median step between stamps that differ (the
    // period itself for fine stamps, 10 ms for a 10 ms clock).
    let mut steps = 0;
    for i in 1..n {
        let step = stamps[i] - stamps[i - 1];
        if step > 0.0 && steps < times.len() {
            times[steps] = step;
            steps += 1;
        }
    }
    let quantum = median(&mut times[..steps]).max(period);
    let mut base = TimeBase::line(period, false);
    part_starts[0] = 0;
    for i in 1..n {
        let step = stamps[i] - stamps[i - 1];
        if step > GAP_PERIODS * period {
            part_starts[base.parts] = i;
            base.parts += 1;
        } else if step == 0.0 {
            base.repeated += 1;
        } else if step < 0.0 {
            base.backwards += 1;
        }
    }
    for p in 0..base.parts {
        let range = part(part_starts, base.parts, p, n);
        let first = range.start;
        // t₀: the median of tₖ − k·T over the part.
        for (k, i) in range.clone().enumerate() {
            times[i] = stamps[i] - k as f64 * period;
        }
        let t0 = median(&mut times[range.clone()]);
        let mut previous = 0.0;
        for i in range {
            times[i] = t0 + (i - first) as f64 * period;
            let ahead = stamps[i] - times[i];
            if i > first && ahead - previous > (SMALL_GAP_PERIODS * period).max(quantum) {
                base.small_gaps += 1;
            }
            previous = ahead;
            let departure = ahead.abs();
            if departure > base.largest_departure {
                base.largest_departure = departure;
                base.departure_at = i;
            }
        }
    }
    Ok(base)
}

/// Times k / `rate` for `n` samples into `times`: the stamps ignored.
pub fn from_rate(n: usize, rate: f64, times: &mut [f64]) -> Result<TimeBase, TimeError> {
    if !(rate > 0.0 && rate.is_finite()) {
        return Err(TimeError::InvalidRate { rate });
    }
    if times.len() < n {
        return Err(TimeError::BufferTooShort { samples: n });
    }
    for (k, t) in times[..n].iter_mut().enumerate() {
        *t = k as f64 / rate;
    }
    Ok(TimeBase::line(1.0 / rate, true))
}

/// Part `p` of `parts` (from [`repair`]'s `part_starts`) of a record of `n` samples.
pub fn part(part_starts: &[usize], parts: usize, p: usize, n: usize) -> Range<usize> {
    let end = if p + 1 < parts { part_starts[p + 1] } else { n };
    part_starts[p]..end
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(stamps: &[f64]) -> (TimeBase, [f64; 64], [usize; 64]) {
        let mut times = [0.0; 64];
        let mut starts = [0usize; 64];
        let base = repair(stamps, &mut times[..stamps.len()], &mut starts).unwrap();
        (base, times, starts)
    }

    #[test]
    fn clean_stamps_are_kept() {
        let stamps: [f64; 50] = core::array::from_fn(|k| 3.0 + k as f64 * 0.01);
        let (base, times, _) = run(&stamps);
        assert!((base.period - 0.01).abs() < 1e-12);
        assert_eq!((base.parts, base.repeated, base.backwards), (1, 0, 0));
        assert!(!base.repaired());
        for (t, s) in times.iter().zip(stamps) {
            assert!((t - s).abs() < 1e-9);
        }
    }

    #[test]
    fn stamps_quantised_coarser_than_the_period_get_their_own_times() {
        // 200 Hz stamped at 10 ms resolution: pairs share a stamp.
        let stamps: [f64; 64] =
            core::array::from_fn(|k| 100.0 + ((k as f64 * 0.005) / 0.01).floor() * 0.01);
        let (base, times, _) = run(&stamps);
        assert!(
            (base.period - 0.005).abs() < 0.01 / WINDOW as f64,
            "{base:?}"
        );
        assert_eq!(base.repeated, 32);
        assert!(base.repaired());
        assert!(times.windows(2).all(|w| w[1] > w[0]));
        assert!(base.largest_departure <= 0.01, "{base:?}");
    }

    #[test]
    fn an_out_of_order_line_is_put_back_on_the_line_and_a_gap_splits() {
        let mut stamps: [f64; 60] = core::array::from_fn(|k| k as f64 * 0.01);
        stamps.swap(10, 11);
        for s in &mut stamps[40..] {
            *s += 5.0;
        }
        let (base, times, starts) = run(&stamps);
        assert_eq!((base.parts, base.backwards), (2, 1));
        assert_eq!(part(&starts, base.parts, 1, 60), 40..60);
        assert!((times[10] - 0.10).abs() < 1e-9 && (times[11] - 0.11).abs() < 1e-9);
        assert!((times[40] - 5.40).abs() < 1e-9);
        assert!((base.largest_departure - 0.01).abs() < 1e-9);
    }

    #[test]
    fn a_record_that_cannot_be_timed_is_refused_saying_what_to_pass() {
        let mut times = [0.0; 4];
        let mut starts = [0; 4];
        let e = repair(&[2.0; 4], &mut times, &mut starts).unwrap_err();
        assert_eq!(
            e,
            TimeError::NoPeriod {
                samples: 4,
                first: 2.0,
                last: 2.0
            }
        );
        assert_eq!(
            repair(&[1.0], &mut times, &mut starts),
            Err(TimeError::TooFew { samples: 1 })
        );
        assert_eq!(
            repair(&[1.0, f64::NAN], &mut times, &mut starts),
            Err(TimeError::NotFinite { sample: 1 })
        );
        let base = from_rate(4, 100.0, &mut times).unwrap();
        assert_eq!(times, [0.0, 0.01, 0.02, 0.03]);
        assert!(base.from_rate && !base.repaired());
        assert_eq!(
            from_rate(4, 0.0, &mut times),
            Err(TimeError::InvalidRate { rate: 0.0 })
        );
    }
}
