//! The sensor grade from the fitted noise terms, per the published grade
//! tables of [`triad_sim::grade`] (rows of data-sheet bands).
//!
//! Allan variance measures two of each row's three columns: the white-noise
//! density (ARW for gyros, noise density for accelerometers) and the bias
//! instability; scale-factor accuracy needs a rate table or a tumble and is
//! not judged here. For each measured term the best grade whose band holds
//! it is found (rows overlap for accelerometers; a value below the best row's
//! band counts as that best grade; one above every band has no grade). The
//! sensor's grade is the worse of the two: a sensor is only as good as its
//! worse term, and that term is the one reported as deciding it.

use triad_sim::grade::{AccelGrade, Band, GyroGrade};

/// Which measured term set the grade.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecidedBy {
    /// The white-noise density (ARW / VRW).
    WhiteNoise,
    /// The bias instability.
    BiasInstability,
    /// Both terms place the sensor in the same grade.
    Both,
}

impl DecidedBy {
    /// A short description for reports.
    pub fn name(self) -> &'static str {
        match self {
            DecidedBy::WhiteNoise => "white noise",
            DecidedBy::BiasInstability => "bias instability",
            DecidedBy::Both => "white noise and bias instability",
        }
    }
}

/// A grade decision.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Classification<G> {
    /// The grade; None when a term is worse than every row.
    pub grade: Option<G>,
    /// The term (or terms) that set it.
    pub decided_by: DecidedBy,
}

/// Index (into a worst-to-best list of bands) of the best band holding `x`;
/// `Some(len − 1)` below the best band; None above every band or for NaN.
fn best_index(bands: &[Band], x: f64) -> Option<usize> {
    if x.is_nan() {
        return None;
    }
    if let Some(i) = (0..bands.len()).rev().find(|&i| bands[i].contains(x)) {
        return Some(i);
    }
    let best = bands.len().checked_sub(1)?;
    (x < bands[best].lo).then_some(best)
}

/// The worse of two per-term indices, with the deciding term.
fn combine(noise: Option<usize>, bias: Option<usize>) -> (Option<usize>, DecidedBy) {
    match (noise, bias) {
        (None, None) => (None, DecidedBy::Both),
        (None, Some(_)) => (None, DecidedBy::WhiteNoise),
        (Some(_), None) => (None, DecidedBy::BiasInstability),
        (Some(a), Some(b)) if a == b => (Some(a), DecidedBy::Both),
        (Some(a), Some(b)) if a < b => (Some(a), DecidedBy::WhiteNoise),
        (Some(_), Some(b)) => (Some(b), DecidedBy::BiasInstability),
    }
}

/// The gyro grade from ARW (°/√h) and bias instability (°/h).
pub fn classify_gyro(arw_deg_per_sqrt_h: f64, bias_deg_per_h: f64) -> Classification<GyroGrade> {
    let arw = GyroGrade::ALL.map(|g| g.row().arw_deg_per_sqrt_h);
    let bias = GyroGrade::ALL.map(|g| g.row().bias_instability_deg_per_h);
    let (i, decided_by) = combine(
        best_index(&arw, arw_deg_per_sqrt_h),
        best_index(&bias, bias_deg_per_h),
    );
    Classification {
        grade: i.map(|i| GyroGrade::ALL[i]),
        decided_by,
    }
}

/// The accelerometer grade from the noise density (µg/√Hz) and bias instability (µg).
pub fn classify_accel(noise_ug_per_sqrt_hz: f64, bias_ug: f64) -> Classification<AccelGrade> {
    let noise = AccelGrade::ALL.map(|g| g.row().noise_ug_per_sqrt_hz);
    let bias = AccelGrade::ALL.map(|g| g.row().bias_instability_ug);
    let (i, decided_by) = combine(
        best_index(&noise, noise_ug_per_sqrt_hz),
        best_index(&bias, bias_ug),
    );
    Classification {
        grade: i.map(|i| AccelGrade::ALL[i]),
        decided_by,
    }
}
