//! Why a fit was refused: each variant says what was found and what is needed.

use core::fmt;

use super::qr::LsError;

/// The fewest distinct gravity directions the accelerometer fit accepts: 9
/// unknowns (6 of the triangular T, 3 of b), one equation |T(f̂−b)| = g per
/// orientation.
pub const MIN_ACCEL_ORIENTATIONS: usize = 9;

/// The fewest rate vectors the gyro fit accepts: 4 unknowns per output axis
/// (a row of I+Σ and b_i), one equation per axis per segment.
pub const MIN_GYRO_RATES: usize = 4;

/// Why a calibration fit was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FitError {
    /// An input value is NaN or infinite.
    NonFinite {
        /// The segment (0-based).
        segment: usize,
        /// The value.
        value: f64,
    },
    /// The gravity (or a rate) given is not a positive finite number.
    InvalidGravity {
        /// The value in m/s².
        value: f64,
    },
    /// A static mean's magnitude is nowhere near g: not the sensor at rest
    /// in gravity, or not in m/s² (a record in g gives |f̂| ≈ 1).
    NotNearGravity {
        /// The segment (0-based).
        segment: usize,
        /// |f̂|, m/s².
        magnitude: f64,
        /// g, m/s².
        gravity: f64,
    },
    /// Fewer distinct static orientations than the model's unknowns.
    TooFewOrientations {
        /// Static segments given.
        segments: usize,
        /// Distinct gravity directions among them (more than
        /// [`DISTINCT_ANGLE_DEG`](super::accel_fit::DISTINCT_ANGLE_DEG) apart).
        found: usize,
        /// The minimum.
        needed: usize,
    },
    /// The gravity directions lie near one plane (a circle on the sphere):
    /// the ellipsoid is not determined across it.
    OrientationsInOnePlane {
        /// Distinct orientations found.
        orientations: usize,
        /// RMS distance of the unit directions from their best plane.
        out_of_plane_rms: f64,
        /// The smallest accepted RMS distance.
        needed: f64,
    },
    /// The algebraic ellipsoid fit that starts the iteration is not an
    /// ellipsoid (the data are not a sensor at rest in several orientations).
    NotAnEllipsoid,
    /// Fewer rate vectors than the gyro model's unknowns per axis.
    TooFewRates {
        /// Rate segments given.
        found: usize,
        /// The minimum.
        needed: usize,
    },
    /// The true rate vectors (with the bias column) do not span 4 dimensions.
    RatesDegenerate {
        /// Affine dimension of the rate vectors: 0 all equal, 1 on one line
        /// (e.g. all about one axis), 2 in one plane.
        dimension: u8,
    },
    /// A static mean is not along a sensor axis (the axis-aligned fit needs
    /// one axis vertical in every position).
    NotAxisAligned {
        /// The segment (0-based).
        segment: usize,
        /// Angle between the mean and the nearest sensor axis, degrees.
        angle_deg: f64,
        /// The largest accepted angle, degrees.
        limit_deg: f64,
    },
    /// The axis-aligned fit's faces: fewer than 4, or all in one plane.
    TooFewFaces {
        /// Distinct faces (±x, ±y, ±z) found up.
        found: usize,
        /// Static segments.
        segments: usize,
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
    /// A static-segment buffer is too small for the segments found.
    TooManySegments {
        /// The buffer's capacity.
        capacity: usize,
    },
}

impl From<LsError> for FitError {
    fn from(e: LsError) -> Self {
        FitError::LeastSquares(e)
    }
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FitError::NonFinite { segment, value } => {
                write!(f, "segment {}: value {value} is not a finite number", segment + 1)
            }
            FitError::InvalidGravity { value } => {
                write!(f, "gravity {value} m/s²: must be a positive finite number")
            }
            FitError::NotNearGravity { segment, magnitude, gravity } => write!(
                f,
                "static segment {}: |f̂| = {magnitude:.4} m/s² is outside 0.5..1.5 × g = {gravity} m/s² \
                 (not at rest, or the record is not in m/s²?)",
                segment + 1
            ),
            FitError::TooFewOrientations { segments, found, needed } => write!(
                f,
                "found {found} distinct static orientation(s) in {segments} static segment(s); \
                 the accelerometer fit (9 unknowns: 6 scale/misalignment, 3 bias) needs at least {needed} \
                 distinct orientations, well spread over the sphere (a 6- or 24-position cube tumble \
                 gives only 6 gravity directions)"
            ),
            FitError::OrientationsInOnePlane { orientations, out_of_plane_rms, needed } => write!(
                f,
                "the {orientations} static orientations have gravity directions in one plane \
                 (RMS distance {out_of_plane_rms:.4} of the unit vectors from it, need ≥ {needed}): \
                 tilt the sensor out of that plane too"
            ),
            FitError::NotAnEllipsoid => write!(
                f,
                "the static means do not lie on an ellipsoid around the origin \
                 (not a sensor at rest in several orientations?)"
            ),
            FitError::TooFewRates { found, needed } => write!(
                f,
                "found {found} rate segment(s); the gyro fit (per axis: 3 of I+Σ and 1 bias) needs at least {needed} \
                 rate vectors not in one plane"
            ),
            FitError::RatesDegenerate { dimension } => {
                let what = match dimension {
                    0 => "all the same",
                    1 => "on one line (e.g. all about one axis)",
                    _ => "in one plane",
                };
                write!(
                    f,
                    "the true rate vectors are {what}: I+Σ and b need at least 4 rate vectors not in one plane \
                     (e.g. +30 and −30 °/s about z, and +30 °/s about x and about y)"
                )
            }
            FitError::NotAxisAligned { segment, angle_deg, limit_deg } => write!(
                f,
                "static segment {}: gravity is {angle_deg:.1}° from the nearest sensor axis (limit {limit_deg}°): \
                 --axis-aligned needs one sensor axis vertical in every position",
                segment + 1
            ),
            FitError::TooFewFaces { found, segments } => write!(
                f,
                "found {found} distinct face(s) up in {segments} static segment(s); the axis-aligned fit \
                 (per axis: 3 of I+Σ and 1 bias) needs at least 4 faces not all in one plane, \
                 e.g. +z, −z, +x, +y (better all six)"
            ),
            FitError::IllConditioned { condition, limit } => write!(
                f,
                "the data do not determine the parameters: condition number {condition:.3e} of the \
                 scaled Jacobian exceeds {limit:.0e} (add orientations spread over the sphere)"
            ),
            FitError::LeastSquares(LsError::TooFewRows { rows, unknowns }) => {
                write!(f, "{rows} equations for {unknowns} unknowns")
            }
            FitError::LeastSquares(LsError::RankDeficient { unknown }) => {
                write!(f, "parameter {unknown} is not determined by the data (rank deficient)")
            }
            FitError::NoConvergence { iterations } => {
                write!(f, "the fit did not converge in {iterations} iterations")
            }
            FitError::TooManySegments { capacity } => {
                write!(f, "more than {capacity} static segments")
            }
        }
    }
}
