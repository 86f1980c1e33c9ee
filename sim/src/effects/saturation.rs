//! Saturation at the measurement range: the output clips at ±range.

/// Clamps `x` to [−range, range] (NaN stays NaN: it is never produced here).
pub fn saturate(x: f64, range: f64) -> f64 {
    if x > range {
        range
    } else if x < -range {
        -range
    } else {
        x
    }
}
