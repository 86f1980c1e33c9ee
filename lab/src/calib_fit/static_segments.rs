//! Finding the static segments of a record (the sensor at rest between
//! turns), from the accelerometer alone.
//!
//! The record is cut into blocks of `block` samples; a block is static when
//! the largest per-axis standard deviation within it is at most the
//! threshold. The threshold adapts to the sensor: [`THRESHOLD_FACTOR`] times
//! the 10th percentile of the deviations of the blocks that vary at all (a
//! calibration record is mostly at rest, and the quietest tenth of its
//! varying blocks is surely at rest), but never below the record's own
//! resolution (its smallest step between consecutive samples: one LSB of a
//! quantised record, whose static blocks vary by less than that) nor below
//! [`THRESHOLD_FLOOR`].
//!
//! A block whose samples are all identical is *held* (a logger repeating its
//! last sample over lost frames) when the record's noise shows elsewhere
//! (that percentile at least one resolution step): then it is not at rest
//! but unknown, and it never makes a pose. In a quantisation-dominated
//! record (noise under one LSB) identical blocks are simply still.
//!
//! A run of static blocks loses one block at each end that borders motion
//! (a turn may start or end inside it), not at an end where the next block
//! is static too but its mean jumped (a pose changed between two samples),
//! and is kept when at least `min_blocks` remain. Candidates that are
//! dropped are reported with the reason. No allocation: the caller gives
//! the output buffer.

use core::fmt;

/// Threshold = this × the 10th percentile of the block deviations. The
/// sample deviation of a block of n ≥ 25 white-noise samples scatters by
/// 1/√(2(n−1)) ≤ 15 % around σ, so a static block exceeds 4·(0.85σ) with
/// negligible probability, while a turn of 90° in a few seconds moves
/// gravity by ~1 m/s² within a block, ≫ MEMS noise (≤ 0.01 m/s² per sample).
pub const THRESHOLD_FACTOR: f64 = 4.0;

/// The smallest threshold, m/s² (10 µg): noiseless or coarsely quantised
/// records would otherwise get a zero threshold.
pub const THRESHOLD_FLOOR: f64 = 1.0e-4;

/// Why detection failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DetectError {
    /// The output buffer is too small for the segments found.
    TooManySegments {
        /// The buffer's capacity.
        capacity: usize,
    },
}

impl fmt::Display for DetectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DetectError::TooManySegments { capacity } => {
                write!(f, "more than {capacity} static segments")
            }
        }
    }
}

/// Why a run of static blocks made no segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DropReason {
    /// Fewer than `min_blocks` blocks after trimming.
    TooShort,
    /// Its samples repeat one value while the record's noise shows elsewhere.
    Held,
}

/// A candidate the detector did not keep: samples `start..end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dropped {
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// Why.
    pub reason: DropReason,
}

/// Half-open sample range `start..end` of a static segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
}

/// The detector's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector {
    /// Samples per block (e.g. 0.5 s worth).
    pub block: usize,
    /// The fewest static blocks a segment keeps after trimming its ends.
    pub min_blocks: usize,
}

/// Histogram bins of the block deviations: 20 per decade from 1e-9 to 1e3.
const BINS: usize = 240;
const LOG_MIN: f64 = -9.0;
const PER_DECADE: f64 = 20.0;

fn block_deviation(block: &[[f64; 3]]) -> f64 {
    let n = block.len() as f64;
    let mut mean = [0.0; 3];
    for s in block {
        for (m, x) in mean.iter_mut().zip(s) {
            *m += x / n;
        }
    }
    let mut var = [0.0; 3];
    for s in block {
        for ((v, x), m) in var.iter_mut().zip(s).zip(mean) {
            *v += (x - m) * (x - m);
        }
    }
    let worst = var[0].max(var[1]).max(var[2]);
    libm::sqrt(worst / (n - 1.0).max(1.0))
}

/// The smallest nonzero step between consecutive samples on any axis: one
/// LSB of a quantised record (∞ when no sample differs from the last).
pub fn resolution(samples: &[[f64; 3]]) -> f64 {
    let mut smallest = f64::INFINITY;
    for pair in samples.windows(2) {
        for (a, b) in pair[0].iter().zip(&pair[1]) {
            let d = (a - b).abs();
            if d > 0.0 && d < smallest {
                smallest = d;
            }
        }
    }
    smallest
}

/// The threshold a record gets and whether its identical blocks are held.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threshold {
    /// The largest block deviation (and block-mean jump) that is static.
    pub value: f64,
    /// Identical blocks are held samples, not rest: the noise shows.
    pub identical_is_held: bool,
}

impl Detector {
    /// The threshold this record gets (m/s²), or `None` if it has no whole block.
    pub fn threshold(&self, samples: &[[f64; 3]]) -> Option<f64> {
        self.threshold_of(samples).map(|t| t.value)
    }

    /// The threshold and how identical blocks count; `None` without a whole block.
    pub fn threshold_of(&self, samples: &[[f64; 3]]) -> Option<Threshold> {
        let block = self.block.max(2);
        let mut histogram = [0u32; BINS];
        let mut count = 0u32;
        for chunk in samples.chunks_exact(block) {
            let d = block_deviation(chunk);
            if d > 0.0 {
                let bin = ((libm::log10(d) - LOG_MIN) * PER_DECADE).clamp(0.0, (BINS - 1) as f64)
                    as usize;
                histogram[bin] += 1;
                count += 1;
            }
        }
        if samples.len() < block {
            return None;
        }
        let step = resolution(samples);
        if count == 0 {
            // Every block identical within itself: no noise to measure.
            let value = if step.is_finite() { step } else { 0.0 };
            return Some(Threshold {
                value: value.max(THRESHOLD_FLOOR),
                identical_is_held: false,
            });
        }
        let wanted = count.div_ceil(10);
        let mut seen = 0;
        let mut percentile = f64::NAN;
        for (bin, &h) in histogram.iter().enumerate() {
            seen += h;
            if seen >= wanted {
                // The bin's upper edge: never below the percentile.
                percentile = libm::pow(10.0, LOG_MIN + (bin + 1) as f64 / PER_DECADE);
                break;
            }
        }
        Some(Threshold {
            value: (THRESHOLD_FACTOR * percentile)
                .max(step)
                .max(THRESHOLD_FLOOR),
            identical_is_held: percentile >= step,
        })
    }

    /// Writes the static segments of `samples` (m/s²) into `out`; returns
    /// how many. Besides motion within a block, a jump of a block's mean
    /// from the previous block's by more than the threshold also ends a
    /// segment (an orientation change that fell exactly between two blocks;
    /// block means scatter by only σ/√block, far below the threshold).
    pub fn detect(&self, samples: &[[f64; 3]], out: &mut [Segment]) -> Result<usize, DetectError> {
        self.detect_reporting(samples, out, |_| {})
    }

    /// [`Self::detect`], telling `dropped` of each candidate not kept.
    pub fn detect_reporting(
        &self,
        samples: &[[f64; 3]],
        out: &mut [Segment],
        mut dropped: impl FnMut(Dropped),
    ) -> Result<usize, DetectError> {
        let block = self.block.max(2);
        let Some(threshold) = self.threshold_of(samples) else {
            return Ok(0);
        };
        let blocks = samples.len() / block;
        let mut found = 0;
        // The run: its first block and whether that block follows a jump
        // from a static block (then it needs no trimming).
        let mut run_start: Option<(usize, bool)> = None;
        let mut previous_mean: Option<[f64; 3]> = None;
        let mut held_from: Option<usize> = None;
        let mut emit = |first: usize,
                        after_jump: bool,
                        end: usize,
                        clean_end: bool,
                        dropped: &mut dyn FnMut(Dropped)|
         -> Result<(), DetectError> {
            // Trim one block at each end that borders motion.
            let lo = if first == 0 || after_jump {
                first
            } else {
                first + 1
            };
            let hi = if clean_end { end } else { end - 1 };
            if hi >= lo + self.min_blocks.max(1) {
                let slot = out
                    .get_mut(found)
                    .ok_or(DetectError::TooManySegments { capacity: found })?;
                *slot = Segment {
                    start: lo * block,
                    end: hi * block,
                };
                found += 1;
            } else {
                dropped(Dropped {
                    start: first * block,
                    end: end * block,
                    reason: DropReason::TooShort,
                });
            }
            Ok(())
        };
        for b in 0..=blocks {
            let chunk =
                &samples[(b * block).min(samples.len())..((b + 1) * block).min(samples.len())];
            let deviation = block_deviation(chunk);
            let held = b < blocks && deviation == 0.0 && threshold.identical_is_held;
            match (held, held_from) {
                (true, None) => held_from = Some(b),
                (false, Some(from)) => {
                    dropped(Dropped {
                        start: from * block,
                        end: b * block,
                        reason: DropReason::Held,
                    });
                    held_from = None;
                }
                _ => {}
            }
            let is_static = b < blocks && !held && deviation <= threshold.value;
            let m = mean(chunk);
            let jumped = match previous_mean {
                Some(p) => (0..3).any(|i| (m[i] - p[i]).abs() > threshold.value),
                None => false,
            };
            previous_mean = if is_static { Some(m) } else { None };
            match (run_start, is_static) {
                (None, true) => run_start = Some((b, false)),
                (Some((first, after)), true) if jumped => {
                    emit(first, after, b, true, &mut dropped)?;
                    run_start = Some((b, true));
                }
                (Some((first, after)), false) => {
                    emit(first, after, b, b == blocks, &mut dropped)?;
                    run_start = None;
                }
                _ => {}
            }
        }
        Ok(found)
    }
}

/// The mean of `samples` (none: zeros).
pub fn mean(samples: &[[f64; 3]]) -> [f64; 3] {
    let n = samples.len().max(1) as f64;
    let mut m = [0.0; 3];
    for s in samples {
        for (mi, x) in m.iter_mut().zip(s) {
            *mi += x;
        }
    }
    m.map(|x| x / n)
}

/// The per-axis sample standard deviation of `samples` (fewer than 2: zeros).
pub fn standard_deviation(samples: &[[f64; 3]]) -> [f64; 3] {
    if samples.len() < 2 {
        return [0.0; 3];
    }
    let m = mean(samples);
    let mut v = [0.0; 3];
    for s in samples {
        for ((vi, x), mi) in v.iter_mut().zip(s).zip(m) {
            *vi += (x - mi) * (x - mi);
        }
    }
    v.map(|x| libm::sqrt(x / (samples.len() - 1) as f64))
}
