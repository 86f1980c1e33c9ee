//! Laboratory calibration fits: (I+Σ) and b from recorded data, in f64
//! (the caller owns the sample buffers).
//!
//! - [`static_segments`]: where a record is at rest; [`poses`]: a whole
//!   record's poses (the detector for its rate, each part searched alone,
//!   each pose's statistics).
//! - [`fits`]: the fits themselves (accelerometer in unknown orientations
//!   or on a cube's faces, gyroscope on a rate table or rig-free, its
//!   g-sensitivity, and across temperature).
//! - [`numerics`]: what the fits share: least squares (Givens QR),
//!   Levenberg–Marquardt, the algebraic ellipsoid, quaternions, 3×3 helpers.
//! - [`accel_frame`]: a truth's (I+Σ) in the rig-free fits' frame (the
//!   accelerometer's upper triangular corrected axes), for comparisons.
//! - [`stillness`]: whether a record (or a pose) is still, by its block
//!   means and its mean rate.
//! - [`hand_record`]: hand-turned records with known truth, for tests and
//!   benchmarks.
//!
//! Every refusal says what was found and what is needed. Each fit has its
//! own error, holding only what it can refuse: the whole fits
//! ([`fits::imu::ImuFitError`], [`fits::thermal::ThermalFitError`]), their
//! parts ([`fits::accel_fit::AccelFitError`],
//! [`fits::accel_cube::AccelCubeError`], [`fits::gyro_fit::GyroFitError`],
//! [`fits::rig_free::RigFreeError`], [`fits::static_gyro`]'s
//! [`fits::g_sensitivity::PoseNotStatic`],
//! [`fits::thermal_accel::ThermalAccelError`],
//! [`fits::thermal_gyro::ThermalGyroError`],
//! [`fits::bias_polynomial::BiasPolynomialError`]), static detection
//! ([`static_segments::DetectError`]) and the temperatures' coverage
//! ([`fits::thermal_coverage::CoverageError`]); a numerical failure is a
//! [`numerics::NumericsError`] that each wraps.

pub mod accel_frame;
pub mod fits;
pub mod hand_record;
pub mod numerics;
pub mod poses;
pub mod static_segments;
pub mod stillness;
