//! The noise terms: the generalised least-squares fit of IEEE 952's five
//! terms on a column's octave points (`triad_lab::allan::gls`, with the
//! covariance of the overlapping estimates), the reasons a column gets no
//! fit, and what the terms are in data-sheet units (per triad and term).

use std::sync::{Arc, Mutex, PoisonError};

use triad::model::Triad;
use triad::units;
use triad_lab::allan::covariance::OctaveCovariance;
use triad_lab::allan::gls;
use triad_lab::allan::noise_terms::{CurvePoint, FitError, NoiseFit, Term};

use super::curve::Point;

/// Why a column has no fit.
#[derive(Clone, Debug, PartialEq)]
pub enum NoFit {
    /// Every σ(τ) is zero or at the rounding level of the column's values:
    /// a dead or constant channel.
    NoNoise,
    /// Fewer octave points than the fit takes.
    TooFewPoints {
        /// The octave points.
        count: usize,
        /// The fewest the fit takes.
        needed: usize,
    },
    /// The fit failed for another reason (its message).
    Failed(String),
}

impl std::fmt::Display for NoFit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoFit::NoNoise => write!(
                f,
                "no noise detected (sigma(tau) is 0 at every tau: a dead or constant channel); no grade"
            ),
            NoFit::TooFewPoints { count, needed } => write!(
                f,
                "no fit: {count} octave tau points, too few to fit the noise terms (at least {needed}: one per term and one to judge the fit); lengthen --max-tau or the record"
            ),
            NoFit::Failed(why) => write!(f, "no fit: {why}"),
        }
    }
}

/// Relative size, to the column's offset (its mean), of the Allan deviation
/// that rounding alone can make: below it a column holds no noise.
const ROUNDING: f64 = 64.0 * f64::EPSILON;

/// The octave points of a curve (m a power of two: in every-τ mode the
/// neighbouring points are strongly correlated and would overstate the
/// information), with their averaging factors and strides.
fn octave_curve(points: &[Point]) -> (Vec<CurvePoint>, Vec<u64>, Vec<u64>) {
    let mut curve = Vec::new();
    let (mut m, mut strides) = (Vec::new(), Vec::new());
    for p in points.iter().filter(|p| p.m.is_power_of_two()) {
        curve.push(CurvePoint {
            tau: p.tau,
            avar: p.avar,
            edf: p.edf,
        });
        m.push(p.m);
        strides.push(p.stride);
    }
    (curve, m, strides)
}

/// The covariance of a record's octave estimates, computed once for all its
/// columns (they share the record's length, τ grid and strides), by the
/// first column's fit that needs it (the others wait for it), on every core.
#[derive(Default)]
pub struct CovarianceCache {
    cached: Mutex<Option<Arc<OctaveCovariance>>>,
}

impl CovarianceCache {
    fn get(
        &self,
        samples: u64,
        rate: f64,
        m: &[u64],
        strides: &[u64],
    ) -> Result<Arc<OctaveCovariance>, NoFit> {
        let mut cached = self.cached.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(cov) = cached.as_ref() {
            if cov.factors() == m && cov.strides() == strides {
                return Ok(Arc::clone(cov));
            }
        }
        let cov = Arc::new(on_every_core(samples, rate, m, strides)?);
        *cached = Some(Arc::clone(&cov));
        Ok(cov)
    }
}

/// The covariance made in shares of its pairs of points, one per core
/// ([`OctaveCovariance::share_of_pairs`]: the same sums, bit for bit).
fn on_every_core(
    samples: u64,
    rate: f64,
    m: &[u64],
    strides: &[u64],
) -> Result<OctaveCovariance, NoFit> {
    let shares = std::thread::available_parallelism().map_or(1, |n| n.get());
    let share = |k| {
        OctaveCovariance::share_of_pairs(samples, 1.0 / rate, m, strides, k, shares)
            .map_err(|e| NoFit::Failed(e.to_string()))
    };
    std::thread::scope(|scope| {
        let others: Vec<_> = (1..shares).map(|k| scope.spawn(move || share(k))).collect();
        let mut whole = share(0)?;
        for other in others {
            let part = other
                .join()
                .map_err(|_| NoFit::Failed("a thread making the covariance failed".into()))??;
            whole.add_share(&part);
        }
        Ok(whole)
    })
}

/// The fit on the octave points of a column whose values have mean
/// `offset`, from a record of `samples` at `rate` Hz.
pub fn fit_octaves(
    points: &[Point],
    offset: f64,
    samples: u64,
    rate: f64,
    cache: &CovarianceCache,
) -> Result<NoiseFit, NoFit> {
    let floor = ROUNDING * offset.abs();
    if points.iter().all(|p| p.avar.sqrt() <= floor) {
        return Err(NoFit::NoNoise);
    }
    let (curve, m, strides) = octave_curve(points);
    if curve.len() < gls::MIN_POINTS {
        return Err(NoFit::TooFewPoints {
            count: curve.len(),
            needed: gls::MIN_POINTS,
        });
    }
    let cov = cache.get(samples, rate, &m, &strides)?;
    gls::fit(&curve, &cov).map_err(|e| match e {
        FitError::NoNoise => NoFit::NoNoise,
        FitError::TooFewPoints { count, needed } => NoFit::TooFewPoints { count, needed },
        other => NoFit::Failed(other.to_string()),
    })
}

/// SI unit of a triad's samples.
pub fn si_unit(triad: Triad) -> &'static str {
    match triad {
        Triad::Gyro => "rad/s",
        Triad::Accel => "m/s^2",
    }
}

/// A term in data-sheet units: (value factor from SI, unit).
pub fn datasheet(triad: Triad, term: Term) -> (f64, &'static str) {
    match triad {
        Triad::Gyro => gyro_datasheet(term),
        Triad::Accel => accel_datasheet(term),
    }
}

fn gyro_datasheet(term: Term) -> (f64, &'static str) {
    match term {
        Term::Quantisation => (1e6, "urad"),
        Term::WhiteNoise => (units::arw_si_to_deg_per_sqrt_h(1.0), "deg/sqrt(h)"),
        Term::BiasInstability => (units::rad_per_s_to_deg_per_h(1.0), "deg/h"),
        Term::RandomWalk => (units::rrw_si_to_deg_per_h_per_sqrt_h(1.0), "deg/h/sqrt(h)"),
        Term::RateRamp => (
            units::rad_to_deg(1.0) * units::SECONDS_PER_HOUR * units::SECONDS_PER_HOUR,
            "deg/h^2",
        ),
    }
}

fn accel_datasheet(term: Term) -> (f64, &'static str) {
    match term {
        Term::Quantisation => (1e3, "mm/s"),
        Term::WhiteNoise => (units::si_to_ug_per_sqrt_hz(1.0), "ug/sqrt(Hz)"),
        Term::BiasInstability => (units::mps2_to_ug(1.0), "ug"),
        Term::RandomWalk => (
            units::SECONDS_PER_HOUR * units::SQRT_SECONDS_PER_HOUR,
            "m/s/h/sqrt(h)",
        ),
        Term::RateRamp => (units::mps2_to_ug(1.0) * units::SECONDS_PER_HOUR, "ug/h"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad_lab::allan::edf::NoiseType;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs()
    }

    #[test]
    fn data_sheet_factors_are_the_usual_conversions() {
        // 1 rad/s/√Hz = (180/π)·60 °/√h; 1 rad/s = (180/π)·3600 °/h.
        let deg = 180.0 / std::f64::consts::PI;
        let (f, unit) = datasheet(Triad::Gyro, Term::WhiteNoise);
        assert!(close(f, deg * 60.0) && unit == "deg/sqrt(h)");
        let (f, unit) = datasheet(Triad::Gyro, Term::BiasInstability);
        assert!(close(f, deg * 3600.0) && unit == "deg/h");
        // 1 m/s² = 1e6/9.80665 µg.
        let (f, unit) = datasheet(Triad::Accel, Term::BiasInstability);
        assert!(close(f, 1e6 / 9.80665) && unit == "ug");
        assert_eq!(datasheet(Triad::Accel, Term::Quantisation), (1e3, "mm/s"));
        assert_eq!(
            (si_unit(Triad::Gyro), si_unit(Triad::Accel)),
            ("rad/s", "m/s^2")
        );
    }

    fn points(avar: impl Fn(f64) -> f64, octaves: u32) -> Vec<Point> {
        (0..octaves)
            .map(|k| {
                let m = 1u64 << k;
                Point {
                    m,
                    tau: m as f64,
                    avar: avar(m as f64),
                    avar_non_overlapping: f64::NAN,
                    terms: 1000,
                    stride: 1,
                    noise: NoiseType::from_slope(-1.0),
                    edf: 1000.0,
                    ci: (0.0, 1.0),
                }
            })
            .collect()
    }

    #[test]
    fn white_noise_points_fit_a_white_noise_term() {
        // σ²(τ) = N²/τ with N = 1e-3 on octaves of 2^16 samples at 1 Hz.
        let n = 1e-3;
        let cache = CovarianceCache::default();
        let fit =
            fit_octaves(&points(|t| n * n / t, 12), 0.0, 1 << 16, 1.0, &cache).expect("a fit");
        let w = fit.term(Term::WhiteNoise);
        assert!((w.value - n).abs() < 1e-3 * n, "N = {}", w.value);
        assert!(w.significant);
        assert!(!fit.term(Term::RandomWalk).significant);
    }

    #[test]
    fn dead_channels_and_short_grids_get_no_fit() {
        let cache = CovarianceCache::default();
        let zero = points(|_| 0.0, 12);
        assert_eq!(
            fit_octaves(&zero, 0.0, 1 << 16, 1.0, &cache),
            Err(NoFit::NoNoise)
        );
        // A constant 0.1 whose mean is off by rounding: σ at the 1e-17 level.
        let rounding = points(|_| 1e-34, 12);
        assert_eq!(
            fit_octaves(&rounding, 0.1, 1 << 16, 1.0, &cache),
            Err(NoFit::NoNoise)
        );
        let two = points(|t| 1e-6 / t, 2);
        let e = fit_octaves(&two, 0.0, 1 << 16, 1.0, &cache).unwrap_err();
        assert_eq!(
            e,
            NoFit::TooFewPoints {
                count: 2,
                needed: 6
            }
        );
        assert!(e.to_string().contains("2 octave tau points"), "{e}");
    }
}
