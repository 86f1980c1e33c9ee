//! Why a fit was refused: each variant says what was found and what is needed.

use core::fmt;

use crate::calib_fit::numerics::qr::LsError;

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
        /// [`DISTINCT_ANGLE_DEG`](crate::calib_fit::fits::accel_fit::DISTINCT_ANGLE_DEG) apart).
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
    /// The record's times and samples differ in number, or a pose's samples
    /// are not within the record, after the previous pose's.
    PosesOutOfRecord {
        /// The pose (0-based).
        pose: usize,
        /// Samples in the record.
        samples: usize,
    },
    /// The gyro's full scale given is not a positive finite rate.
    InvalidFullScale {
        /// The value, rad/s.
        value: f64,
    },
    /// A gyro sample is near the gyro's range: the turn may have clipped.
    GyroNearRange {
        /// The sample (0-based).
        sample: usize,
        /// Its largest |axis|, rad/s.
        rate: f64,
        /// The gyro's full scale, rad/s.
        full_scale: f64,
        /// The accepted fraction of the full scale.
        fraction: f64,
    },
    /// The record turns too far between two samples for the integration.
    TooFastForRate {
        /// The sample (0-based) where the turn is fastest.
        sample: usize,
        /// The rotation between it and the next sample, degrees.
        rotation_deg: f64,
        /// The largest accepted, degrees.
        limit_deg: f64,
        /// The record's sample rate, Hz.
        rate_hz: f64,
    },
    /// The gyro's mean over a static pose strays from what the other poses
    /// predict for it (their bias, and their g-sensitivity where they
    /// support one): the unit turned during the pose (about the vertical,
    /// which the accelerometer does not see).
    PoseNotStatic {
        /// The pose (0-based).
        pose: usize,
        /// Its first and last sample's times, s.
        time_s: [f64; 2],
        /// The gyro axis (0..3).
        axis: usize,
        /// Its mean minus the others' prediction, rad/s.
        rate: f64,
        /// The largest accepted, rad/s.
        limit: f64,
        /// The limit in σ's of the residual.
        sigmas: f64,
        /// Whether the prediction included the g-sensitivity.
        with_g: bool,
        /// Poses checked.
        poses: usize,
    },
    /// Fewer turns between consecutive poses than the gyro fit needs.
    TooFewRotations {
        /// Consecutive pose pairs (poses − 1).
        rotations: usize,
        /// Those that turn by at least the smallest counted angle.
        turns: usize,
        /// The minimum.
        needed: usize,
    },
    /// The turns' axes lie near one plane or one axis: some column of the
    /// gyro's (I+Σ) is not determined.
    RotationAxesDegenerate {
        /// Turns whose axes were measured.
        turns: usize,
        /// The smallest and the middle eigenvalue of the axes' scatter
        /// (mean of a·aᵀ, trace 1; 1/3 each for axes spread evenly).
        spread: [f64; 2],
        /// The smallest accepted eigenvalue.
        needed: f64,
    },
    /// The gyro's (I+Σ) against temperature needs turns both colder and
    /// warmer than the reference temperature.
    TooFewTurnsForScale {
        /// Turns of ≥ 10° colder than the reference.
        colder: usize,
        /// Warmer.
        warmer: usize,
        /// The reference temperature, °C.
        reference_c: f64,
        /// The minimum on each side.
        needed: usize,
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
            FitError::LeastSquares(e) => write!(f, "{e}"),
            FitError::NoConvergence { iterations } => {
                write!(f, "the fit did not converge in {iterations} iterations")
            }
            FitError::PosesOutOfRecord { pose, samples } => write!(
                f,
                "pose {}: its samples are not within the record's {samples} (or not after the previous pose's)",
                pose + 1
            ),
            FitError::InvalidFullScale { value } => {
                write!(f, "gyro full scale {value} rad/s: must be a positive finite rate")
            }
            FitError::GyroNearRange { sample, rate, full_scale, fraction } => write!(
                f,
                "sample {}: the gyro reads {:.1} °/s, beyond {:.0} % of its full scale {:.0} °/s, so the turn may \
                 have clipped: turn more slowly (or set a wider gyro range)",
                sample + 1,
                rate.to_degrees(),
                100.0 * fraction,
                full_scale.to_degrees()
            ),
            FitError::TooFastForRate { sample, rotation_deg, limit_deg, rate_hz } => write!(
                f,
                "sample {}: the unit turns {rotation_deg:.2}° between two samples (limit {limit_deg}° at \
                 {rate_hz:.1} Hz, i.e. {:.0} °/s): turn more slowly or record at a higher rate",
                sample + 1,
                limit_deg * rate_hz
            ),
            FitError::PoseNotStatic { pose, time_s, axis, rate, limit, sigmas, with_g, poses } => write!(
                f,
                "pose {} ({:.2}–{:.2} s): the gyro's {} mean differs from what the other poses predict \
                 (their bias{}) by {:.4} °/s (limit {:.4} °/s: {sigmas:.1} σ of that difference, \
                 from the poses' own scatter and standard errors, at a family-wise level of {} over \
                 {poses} poses × 3 axes): the unit turned during that pose (about the vertical, which \
                 the accelerometer does not see); hold it still at each pose",
                pose + 1,
                time_s[0],
                time_s[1],
                ["x", "y", "z"].get(axis).copied().unwrap_or("?"),
                if with_g { " and g-sensitivity" } else { "" },
                rate.to_degrees(),
                limit.to_degrees(),
                crate::calib_fit::fits::g_sensitivity::POSE_FAMILY_LEVEL,
            ),
            FitError::TooFewRotations { rotations, turns, needed } => write!(
                f,
                "{turns} of the {rotations} moves between consecutive poses turn by ≥ {} degrees; the gyro fit \
                 (9 entries of I+Σ, 2 equations per turn: the gravity direction at the next pose) needs at least \
                 {needed}: add poses, turning the unit between each",
                crate::calib_fit::fits::rig_free::MIN_TURN_DEG
            ),
            FitError::RotationAxesDegenerate { turns, spread, needed } => {
                let what = if spread[1] < needed { "all about one axis" } else { "all about axes in one plane" };
                write!(
                    f,
                    "the {turns} turns are {what} (eigenvalues {:.4}, {:.4} of the axes' scatter, need ≥ {needed}): \
                 the gyro's response to rates about the missing axis is not determined; turn the unit about \
                 other axes too (tip it over its edges and spin it flat, not always the same way)",
                    spread[0], spread[1]
                )
            }
            FitError::TooFewTurnsForScale { colder, warmer, reference_c, needed } => write!(
                f,
                "the gyro's (I+Σ) against temperature needs ≥ {needed} turns of ≥ {} degrees between static \
                 poses both colder and warmer than the reference {reference_c:.1} °C; found {colder} colder and \
                 {warmer} warmer: turn the unit by hand between poses at each end of the range (the hand-soak script)",
                crate::calib_fit::fits::rig_free::MIN_TURN_DEG
            ),
        }
    }
}
