//! Unit conversions of inertial-sensor specifications. Inside the core all
//! quantities are SI; other units appear only at the edges.

/// Standard gravity in m/s² (CGPM 1901), used for every g ↔ m/s² conversion.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Degrees → radians.
pub fn deg_to_rad(deg: f64) -> f64 {
    deg * (core::f64::consts::PI / 180.0)
}

/// Radians → degrees.
pub fn rad_to_deg(rad: f64) -> f64 {
    rad * (180.0 / core::f64::consts::PI)
}
