//! Which moves between a hand record's consecutive poses the rig-free gyro
//! fit ([`super::rig_free`]) can use: not one that crosses a gap in the time
//! stamps (its turn is not in the record), nor one whose gyro holds a value
//! while turning (a logger repeating samples over lost frames loses the
//! turn), nor one that reaches the gyro's range (the turn may have clipped).
//! What is left out is said with the sample that decided it; the samples
//! beyond the range that lie outside the poses and the kept moves are
//! listed too (the fit ignores them).

use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use crate::calib_fit::fits::rig_free::{self, Record, MAX_RANGE_FRACTION};
use crate::calib_fit::static_segments::{self, Segment};

/// Why a move was left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LeftOut {
    /// Its two poses lie in different parts of the record (a gap between).
    CrossesGap,
    /// The gyro repeats one value for `samples` samples from sample `at`.
    Held {
        /// The run's first sample.
        at: usize,
        /// Its length.
        samples: usize,
    },
    /// The gyro reads `rate` (rad/s) at `sample`, beyond
    /// [`MAX_RANGE_FRACTION`] of its full scale.
    NearRange {
        /// The sample.
        sample: usize,
        /// |axis|, rad/s.
        rate: f64,
    },
}

/// The moves kept and left out.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    /// The moves the fit uses (j: from pose j to pose j+1), in order.
    pub moves: Vec<usize>,
    /// The moves left out, with why.
    pub left_out: Vec<(usize, LeftOut)>,
    /// The samples beyond [`MAX_RANGE_FRACTION`] of the full scale outside
    /// the poses and the kept moves, in order.
    pub outside: Vec<usize>,
}

/// Selects the moves between consecutive `poses` of `record` (the record's
/// `parts` split at gaps; `full_scale` the gyro's range, rad/s).
pub fn select(
    record: &Record,
    poses: &[Segment],
    parts: &[Range<usize>],
    full_scale: f64,
) -> Selection {
    let part_of = |sample: usize| parts.iter().position(|p| p.contains(&sample));
    let limit = MAX_RANGE_FRACTION * full_scale;
    let mut moves = Vec::new();
    let mut left_out = Vec::new();
    for (j, pair) in poses.windows(2).enumerate() {
        let (a, b) = (pair[0], pair[1]);
        if part_of(a.start) != part_of(b.start) {
            left_out.push((j, LeftOut::CrossesGap));
            continue;
        }
        let still = static_segments::mean(&record.gyro[a.start..a.end]);
        let held = noise_shows(&record.gyro[a.start..a.end])
            .then(|| held_run(record.gyro, a.end..b.start, &still))
            .flatten();
        if let Some((at, samples)) = held {
            left_out.push((j, LeftOut::Held { at, samples }));
            continue;
        }
        let (sample, rate) = rig_free::peak_of(record, rig_free::move_samples(poses, j));
        if rate > limit {
            left_out.push((j, LeftOut::NearRange { sample, rate }));
            continue;
        }
        moves.push(j);
    }
    // The samples the fit uses: the poses and the moves kept.
    let mut in_fit = vec![false; record.gyro.len()];
    let ranges = poses
        .iter()
        .map(|p| p.start..p.end)
        .chain(moves.iter().map(|&j| rig_free::move_samples(poses, j)));
    for r in ranges {
        in_fit[r].fill(true);
    }
    let outside = (0..record.gyro.len())
        .filter(|&i| record.gyro[i].iter().any(|x| x.abs() > limit) && !in_fit[i])
        .collect();
    Selection {
        moves,
        left_out,
        outside,
    }
}

/// A run of at least this many identical gyro samples (all three axes) in a
/// move, at a rate of at least [`HELD_STEPS`] resolution steps from the
/// still pose's mean, is held, not measured, when the gyro's noise shows
/// at rest (a standard deviation of at least one resolution step): while
/// the unit turns, noise and the turn itself change every sample. (Near rest, at the start and end of a turn,
/// a coarse gyro may repeat a count honestly; a quiet quantised one may at
/// a steady rate.)
pub const HELD_RUN: usize = 5;

/// See [`HELD_RUN`].
pub const HELD_STEPS: f64 = 10.0;

/// Whether the gyro's noise shows in the still `samples` (a standard
/// deviation of at least one resolution step on every axis): only then is
/// a run of identical samples in a turn held rather than a quiet,
/// coarsely quantised gyro turning at a steady rate.
fn noise_shows(samples: &[[f64; 3]]) -> bool {
    let step = static_segments::resolution(samples);
    static_segments::standard_deviation(samples)
        .iter()
        .all(|&sd| sd >= step)
}

/// The first held run within `range` (see [`HELD_RUN`]), `still` the gyro's
/// mean at the pose before: its first sample and length.
fn held_run(samples: &[[f64; 3]], range: Range<usize>, still: &[f64; 3]) -> Option<(usize, usize)> {
    let step = static_segments::resolution(&samples[range.clone()]);
    let turning = |w: &[f64; 3]| (0..3).any(|k| (w[k] - still[k]).abs() > HELD_STEPS * step);
    let mut start = range.start;
    for i in range.clone().skip(1).chain([range.end]) {
        if i == range.end || samples[i] != samples[start] {
            if i - start >= HELD_RUN && turning(&samples[start]) {
                return Some((start, i - start));
            }
            start = i;
        }
    }
    None
}
