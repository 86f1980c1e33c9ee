//! A record's static poses as the whole fits find them: the detector for
//! the record's sample rate, detection in each part of the record (no pose
//! spans a gap in its time stamps), and a pose's mean and standard error.

use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use crate::calib_fit::static_segments::{self, DetectError, Detector, Dropped, Segment};

/// The static detector for a record at `rate_hz`: blocks of 0.5 s (≥ 25
/// samples so the block deviation is within ~15 % of σ, see
/// [`static_segments::THRESHOLD_FACTOR`]), segments of at least
/// `min_static_s` seconds.
pub fn detector(rate_hz: f64, min_static_s: f64) -> Detector {
    let block = (libm::round(0.5 * rate_hz) as usize).max(25);
    let block_s = block as f64 / rate_hz;
    Detector {
        block,
        min_blocks: libm::ceil(min_static_s / block_s) as usize,
    }
}

/// What detection found in one record: the static segments and the
/// candidates it dropped, as sample ranges of the whole record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Detection {
    /// The static segments, in order.
    pub segments: Vec<Segment>,
    /// The candidates not kept, in order.
    pub dropped: Vec<Dropped>,
}

/// The static segments of `samples` found by `detector` in each of `parts`
/// (sample ranges of the record, in order: where its time stamps split it).
pub fn detect(
    detector: &Detector,
    samples: &[[f64; 3]],
    parts: &[Range<usize>],
) -> Result<Detection, DetectError> {
    let mut found = Detection::default();
    for part in parts {
        let within = &samples[part.clone()];
        let mut buffer =
            vec![Segment { start: 0, end: 0 }; within.len() / detector.block.max(2) + 1];
        let mut dropped = Vec::new();
        let n = detector.detect_reporting(within, &mut buffer, |d| dropped.push(d))?;
        let shift = part.start;
        found.segments.extend(buffer[..n].iter().map(|s| Segment {
            start: shift + s.start,
            end: shift + s.end,
        }));
        found.dropped.extend(dropped.into_iter().map(|d| Dropped {
            start: shift + d.start,
            end: shift + d.end,
            ..d
        }));
    }
    Ok(found)
}

/// The mean of a pose's samples and its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Statistics {
    /// Mean per axis.
    pub mean: [f64; 3],
    /// Standard error of the mean per axis (white noise: s/√n).
    pub standard_error: [f64; 3],
    /// Samples.
    pub count: usize,
}

/// The [`Statistics`] of `samples`.
pub fn statistics(samples: &[[f64; 3]]) -> Statistics {
    let root_n = libm::sqrt(samples.len() as f64);
    Statistics {
        mean: static_segments::mean(samples),
        standard_error: static_segments::standard_deviation(samples).map(|s| s / root_n),
        count: samples.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_detector_uses_half_second_blocks_of_at_least_25_samples() {
        let d = detector(100.0, 2.0);
        assert_eq!((d.block, d.min_blocks), (50, 4));
        let d = detector(10.0, 2.0);
        assert_eq!((d.block, d.min_blocks), (25, 1));
    }

    /// Two parts, each a still stretch: one segment in each, indexed in the
    /// whole record, none across the split.
    #[test]
    fn each_part_is_searched_alone() {
        let mut samples = Vec::new();
        let mut state = 7u64;
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
        };
        for i in 0..600 {
            let up = if i < 300 {
                [0.0, 0.0, 9.8]
            } else {
                [9.8, 0.0, 0.0]
            };
            samples.push(up.map(|x| x + noise()));
        }
        let d = Detector {
            block: 50,
            min_blocks: 2,
        };
        let found = detect(&d, &samples, &[0..300, 300..600]).unwrap();
        assert_eq!(found.segments.len(), 2, "{found:?}");
        assert!(found.segments[0].end <= 300 && found.segments[1].start >= 300);
        let s = statistics(&samples[300..600]);
        assert_eq!(s.count, 300);
        assert!((s.mean[0] - 9.8).abs() < 0.01);
    }
}
