//! Numbers in messages in a form a person reads: `1e300`, not 301 digits
//! (the core's [`Readable`], which its calibration errors use too).

use triad::model::Readable;

/// `x` as the shortest decimal that reads back to it when that is short
/// (magnitudes 1e-5 up to 1e16, and zero), in exponent form otherwise.
pub fn readable(x: f64) -> String {
    Readable(x).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_and_small_magnitudes_take_the_exponent_form() {
        assert_eq!(readable(1e300), "1e300");
        assert_eq!(readable(-1.5e308), "-1.5e308");
        assert_eq!(readable(2.5e-9), "2.5e-9");
        assert_eq!(readable(16.0), "16");
        assert_eq!(readable(-0.125), "-0.125");
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(f64::NAN), "NaN");
        assert_eq!(readable(f64::NEG_INFINITY), "-inf");
    }
}
