//! `fit thermal` whole: the temperature terms of both triads from records
//! over a temperature range (soaks or ramps).
//!
//! - The static segments of every record (the accelerometer's), cut where
//!   their temperature has moved by [`CHUNK_C`], each with its mean
//!   temperature: a soak's pose is one segment, a ramp's rest many.
//! - Which terms are fitted is decided by the temperatures alone
//!   ([`thermal_coverage`]).
//! - Accelerometer: (I+Σ)₀ + ΔT·D and b cubic in ΔT over every segment
//!   ([`thermal_accel`]), when ≥ 9 orientations lie both colder and warmer
//!   than the reference; not fitted when the options say gyroscope only.
//! - Gyroscope: its bias against temperature from the segments' means
//!   ([`bias_polynomial`]), then its (I+Σ)₀ + ΔT·D from the turns between
//!   consecutive poses of each record ([`thermal_gyro`]) when the
//!   accelerometer was fitted and enough turns lie on either side of the
//!   reference; else not fitted, and why.

use alloc::vec::Vec;
use core::fmt;

use crate::calib_fit::fits::bias_polynomial::{
    self, BiasPolynomial, BiasPolynomialError, StaticMean,
};
use crate::calib_fit::fits::rig_free::Record;
use crate::calib_fit::fits::thermal_accel::{self, Terms, ThermalAccelError, ThermalAccelFit};
use crate::calib_fit::fits::thermal_coverage::{self, Coverage, CoverageError};
use crate::calib_fit::fits::thermal_gyro::{self, Poses, ThermalGyroError, ThermalGyroFit};
use crate::calib_fit::poses;
use crate::calib_fit::static_segments::{DetectError, Detector, Segment};

/// A static segment is cut where its temperature has moved by this (°C)
/// from the cut's start: within a cut the terms change by at most
/// 0.5 °C × the coefficient, and its mean temperature is its temperature.
pub const CHUNK_C: f64 = 0.5;

/// One record over temperature: both triads and the temperature at the same times.
#[derive(Clone, Copy, Debug)]
pub struct ThermalRecord<'a> {
    /// Times, s, increasing.
    pub t: &'a [f64],
    /// The accelerometer's samples, m/s².
    pub accel: &'a [[f64; 3]],
    /// The gyroscope's samples, rad/s.
    pub gyro: &'a [[f64; 3]],
    /// The chip's temperature at each sample, °C.
    pub temperature: &'a [f64],
    /// The static detector for this record's sample rate.
    pub detector: Detector,
}

/// What the fit is given besides the records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalOptions {
    /// Local gravity, m/s².
    pub gravity: f64,
    /// The gyro's full scale, rad/s.
    pub full_scale: f64,
    /// Fit only the gyroscope's bias (the accelerometer is not fitted).
    pub gyro_only: bool,
}

/// Why the gyroscope's (I+Σ) against temperature was not fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScaleNotFitted {
    /// The options asked for the gyroscope's bias only (no accelerometer fit
    /// gives the gravity directions).
    GyroOnly,
    /// Too few turns on either side of the reference.
    TooFewTurns(ThermalGyroError),
}

/// Both triads' temperature terms, with what the report says.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermalFit {
    /// The temperatures' range, reference and levels.
    pub coverage: Coverage,
    /// Static segments (after cutting) over all records.
    pub segments: usize,
    /// The accelerometer's fit, unless gyroscope only.
    pub accel: Option<ThermalAccelFit>,
    /// The gyroscope's bias polynomial.
    pub gyro_bias: BiasPolynomial,
    /// The gyroscope's (I+Σ)₀ and D, or why not.
    pub gyro_scale: Result<ThermalGyroFit, ScaleNotFitted>,
}

/// Why `fit thermal` refused its records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThermalFitError {
    /// Static detection failed in a record.
    Detection {
        /// The record (0-based).
        record: usize,
        /// Why.
        error: DetectError,
    },
    /// The temperatures do not support any term.
    Coverage(CoverageError),
    /// Too few orientations on either side of the reference for the
    /// accelerometer's D.
    AccelSupport(CoverageError),
    /// The accelerometer's fit refused the segments.
    Accel {
        /// Static segments given.
        segments: usize,
        /// Why.
        error: ThermalAccelError,
    },
    /// The gyroscope's bias polynomial refused the segments.
    GyroBias(BiasPolynomialError),
    /// The gyroscope's (I+Σ) against temperature refused the turns (other
    /// than for too few of them, which leaves it unfitted).
    GyroScale(ThermalGyroError),
}

impl fmt::Display for ThermalFitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalFitError::Detection { record, error } => {
                write!(f, "record {}: {error}", record + 1)
            }
            ThermalFitError::Coverage(e) => write!(f, "{e}"),
            ThermalFitError::AccelSupport(e) => write!(f, "accelerometer: {e}"),
            ThermalFitError::Accel { segments, error } => {
                write!(f, "accelerometer, {segments} static segments: {error}")
            }
            ThermalFitError::GyroBias(e) => write!(f, "gyroscope bias: {e}"),
            ThermalFitError::GyroScale(e) => {
                write!(f, "gyroscope (I+Σ) against temperature: {e}")
            }
        }
    }
}

/// `segment` cut where the temperature has moved by [`CHUNK_C`]; pieces
/// shorter than `min_len` join the previous piece.
pub fn cut(temperature: &[f64], segment: Segment, min_len: usize, out: &mut Vec<Segment>) {
    let first = out.len();
    let mut start = segment.start;
    for i in segment.start..segment.end {
        if (temperature[i] - temperature[start]).abs() >= CHUNK_C && i - start >= min_len {
            out.push(Segment { start, end: i });
            start = i;
        }
    }
    if segment.end - start >= min_len || out.len() == first {
        out.push(Segment {
            start,
            end: segment.end,
        });
    } else if let Some(last) = out.last_mut() {
        last.end = segment.end;
    }
}

/// A record's static poses (uncut), their accelerometer means and temperatures.
struct RecordPoses {
    segments: Vec<Segment>,
    accel_means: Vec<[f64; 3]>,
    temperatures: Vec<f64>,
}

fn mean_of(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// Both triads' static means at every (cut) segment of every record, and
/// each record's whole poses for the gyro's turns.
#[allow(clippy::type_complexity)] // three lists, named where they are taken apart
fn static_means(
    records: &[ThermalRecord],
) -> Result<(Vec<StaticMean>, Vec<StaticMean>, Vec<RecordPoses>), ThermalFitError> {
    let (mut accel, mut gyro, mut all) = (Vec::new(), Vec::new(), Vec::new());
    for (record, r) in records.iter().enumerate() {
        let d = r.detector;
        let whole = 0..r.accel.len();
        let segments = poses::detect(&d, r.accel, core::slice::from_ref(&whole))
            .map_err(|error| ThermalFitError::Detection { record, error })?
            .segments;
        let mut pieces = Vec::new();
        for s in &segments {
            cut(r.temperature, *s, d.block * d.min_blocks, &mut pieces);
        }
        for p in pieces {
            let temperature_c = mean_of(&r.temperature[p.start..p.end]);
            for (out, samples) in [(&mut accel, r.accel), (&mut gyro, r.gyro)] {
                let s = poses::statistics(&samples[p.start..p.end]);
                out.push(StaticMean {
                    temperature_c,
                    mean: s.mean,
                    standard_error: s.standard_error,
                });
            }
        }
        all.push(RecordPoses {
            accel_means: segments
                .iter()
                .map(|p| poses::statistics(&r.accel[p.start..p.end]).mean)
                .collect(),
            temperatures: segments
                .iter()
                .map(|p| mean_of(&r.temperature[p.start..p.end]))
                .collect(),
            segments,
        });
    }
    Ok((accel, gyro, all))
}

/// The accelerometer's thermal fit over `means`, after checking the
/// orientations on either side of the reference support its D.
fn fit_accel(
    means: &[StaticMean],
    gravity: f64,
    coverage: &Coverage,
) -> Result<ThermalAccelFit, ThermalFitError> {
    let directions: Vec<[f64; 3]> = means.iter().map(|m| m.mean).collect();
    let temps: Vec<f64> = means.iter().map(|m| m.temperature_c).collect();
    let mut scratch = alloc::vec![[0.0; 3]; means.len()];
    let sides = thermal_coverage::orientations_either_side(
        &directions,
        &temps,
        coverage.reference_c,
        &mut scratch,
    );
    thermal_coverage::check_scale_support(sides, coverage)
        .map_err(ThermalFitError::AccelSupport)?;
    let terms = Terms {
        reference_c: coverage.reference_c,
        bias_order: coverage.bias_order(),
        scale: true,
    };
    let mut weights = alloc::vec![0.0; means.len()];
    thermal_accel::fit(means, gravity, terms, &mut scratch, &mut weights).map_err(|error| {
        ThermalFitError::Accel {
            segments: means.len(),
            error,
        }
    })
}

/// Fits both triads' temperature terms to `records` as `options` say.
pub fn fit(
    records: &[ThermalRecord],
    options: &ThermalOptions,
) -> Result<ThermalFit, ThermalFitError> {
    let (accel_means, gyro_means, record_poses) = static_means(records)?;
    let temps: Vec<f64> = accel_means.iter().map(|m| m.temperature_c).collect();
    let coverage = thermal_coverage::coverage(&temps).map_err(ThermalFitError::Coverage)?;
    let accel = if options.gyro_only {
        None
    } else {
        Some(fit_accel(&accel_means, options.gravity, &coverage)?)
    };
    let gyro_bias = bias_polynomial::fit(&gyro_means, coverage.reference_c, coverage.bias_order())
        .map_err(ThermalFitError::GyroBias)?;
    let gyro_scale = match &accel {
        None => Err(ScaleNotFitted::GyroOnly),
        Some(accel_fit) => {
            let sets: Vec<Poses> = records
                .iter()
                .zip(&record_poses)
                .map(|(r, p)| Poses {
                    record: Record {
                        t: r.t,
                        gyro: r.gyro,
                    },
                    segments: &p.segments,
                    accel_means: &p.accel_means,
                    temperatures: &p.temperatures,
                })
                .collect();
            match thermal_gyro::fit(&sets, accel_fit, &gyro_bias, options.full_scale) {
                Ok(fit) => Ok(fit),
                Err(e @ ThermalGyroError::TooFewTurnsForScale { .. }) => {
                    Err(ScaleNotFitted::TooFewTurns(e))
                }
                Err(e) => return Err(ThermalFitError::GyroScale(e)),
            }
        }
    };
    Ok(ThermalFit {
        coverage,
        segments: accel_means.len(),
        accel,
        gyro_bias,
        gyro_scale,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn a_ramp_is_cut_every_half_degree_and_a_soak_is_not() {
        // 0.1 °C a sample: a cut every 5 samples; the last 2 join the previous.
        let ramp: Vec<f64> = (0..22).map(|i| 0.1 * i as f64).collect();
        let mut out = Vec::new();
        cut(&ramp, Segment { start: 0, end: 22 }, 3, &mut out);
        let bounds: Vec<(usize, usize)> = out.iter().map(|s| (s.start, s.end)).collect();
        assert_eq!(bounds, [(0, 5), (5, 10), (10, 15), (15, 22)]);
        let soak = vec![25.0; 40];
        let mut out = Vec::new();
        cut(&soak, Segment { start: 3, end: 40 }, 3, &mut out);
        assert_eq!(out, [Segment { start: 3, end: 40 }]);
        // Shorter than the shortest piece: kept whole (the detector's own minimum).
        let mut out = Vec::new();
        cut(&ramp, Segment { start: 0, end: 2 }, 3, &mut out);
        assert_eq!(out, [Segment { start: 0, end: 2 }]);
    }
}
