//! Shared by the tests/model_*.rs files: random valid calibrations, sensor
//! scales and raw samples, reproducible from a seed.
#![allow(dead_code)]

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use triad::model::{
    Calibration, Corrector, Orientation, TemperatureTerms, Triad, TriadCalibration,
};
use triad::sensor::{CodeRange, ImuScale, RawSample, TriadScale};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

/// A seeded generator, so a failure is reproducible.
pub fn rng(seed: u64) -> SmallRng {
    SmallRng::seed_from_u64(seed)
}

/// A 16-bit chip at one of its usual ranges: accel ±2..16 g, gyro ±15.625..2000 °/s
/// (the ICM-42688-P's finest gyro range is ±15.625 °/s).
pub fn random_scale(rng: &mut SmallRng) -> ImuScale {
    let g = [2.0, 4.0, 8.0, 16.0][rng.random_range(0..4)] * STANDARD_GRAVITY;
    let dps = deg_to_rad(
        [15.625, 31.25, 62.5, 125.0, 250.0, 500.0, 1000.0, 2000.0][rng.random_range(0..8)],
    );
    ImuScale {
        accel: TriadScale {
            si_per_lsb: g / 32768.0,
            full_scale: g,
            codes: CodeRange::I16,
        },
        gyro: TriadScale {
            si_per_lsb: dps / 32768.0,
            full_scale: dps,
            codes: CodeRange::I16,
        },
        temperature_per_lsb: 1.0 / 132.48,
        temperature_offset: 25.0,
    }
}

/// ±16 g, ±2000 °/s: the widest usual ranges.
pub fn widest_scale() -> ImuScale {
    let g = 16.0 * STANDARD_GRAVITY;
    let dps = deg_to_rad(2000.0);
    ImuScale {
        accel: TriadScale {
            si_per_lsb: g / 32768.0,
            full_scale: g,
            codes: CodeRange::I16,
        },
        gyro: TriadScale {
            si_per_lsb: dps / 32768.0,
            full_scale: dps,
            codes: CodeRange::I16,
        },
        temperature_per_lsb: 1.0 / 132.48,
        temperature_offset: 25.0,
    }
}

/// A random valid triad: half the time a realistic one (scale within 3 %,
/// misalignment within 1 %, bias within 2 % of full scale), otherwise one
/// anywhere in the validated bounds (diagonal 0.5..1.5, |off| ≤ 0.1, |b| ≤ FS).
pub fn random_triad(rng: &mut SmallRng, full_scale: f64) -> TriadCalibration {
    let extreme = rng.random_bool(0.5);
    let (d, o, b) = if extreme {
        (0.5, 0.1, 1.0)
    } else {
        (0.03, 0.01, 0.02)
    };
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = if i == j {
                1.0 + rng.random_range(-d..=d)
            } else {
                rng.random_range(-o..=o)
            };
        }
    }
    let bias = [(); 3].map(|_| rng.random_range(-b..=b) * full_scale);
    TriadCalibration {
        scale_misalignment: m,
        bias,
        temperature: None,
    }
}

/// A random valid calibration for `scale`: half of them with a gyro
/// g-sensitivity G, entries anywhere within the validated bound.
pub fn random_calibration(rng: &mut SmallRng, scale: &ImuScale) -> Calibration {
    let limit = triad::model::validate::MAX_G_SENSITIVITY;
    Calibration {
        id: rng.random(),
        accel: random_triad(rng, scale.accel.full_scale),
        gyro: random_triad(rng, scale.gyro.full_scale),
        g_sensitivity: rng
            .random_bool(0.5)
            .then(|| [(); 3].map(|_| [(); 3].map(|_| rng.random_range(-limit..=limit)))),
    }
}

/// Small, valid temperature terms (scale TC ≤ 300 ppm/°C, bias drift small
/// enough to stay within full scale over −40..85 °C for realistic biases).
pub fn random_temperature_terms(rng: &mut SmallRng, full_scale: f64) -> TemperatureTerms {
    let c = 1e-4 * full_scale;
    TemperatureTerms {
        reference_c: rng.random_range(15.0..35.0),
        bias_coefficients: [(); 3].map(|_| {
            [
                rng.random_range(-c..c),
                rng.random_range(-c..c) * 1e-2,
                rng.random_range(-c..c) * 1e-4,
            ]
        }),
        scale_misalignment_per_c: [(); 3].map(|_| [(); 3].map(|_| rng.random_range(-3e-4..3e-4))),
    }
}

/// A random orientation of the 24.
pub fn random_orientation(rng: &mut SmallRng) -> Orientation {
    Orientation::ALL[rng.random_range(0..24)]
}

/// Raw samples over the full i16 range; one in eight axes at a limit code.
pub fn random_raw(rng: &mut SmallRng) -> RawSample {
    let mut axis = || {
        i32::from(match rng.random_range(0..16) {
            0 => i16::MIN,
            1 => i16::MAX,
            _ => rng.random::<i16>(),
        })
    };
    RawSample {
        accel: [axis(), axis(), axis()],
        gyro: [axis(), axis(), axis()],
        temperature: rng.random(),
    }
}

/// S_i = Σ_j |K_ij|·|x_j| + |k_i| for raw counts x: the scale of the
/// kernels' rounding errors.
pub fn magnitude(c: &Corrector, triad: Triad, x: [i32; 3]) -> [f64; 3] {
    let f = c.folded(triad);
    [0, 1, 2].map(|i| {
        (0..3)
            .map(|j| f.k[i][j].abs() * f64::from(x[j]).abs())
            .sum::<f64>()
            + f.offset[i].abs()
    })
}
