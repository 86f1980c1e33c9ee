//! The numerical tools the fits share: the least-squares solver (Givens QR,
//! fixed size), the nonlinear minimiser, the algebraic ellipsoid that
//! starts the accelerometer's iteration, quaternions for attitude
//! integration, and 3×3 helpers.
//!
//! - [`qr`]: least squares by Givens QR, fixed size, no normal equations.
//! - [`levenberg_marquardt`]: the nonlinear fits' minimiser.
//! - [`ellipsoid`]: the algebraic ellipsoid through static means.
//! - [`quaternion`]: attitude integration (RK4 on the quaternion).
//! - [`small3`]: 3×3 helpers beyond `triad::model::matrix`.
//! - [`error`]: why a numerical step failed ([`NumericsError`]), which
//!   every fit's own error wraps.

pub mod ellipsoid;
pub mod error;
pub mod levenberg_marquardt;
pub mod qr;
pub mod quaternion;
pub mod small3;

pub use error::NumericsError;
