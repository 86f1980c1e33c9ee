//! The calibration fits, each from the statistics of a record to (I+Σ), b
//! (and G, temperature terms) with σ's and degrees of freedom. Each fit has
//! its own error, holding only what that fit can refuse; their numerical
//! failures are one [`NumericsError`](crate::calib_fit::numerics::NumericsError)
//! that each wraps.
//!
//! - [`accel_fit`]: the accelerometer from static means in unknown
//!   orientations, |(I+Σ)⁻¹(f̂ − b)| = g, by Levenberg–Marquardt from the
//!   algebraic ellipsoid; (I+Σ) upper triangular by convention.
//! - [`accel_cube`]: the accelerometer from axis-aligned positions (a cube
//!   tumble), where gravity's direction is known: full (I+Σ), linear.
//! - [`gyro_fit`]: the gyroscope from rate-table segments with known rates,
//!   ω̂ = (I+Σ)ω + b, by linear least squares.
//! - [`rig_free`]: the gyroscope from one hand-rotated record (turns
//!   between static poses integrated and matched to the accelerometer's
//!   gravity directions); [`move_selection`]: which moves between poses
//!   it can use; [`turn_sensitivity`]: the derivatives of an integrated
//!   turn, from one pass over the move; [`turn_refusals`]: what it and the
//!   gyroscope's fit across temperature both refuse.
//! - [`g_sensitivity`]: the gyroscope's g-sensitivity G from static poses in
//!   several orientations, and the poses' consistency test that accounts for
//!   it; [`static_gyro`]: the gyroscope's bias and G from a record of
//!   static poses alone; [`gyro_at_rest`]: `fit gyro --static` whole, the
//!   bias of a still record or the bias and G of its poses.
//! - [`imu`]: `fit imu` whole, from one hand-turned record (or a cube
//!   tumble) and its options to both triads with what the report says.
//! - Across temperature: [`thermal_coverage`] (the range, the reference
//!   and which terms the temperatures support), [`thermal_accel`] (the
//!   accelerometer's (I+Σ) linear and b cubic in ΔT from poses in unknown
//!   orientations at several temperatures), [`bias_polynomial`] (a bias
//!   against temperature from static means, for the gyroscope),
//!   [`thermal_gyro`] (the gyroscope's (I+Σ) linear in ΔT from hand turns
//!   at several temperatures); [`thermal`]: `fit thermal` whole, from the
//!   records and options to both triads' terms with what the report says.

pub mod accel_cube;
pub mod accel_fit;
pub mod bias_polynomial;
pub mod g_sensitivity;
pub mod gyro_at_rest;
pub mod gyro_fit;
pub mod imu;
pub mod move_selection;
pub mod rig_free;
pub mod static_gyro;
pub mod thermal;
pub mod thermal_accel;
pub mod thermal_coverage;
pub mod thermal_gyro;
pub mod turn_refusals;
pub mod turn_sensitivity;
