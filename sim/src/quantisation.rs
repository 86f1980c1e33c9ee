//! Quantisation to a least significant bit: the output moves in steps of the
//! LSB (rounded to nearest, halves away from zero as an ADC's mid-tread
//! quantiser does). Its noise is uniform with variance LSB²/12 (IEEE Std 952
//! Annex C.1, quantisation noise).

/// Rounds `x` to a multiple of `lsb`; an LSB of zero leaves `x` unchanged.
pub fn quantise(x: f64, lsb: f64) -> f64 {
    if lsb > 0.0 {
        libm::round(x / lsb) * lsb
    } else {
        x
    }
}
