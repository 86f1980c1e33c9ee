//! The benchmark's inputs: raw samples spread over the whole i16 range, the
//! chip scale they are read at, and the calibrations folded in. Everything is
//! a pure function of its arguments, so the emulated core and the host see
//! the same numbers.

use super::BATCH;
use triad::model::{Calibration, TemperatureTerms, TriadCalibration};
use triad::sensor::icm42688::config::Config;
use triad::sensor::{ImuScale, RawSample};

/// xorshift32 (Marsaglia 2003): small, integer-only, the same on every core.
struct XorShift32(u32);

impl XorShift32 {
    fn next(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    fn i16(&mut self) -> i16 {
        (self.next() >> 16) as u16 as i16
    }
}

/// Batch `index` of raw samples: every axis uniform over the whole i16 range
/// (so about 1 sample in 5000 has an axis at a limit code by chance), and
/// in each batch sample 7 has accel x at i16::MAX and sample 13 gyro z at
/// i16::MIN, so the clip flags are exercised in every batch.
///
/// The temperature starts each batch somewhere in −40..85 °C (the
/// ICM-42688-P's 132.48 LSB/°C around 25 °C) and rises one LSB every ten
/// samples, 0.75 °C/s at 1 kHz: a fast thermal ramp, so the refold rows see
/// a realistic drift within a batch.
pub fn raw_batch(index: usize, out: &mut [RawSample; BATCH]) {
    let mut rng = XorShift32(0x9E37_79B9 ^ (index as u32).wrapping_mul(0x85EB_CA6B));
    let start = (rng.next() % 16_540) as i16 - 8_611;
    for (n, s) in out.iter_mut().enumerate() {
        *s = RawSample {
            accel: [rng.i16(), rng.i16(), rng.i16()].map(i32::from),
            gyro: [rng.i16(), rng.i16(), rng.i16()].map(i32::from),
            temperature: start + (n / 10) as i16,
        };
    }
    out[7].accel[0] = i32::from(i16::MAX);
    out[13].gyro[2] = i32::from(i16::MIN);
}

/// The chip scale of the benchmark: the ICM-42688-P at ±16 g and ±2000 °/s
/// (the emulated board's configuration).
pub fn scale() -> ImuScale {
    Config::default().scale()
}

/// A realistic calibration: calibrations/default.toml's accelerometer (scale
/// within 0.2 %, misalignments within 0.2 %) and a gyroscope with the same
/// kind of errors.
pub fn realistic() -> Calibration {
    Calibration {
        id: 0x0BE7_C401,
        accel: TriadCalibration {
            scale_misalignment: [
                [1.002, 0.001, -0.0005],
                [0.0003, 0.998, 0.002],
                [0.0, -0.001, 1.001],
            ],
            bias: [0.05, -0.02, 0.10],
            temperature: None,
        },
        gyro: TriadCalibration {
            scale_misalignment: [
                [0.9985, -0.0012, 0.0007],
                [0.0021, 1.0017, -0.0004],
                [-0.0009, 0.0015, 1.0008],
            ],
            bias: [0.001, -0.002, 0.0005],
            temperature: None,
        },
        g_sensitivity: None,
    }
}

/// [`realistic`] with a gyroscope g-sensitivity of about 0.1 °/s per g on
/// the diagonal and a tenth of that across (issue 22's real unit showed
/// 0.12 °/s per g).
pub fn with_g_sensitivity() -> Calibration {
    let per_g = triad::units::dps_per_g_to_si(1.0);
    Calibration {
        id: 0x0BE7_C404,
        g_sensitivity: Some([
            [0.10 * per_g, 0.012 * per_g, -0.008 * per_g],
            [-0.011 * per_g, 0.12 * per_g, 0.009 * per_g],
            [0.007 * per_g, -0.010 * per_g, 0.09 * per_g],
        ]),
        ..realistic()
    }
}

/// An extreme but valid calibration: scale factors near the validation
/// bounds (0.5..1.5), misalignments near 0.1, biases of a few percent of
/// full scale. The fixed-point path must not overflow on it.
pub fn extreme() -> Calibration {
    Calibration {
        id: 0x0BE7_C402,
        accel: TriadCalibration {
            scale_misalignment: [
                [0.55, 0.09, -0.09],
                [-0.08, 1.45, 0.095],
                [0.07, -0.09, 0.6],
            ],
            bias: [3.0, -4.0, 5.0],
            temperature: None,
        },
        gyro: TriadCalibration {
            scale_misalignment: [
                [1.4, -0.09, 0.08],
                [0.095, 0.52, -0.07],
                [-0.09, 0.085, 1.3],
            ],
            bias: [0.5, -0.7, 0.9],
            temperature: None,
        },
        g_sensitivity: None,
    }
}

/// The realistic calibration with temperature terms on both triads (bias
/// cubic and (I+Σ) linear in ΔT around 25 °C): the refold rows.
pub fn with_temperature_terms() -> Calibration {
    let mut cal = realistic();
    let terms = |bias_per_c: f64| TemperatureTerms {
        reference_c: 25.0,
        bias_coefficients: [
            [bias_per_c, 1e-3 * bias_per_c, -1e-5 * bias_per_c],
            [-bias_per_c, 2e-3 * bias_per_c, 1e-5 * bias_per_c],
            [0.5 * bias_per_c, -1e-3 * bias_per_c, 2e-5 * bias_per_c],
        ],
        scale_misalignment_per_c: [[5e-5, 1e-6, 0.0], [-1e-6, -4e-5, 2e-6], [0.0, 1e-6, 3e-5]],
    };
    cal.accel.temperature = Some(terms(1e-3));
    cal.gyro.temperature = Some(terms(1e-5));
    cal
}
