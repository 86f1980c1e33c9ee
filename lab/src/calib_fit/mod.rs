//! Laboratory calibration fits: (I+Σ) and b from recorded data, in f64,
//! without allocation (the caller owns the sample and segment buffers).
//!
//! - [`static_segments`]: where a record is at rest.
//! - [`accel_fit`]: the accelerometer from static means in unknown
//!   orientations, |(I+Σ)⁻¹(f̂ − b)| = g, by Levenberg–Marquardt from the
//!   algebraic [`ellipsoid`]; (I+Σ) upper triangular by convention.
//! - [`accel_cube`]: the accelerometer from axis-aligned positions (a cube
//!   tumble), where gravity's direction is known: full (I+Σ), linear.
//! - [`gyro_fit`]: the gyroscope from rate-table segments with known rates,
//!   ω̂ = (I+Σ)ω + b, by linear least squares.
//! - [`accel_frame`]: a truth's (I+Σ) in the rig-free fits' frame (the
//!   accelerometer's upper triangular corrected axes), for comparisons.
//! - [`rig_free`]: the gyroscope from one hand-rotated record (turns
//!   between static poses integrated and matched to the accelerometer's
//!   gravity directions); [`hand_record`] makes such records with known
//!   truth; [`turn_sensitivity`]: the derivatives of an integrated turn,
//!   from one pass over the move.
//! - [`g_sensitivity`]: the gyroscope's g-sensitivity G from static poses in
//!   several orientations, and the poses' consistency test that accounts for it.
//! - Across temperature: [`thermal_coverage`] (the range, the reference
//!   and which terms the temperatures support), [`thermal_accel`] (the
//!   accelerometer's (I+Σ) linear and b cubic in ΔT from poses in unknown
//!   orientations at several temperatures), [`bias_polynomial`] (a bias
//!   against temperature from static means, for the gyroscope),
//!   [`thermal_gyro`] (the gyroscope's (I+Σ) linear in ΔT from hand turns
//!   at several temperatures).
//! - [`levenberg_marquardt`]: the nonlinear fits' minimiser; [`quaternion`]:
//!   attitude integration.
//! - [`qr`]: the least-squares solver both use (Givens QR, fixed size);
//!   [`small3`]: 3×3 helpers.
//!
//! Every refusal is a [`FitError`] that says what was found and what is needed.

pub mod accel_cube;
pub mod accel_fit;
pub mod accel_frame;
pub mod bias_polynomial;
pub mod ellipsoid;
pub mod error;
pub mod g_sensitivity;
pub mod gyro_fit;
pub mod hand_record;
pub mod levenberg_marquardt;
pub mod qr;
pub mod quaternion;
pub mod rig_free;
pub mod small3;
pub mod static_segments;
pub mod thermal_accel;
pub mod thermal_coverage;
pub mod thermal_gyro;
pub mod turn_sensitivity;

pub use error::FitError;
