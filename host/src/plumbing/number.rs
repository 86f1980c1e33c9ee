//! Numbers in messages in a form a person reads: `1e300`, not 301 digits
//! (the core's [`Readable`], which its calibration errors use too); and the
//! check every positive option (a rate, a duration, a range) makes.

use triad::model::Readable;

/// `x` as the shortest decimal that reads back to it when that is short
/// (magnitudes 1e-5 up to 1e16, and zero), in exponent form otherwise.
pub fn readable(x: f64) -> String {
    Readable(x).to_string()
}

/// What `--rate` must be (`triad sim`, `triad allan`).
pub const RATE_WORDS: &str = "the sample rate must be a positive number of Hz";

/// The error of an option's value out of range: `OPTION VALUE: WORDS`,
/// `words` saying what it must be.
pub fn refused(option: &str, value: f64, words: &str) -> anyhow::Error {
    anyhow::anyhow!("{option} {}: {words}", readable(value))
}

/// `value` when it is positive and finite, else [`refused`] with `words`
/// (e.g. "must be a positive number of seconds").
pub fn positive(option: &str, value: f64, words: &str) -> anyhow::Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(refused(option, value, words))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_positive_finite_value_passes_and_the_error_names_option_and_value() {
        let words = "must be a positive number of Hz";
        assert_eq!(positive("--rate", 1e-300, words).unwrap(), 1e-300);
        for bad in [0.0, -0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(positive("--rate", bad, words).is_err(), "{bad}");
        }
        assert_eq!(
            positive("--rate", -1e300, words).unwrap_err().to_string(),
            "--rate -1e300: must be a positive number of Hz"
        );
    }

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
