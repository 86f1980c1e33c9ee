//! The noise terms: the joint IEEE 952 fit on a column's octave points, and
//! what it returns in data-sheet units (per triad and term).

use triad::model::Triad;
use triad::units;
use triad_lab::allan::noise_terms::{self, CurvePoint, NoiseFit, Term};

use super::curve::Point;

/// The joint fit on the octave points (m a power of two: in every-τ mode the
/// neighbouring points are strongly correlated and would overstate the
/// information). None when no point is valid.
pub fn fit_octaves(points: &[Point]) -> Option<NoiseFit> {
    let curve: Vec<CurvePoint> = points
        .iter()
        .filter(|p| p.m.is_power_of_two())
        .map(|p| CurvePoint {
            tau: p.tau,
            avar: p.avar,
            edf: p.edf,
        })
        .collect();
    let mut scratch = vec![0.0; curve.len()];
    noise_terms::fit(&curve, &mut scratch).ok()
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

    #[test]
    fn white_noise_points_fit_a_white_noise_term() {
        // σ²(τ) = N²/τ with N = 1e-3 on octaves, plenty of degrees of freedom.
        let n = 1e-3;
        let points: Vec<Point> = (0..12)
            .map(|k| {
                let m = 1u64 << k;
                Point {
                    m,
                    tau: m as f64,
                    avar: n * n / m as f64,
                    avar_non_overlapping: f64::NAN,
                    terms: 1000,
                    noise: NoiseType::from_slope(-1.0),
                    edf: 1000.0,
                    ci: (0.0, 1.0),
                }
            })
            .collect();
        let fit = fit_octaves(&points).expect("a fit");
        let w = fit.term(Term::WhiteNoise);
        assert!((w.value - n).abs() < 1e-3 * n, "N = {}", w.value);
        assert!(fit.term(Term::RandomWalk).value < 1e-3 * n);
        assert!(fit_octaves(&[]).is_none());
    }
}
