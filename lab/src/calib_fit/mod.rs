//! Laboratory calibration fits: (I+Σ) and b from recorded data, in f64
//! (the caller owns the sample buffers).
//!
//! - [`static_segments`]: where a record is at rest.
//! - [`fits`]: the fits themselves (accelerometer in unknown orientations
//!   or on a cube's faces, gyroscope on a rate table or rig-free, its
//!   g-sensitivity, and across temperature).
//! - [`numerics`]: what the fits share: least squares (Givens QR),
//!   Levenberg–Marquardt, the algebraic ellipsoid, quaternions, 3×3 helpers.
//! - [`accel_frame`]: a truth's (I+Σ) in the rig-free fits' frame (the
//!   accelerometer's upper triangular corrected axes), for comparisons.
//! - [`hand_record`]: hand-turned records with known truth, for tests and
//!   benchmarks.
//!
//! Every refusal is a [`FitError`] that says what was found and what is needed.

pub mod accel_frame;
pub mod error;
pub mod fits;
pub mod hand_record;
pub mod numerics;
pub mod static_segments;

pub use error::FitError;
