//! Unit conversions of inertial-sensor specifications. Inside the core all
//! quantities are SI; other units appear only at the edges.
//!
//! The nomenclature follows IEEE Std 952-1997 (Annex C, Allan variance) and
//! IEEE Std 1293 for accelerometers: a white-noise density N is the
//! coefficient of the two-sided rate PSD S(f) = N², so the angle (or velocity)
//! it integrates to grows as σ(t) = N·√t. Data sheets quote the same N in
//! several units:
//!
//! - angle random walk (ARW): °/√h or (°/s)/√Hz, with 1 (°/s)/√Hz = 1 °/√s = 60 °/√h;
//! - velocity random walk (VRW): (m/s)/√h or g/√Hz, with
//!   1 g/√Hz = 9.80665 (m/s)/√s = 588.399 (m/s)/√h;
//! - rate random walk (RRW): (°/h)/√h; acceleration random walk: (m/s/h)/√h;
//! - bias instability: °/h or µg (the flicker floor of the Allan deviation).

/// Standard gravity in m/s² (CGPM 1901), used for every g ↔ m/s² conversion.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Seconds in an hour.
pub const SECONDS_PER_HOUR: f64 = 3600.0;

/// √(seconds in an hour) = 60: the factor between "per √s" and "per √h".
pub const SQRT_SECONDS_PER_HOUR: f64 = 60.0;

/// Earth's rotation rate in rad/s (WGS 84, NIMA TR8350.2 §3.2.4: ω = 7.292115×10⁻⁵ rad/s).
pub const EARTH_RATE: f64 = 7.292_115e-5;

/// Degrees → radians.
pub fn deg_to_rad(deg: f64) -> f64 {
    deg * (core::f64::consts::PI / 180.0)
}

/// Radians → degrees.
pub fn rad_to_deg(rad: f64) -> f64 {
    rad * (180.0 / core::f64::consts::PI)
}

/// g → m/s² (standard gravity).
pub fn g_to_mps2(g: f64) -> f64 {
    g * STANDARD_GRAVITY
}

/// m/s² → g (standard gravity).
pub fn mps2_to_g(a: f64) -> f64 {
    a / STANDARD_GRAVITY
}

/// Micro-g → m/s².
pub fn ug_to_mps2(ug: f64) -> f64 {
    ug * 1e-6 * STANDARD_GRAVITY
}

/// m/s² → micro-g.
pub fn mps2_to_ug(a: f64) -> f64 {
    a / (1e-6 * STANDARD_GRAVITY)
}

/// Parts per million → a plain ratio.
pub fn ppm_to_ratio(ppm: f64) -> f64 {
    ppm * 1e-6
}

/// A plain ratio → parts per million.
pub fn ratio_to_ppm(ratio: f64) -> f64 {
    ratio * 1e6
}

/// ARW in (°/s)/√Hz → °/√h (× 60).
pub fn deg_per_s_per_sqrt_hz_to_deg_per_sqrt_h(arw: f64) -> f64 {
    arw * SQRT_SECONDS_PER_HOUR
}

/// ARW in °/√h → (°/s)/√Hz (÷ 60).
pub fn deg_per_sqrt_h_to_deg_per_s_per_sqrt_hz(arw: f64) -> f64 {
    arw / SQRT_SECONDS_PER_HOUR
}

/// ARW in °/√h → SI rate noise density (rad/s)/√Hz.
pub fn arw_deg_per_sqrt_h_to_si(arw: f64) -> f64 {
    deg_to_rad(deg_per_sqrt_h_to_deg_per_s_per_sqrt_hz(arw))
}

/// SI rate noise density (rad/s)/√Hz → ARW in °/√h.
pub fn arw_si_to_deg_per_sqrt_h(density: f64) -> f64 {
    deg_per_s_per_sqrt_hz_to_deg_per_sqrt_h(rad_to_deg(density))
}

/// Rate random walk in (°/h)/√h → SI (rad/s)/√s.
///
/// 1 (°/h)/√h = (1/3600 °/s)/(60 √s) = 1/216 000 (°/s)/√s.
pub fn rrw_deg_per_h_per_sqrt_h_to_si(rrw: f64) -> f64 {
    deg_to_rad(rrw / (SECONDS_PER_HOUR * SQRT_SECONDS_PER_HOUR))
}

/// SI rate random walk (rad/s)/√s → (°/h)/√h.
pub fn rrw_si_to_deg_per_h_per_sqrt_h(rrw: f64) -> f64 {
    rad_to_deg(rrw) * SECONDS_PER_HOUR * SQRT_SECONDS_PER_HOUR
}

/// Gyro g-sensitivity (°/s)/g → (rad/s)/(m/s²).
pub fn dps_per_g_to_si(g_sensitivity: f64) -> f64 {
    deg_to_rad(g_sensitivity) / STANDARD_GRAVITY
}

/// Gyro g-sensitivity (rad/s)/(m/s²) → (°/s)/g.
pub fn si_to_dps_per_g(g_sensitivity: f64) -> f64 {
    rad_to_deg(g_sensitivity) * STANDARD_GRAVITY
}

/// Gyro bias (or bias instability) in °/h → rad/s.
pub fn deg_per_h_to_rad_per_s(bias: f64) -> f64 {
    deg_to_rad(bias / SECONDS_PER_HOUR)
}

/// Gyro bias in rad/s → °/h.
pub fn rad_per_s_to_deg_per_h(bias: f64) -> f64 {
    rad_to_deg(bias) * SECONDS_PER_HOUR
}

/// VRW in g/√Hz → (m/s)/√h (1 g/√Hz = 588.399 (m/s)/√h).
pub fn g_per_sqrt_hz_to_m_per_s_per_sqrt_h(vrw: f64) -> f64 {
    g_to_mps2(vrw) * SQRT_SECONDS_PER_HOUR
}

/// VRW in (m/s)/√h → g/√Hz.
pub fn m_per_s_per_sqrt_h_to_g_per_sqrt_hz(vrw: f64) -> f64 {
    mps2_to_g(vrw / SQRT_SECONDS_PER_HOUR)
}

/// VRW in (m/s)/√h → SI acceleration noise density (m/s²)/√Hz.
pub fn vrw_m_per_s_per_sqrt_h_to_si(vrw: f64) -> f64 {
    vrw / SQRT_SECONDS_PER_HOUR
}

/// Accelerometer noise density in µg/√Hz → SI (m/s²)/√Hz.
pub fn ug_per_sqrt_hz_to_si(density: f64) -> f64 {
    ug_to_mps2(density)
}

/// SI acceleration noise density (m/s²)/√Hz → µg/√Hz.
pub fn si_to_ug_per_sqrt_hz(density: f64) -> f64 {
    mps2_to_ug(density)
}

/// Acceleration random walk in (m/s/h)/√h → SI (m/s²)/√s.
pub fn accel_rw_m_per_s_per_h_per_sqrt_h_to_si(rw: f64) -> f64 {
    rw / (SECONDS_PER_HOUR * SQRT_SECONDS_PER_HOUR)
}

/// RMS noise in a bandwidth from a white-noise density: σ = N·√B.
///
/// `bandwidth_hz` is the equivalent noise bandwidth; for band-limited sampled
/// white noise at rate fs it is fs (two-sided density over ±fs/2).
pub fn resolution_from_density(density: f64, bandwidth_hz: f64) -> f64 {
    density * libm::sqrt(bandwidth_hz)
}

/// The standard deviation of the angle (or velocity) a white-noise density
/// integrates to after `seconds`: σ(t) = N·√t.
pub fn random_walk_sigma(density: f64, seconds: f64) -> f64 {
    density * libm::sqrt(seconds)
}
