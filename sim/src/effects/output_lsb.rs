//! The output register's least significant bit: each sample is rounded to a
//! multiple of the LSB (to nearest, halves away from zero, as an ADC's
//! mid-tread quantiser does). This is rate (or specific-force) rounding:
//! with a busy signal its error is white rate noise of variance LSB²/12, a
//! part of the white-noise term N, not the IEEE 952 quantisation term Q —
//! that one is angle (velocity) quantisation, [`super::increment_quantisation`].

/// Rounds `x` to a multiple of `lsb`; an LSB of zero leaves `x` unchanged.
pub fn round_to_lsb(x: f64, lsb: f64) -> f64 {
    if lsb > 0.0 {
        libm::round(x / lsb) * lsb
    } else {
        x
    }
}
