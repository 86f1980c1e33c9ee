//! The fixed-point hot path against the f64 reference. The bound is the one
//! proven for the form in use (src/model/fixed.rs for the i64 form,
//! src/model/fixed_narrow.rs for the 32-bit form; `FixedCorrector::error_bound`), plus the f64 reference's own error
//! (≈ 3e−14 relative to Σ|K_ij||x_j| + |k_i|, see tests/model_f32.rs), for
//! which 1e−12·S_i is added. For every 16-bit range tested the bound must also
//! be ≤ 0.5 LSB of the sensor.

mod model_support;

use model_support::*;
use triad::model::{Calibration, Corrector, FixedCorrector, Orientation, Triad, TriadCalibration};
use triad::sensor::{CodeRange, ImuScale, RawSample, TriadScale};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

/// Checks one sample; returns the worst error in LSB.
fn check(c: &Corrector, fixed: &FixedCorrector, raw: &RawSample) -> f64 {
    let got = fixed.correct(raw);
    let exact = c.reference(raw);
    assert_eq!(got.clip, exact.clip);
    let as_f64 = got.to_f64();
    let bound = fixed.error_bound();
    let scale = c.scale();
    let mut worst_lsb: f64 = 0.0;
    for (k, (triad, g, w, x, lsb)) in [
        (
            Triad::Accel,
            as_f64.accel,
            exact.accel,
            raw.accel,
            scale.accel.si_per_lsb,
        ),
        (
            Triad::Gyro,
            as_f64.gyro,
            exact.gyro,
            raw.gyro,
            scale.gyro.si_per_lsb,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let s = magnitude(c, triad, x);
        for i in 0..3 {
            let err = (g[i] - w[i]).abs();
            assert!(
                err <= bound[k] + 1e-12 * s[i],
                "{triad:?}[{i}]: err {err:e} > bound {:e}, raw {raw:?}",
                bound[k]
            );
            worst_lsb = worst_lsb.max(err / lsb);
        }
    }
    let t_err = (as_f64.temperature - exact.temperature).abs();
    assert!(
        t_err <= bound[2] + 1e-12 * 300.0,
        "temperature err {t_err:e}"
    );
    worst_lsb
}

#[test]
fn fixed_path_is_within_its_proven_bound_and_half_an_lsb() {
    let mut rng = rng(0xF1C5);
    let mut worst_lsb: f64 = 0.0;
    for _ in 0..400 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        let c = Corrector::new(&cal, &scale, random_orientation(&mut rng)).unwrap();
        let fixed = c.to_fixed().expect("valid calibrations fit Q16.16");
        let bound = fixed.error_bound();
        assert!(
            bound[0] <= 0.5 * scale.accel.si_per_lsb,
            "accel bound {:e}",
            bound[0]
        );
        assert!(
            bound[1] <= 0.5 * scale.gyro.si_per_lsb,
            "gyro bound {:e}",
            bound[1]
        );
        for _ in 0..250 {
            worst_lsb = worst_lsb.max(check(&c, &fixed, &random_raw(&mut rng)));
        }
    }
    println!("fixed vs f64: worst error {worst_lsb:.4} LSB");
    assert!(worst_lsb <= 0.5);
}

/// The calibrations that make |K·raw + k| largest within the validated bounds:
/// diagonal 0.5, off-diagonals ±0.1 with the sign that adds up, bias at ±full
/// scale; (I+Σ)⁻¹ then has a 1-norm of up to 1/(0.5 − 0.2) = 3.3.
fn extreme_triads(full_scale: f64) -> Vec<TriadCalibration> {
    let mut out = Vec::new();
    for off in [-0.1, 0.1] {
        for diag in [0.5, 1.5] {
            for b in [-1.0, 1.0] {
                out.push(TriadCalibration {
                    scale_misalignment: [[diag, off, off], [off, diag, off], [off, off, diag]],
                    bias: [b * full_scale, -b * full_scale, b * full_scale],
                    temperature: None,
                });
            }
        }
    }
    out
}

fn corner_raws() -> Vec<RawSample> {
    let v = [i16::MIN, -32767, -1, 0, 1, 32766, i16::MAX];
    let mut out = Vec::new();
    for &x in &v {
        for &y in &v {
            for &z in &v {
                out.push(RawSample {
                    accel: [x, y, z].map(i32::from),
                    gyro: [z, x, y].map(i32::from),
                    temperature: x,
                });
            }
        }
    }
    out
}

#[test]
fn full_scale_inputs_with_extreme_valid_coefficients_do_not_overflow() {
    // Widest 16-bit ranges and a ±200 g / ±4000 °/s chip: the largest outputs
    // (≈ 6.7 × full scale) still fit Q16.16 m/s² and Q12.20 rad/s. Overflow checks are on
    // in test builds, so an i64 overflow would panic here.
    let high_g = ImuScale {
        accel: TriadScale {
            si_per_lsb: 200.0 * STANDARD_GRAVITY / 32768.0,
            full_scale: 200.0 * STANDARD_GRAVITY,
            codes: CodeRange::I16,
        },
        gyro: TriadScale {
            si_per_lsb: deg_to_rad(4000.0) / 32768.0,
            full_scale: deg_to_rad(4000.0),
            codes: CodeRange::I16,
        },
        temperature_per_lsb: 1.0 / 8.0,
        temperature_offset: 23.0,
    };
    let mut cases = 0;
    for scale in [widest_scale(), high_g] {
        for accel in extreme_triads(scale.accel.full_scale) {
            for gyro in extreme_triads(scale.gyro.full_scale) {
                for orientation in [Orientation::RotationNone, Orientation::Roll90Pitch180Yaw90] {
                    let cal = Calibration {
                        id: 1,
                        accel,
                        gyro,
                        g_sensitivity: None,
                    };
                    let c = Corrector::new(&cal, &scale, orientation).unwrap();
                    let fixed = c.to_fixed().unwrap();
                    for raw in corner_raws() {
                        check(&c, &fixed, &raw);
                        cases += 1;
                    }
                }
            }
        }
    }
    assert_eq!(cases, 2 * 8 * 8 * 2 * 343);
}

/// The ICM-42688-P's 20-bit FIFO values (src/model/fixed.rs: the i64 form
/// with inputs up to 2¹⁹, the 32-bit form refused): the extreme valid
/// calibrations on the 20-bit corner values, and random calibrations on
/// random 20-bit values, within the proven bound, which is within half the
/// 20-bit value's LSB. Overflow checks are on in test builds.
#[test]
fn twenty_bit_inputs_stay_within_the_bound_without_overflow() {
    let scale = triad::sensor::icm42688::config::high_resolution_scale();
    let corners = [-524_288, -524_284, -1, 0, 1, 524_280, 524_284];
    let mut corner_raws = Vec::new();
    for x in corners {
        for y in corners {
            for z in corners {
                corner_raws.push(RawSample {
                    accel: [x, y, z],
                    gyro: [z, x, y],
                    temperature: 0,
                });
            }
        }
    }
    let mut cases = 0;
    for accel in extreme_triads(scale.accel.full_scale) {
        for gyro in extreme_triads(scale.gyro.full_scale) {
            let cal = Calibration {
                id: 1,
                accel,
                gyro,
                g_sensitivity: None,
            };
            let c = Corrector::new(&cal, &scale, Orientation::Roll90Pitch180Yaw90).unwrap();
            let fixed = c.to_fixed().unwrap();
            assert_eq!(fixed.uses_32_bit_products(), [false, false, true]);
            for raw in &corner_raws {
                check(&c, &fixed, raw);
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 8 * 8 * 343);
    let mut rng = rng(0x20B1);
    let mut worst_lsb: f64 = 0.0;
    for _ in 0..100 {
        let cal = random_calibration(&mut rng, &scale);
        let c = Corrector::new(&cal, &scale, random_orientation(&mut rng)).unwrap();
        let fixed = c.to_fixed().unwrap();
        let bound = fixed.error_bound();
        assert!(bound[0] <= 0.5 * scale.accel.si_per_lsb, "{bound:?}");
        assert!(bound[1] <= 0.5 * scale.gyro.si_per_lsb, "{bound:?}");
        for _ in 0..200 {
            let mut axis = || rand::Rng::random_range(&mut rng, -524_288..=524_284);
            let raw = RawSample {
                accel: [axis(), axis(), axis()],
                gyro: [axis(), axis(), axis()],
                temperature: 0,
            };
            worst_lsb = worst_lsb.max(check(&c, &fixed, &raw));
        }
    }
    println!("fixed vs f64 on 20-bit inputs: worst error {worst_lsb:.4} LSB");
    assert!(worst_lsb <= 0.5);
}

#[test]
fn limit_codes_flag_their_whole_triad() {
    let c = Corrector::new(
        &Calibration::identity(0),
        &widest_scale(),
        Orientation::RotationNone,
    )
    .unwrap();
    let fixed = c.to_fixed().unwrap();
    let raw = |accel, gyro| RawSample {
        accel,
        gyro,
        temperature: 0,
    };
    let (min, max) = (i32::from(i16::MIN), i32::from(i16::MAX));
    for (r, accel, gyro) in [
        (raw([0, max, 0], [0; 3]), true, false),
        (raw([0; 3], [0, 0, min]), false, true),
        (raw([min, 0, 0], [max, 0, 0]), true, true),
        (raw([32766, -32767, 0], [-32767, 32766, 5]), false, false),
    ] {
        assert_eq!(
            (c.correct(&r).clip.accel, c.correct(&r).clip.gyro),
            (accel, gyro),
            "{r:?}"
        );
        assert_eq!(
            (fixed.correct(&r).clip.accel, fixed.correct(&r).clip.gyro),
            (accel, gyro),
            "{r:?}"
        );
        assert_eq!(c.reference(&r).clip, c.correct(&r).clip);
    }
}

#[test]
fn clip_detection_is_exact_for_every_i16_on_every_axis() {
    use triad::model::ClipFlags;
    let scale = widest_scale();
    for x in i16::MIN..=i16::MAX {
        let limit = x == i16::MIN || x == i16::MAX;
        for axis in 0..3 {
            let mut raw = RawSample {
                accel: [0, 1, -1],
                gyro: [32766, -32767, 0],
                temperature: 0,
            };
            raw.accel[axis] = i32::from(x);
            raw.gyro[2 - axis] = i32::from(x);
            assert_eq!(
                ClipFlags::of(&raw, &scale),
                ClipFlags {
                    accel: limit,
                    gyro: limit
                },
                "x = {x}, axis {axis}"
            );
        }
    }
}

#[test]
fn fixed_output_is_q16_16_accel_q12_20_gyro_si() {
    // Identity, s = 2⁻¹⁰ m/s² per LSB: raw 1024 is exactly 1 m/s² = 65536 in Q16.16.
    // Temperature 10·0.5 + 20 = 25 °C in Q16.16.
    let scale = ImuScale {
        accel: TriadScale {
            si_per_lsb: 1.0 / 1024.0,
            full_scale: 32.0,
            codes: CodeRange::I16,
        },
        gyro: TriadScale {
            si_per_lsb: 1.0 / 4096.0,
            full_scale: 8.0,
            codes: CodeRange::I16,
        },
        temperature_per_lsb: 0.5,
        temperature_offset: 20.0,
    };
    let c = Corrector::new(&Calibration::identity(0), &scale, Orientation::Yaw90).unwrap();
    let out = c.to_fixed().unwrap().correct(&RawSample {
        accel: [1024, 0, -512],
        gyro: [0, 4096, 0],
        temperature: 10,
    });
    // Yaw 90: board = (−y, x, z) of the sensor.
    assert_eq!(out.accel, [0, 65536, -32768]);
    // Gyro in Q12.20: 1 rad/s = 2²⁰ = 1048576.
    assert_eq!(out.gyro, [-1048576, 0, 0]);
    assert_eq!(out.temperature, 25 * 65536);
    assert_eq!(out.to_f64().accel, [0.0, 1.0, -0.5]);
    assert_eq!(out.to_f64().gyro, [-1.0, 0.0, 0.0]);
}

/// The 32-bit form holds every valid calibration of the usual ranges (the
/// cheap path on a Cortex-M0); the accelerometer of a ±200 g chip with an
/// almost 2× correction needs the i64 form (|K| = 0.11 m/s² per LSB is near
/// the 32-bit form's limit 0.125 before the correction). The other tests check both against the reference.
#[test]
fn usual_ranges_use_the_32_bit_form_and_very_wide_ones_the_i64_form() {
    let scale = |g: f64, dps: f64| ImuScale {
        accel: TriadScale {
            si_per_lsb: g * STANDARD_GRAVITY / 32768.0,
            full_scale: g * STANDARD_GRAVITY,
            codes: CodeRange::I16,
        },
        gyro: TriadScale {
            si_per_lsb: deg_to_rad(dps) / 32768.0,
            full_scale: deg_to_rad(dps),
            codes: CodeRange::I16,
        },
        temperature_per_lsb: 1.0 / 132.48,
        temperature_offset: 25.0,
    };
    let forms = |s: &ImuScale, t: TriadCalibration| {
        let cal = Calibration {
            id: 1,
            accel: t,
            gyro: t,
            g_sensitivity: None,
        };
        let c = Corrector::new(&cal, s, Orientation::RotationNone).unwrap();
        c.to_fixed().unwrap().uses_32_bit_products()
    };
    // (I+Σ) = 0.55·I, near the smallest valid scale factor 0.5: |K| = s/0.55.
    let shrink = TriadCalibration {
        scale_misalignment: [[0.55, 0.0, 0.0], [0.0, 0.55, 0.0], [0.0, 0.0, 0.55]],
        ..TriadCalibration::IDENTITY
    };
    for (g, dps) in [(2.0, 15.625), (16.0, 2000.0)] {
        assert_eq!(forms(&scale(g, dps), TriadCalibration::IDENTITY), [true; 3]);
        assert_eq!(
            forms(&scale(g, dps), shrink),
            [true; 3],
            "±{g} g, ±{dps} °/s"
        );
    }
    // 400 g: 0.12 m/s² per LSB, |K| = 0.22 > 2⁻³ (fixed_narrow.rs).
    assert_eq!(forms(&scale(400.0, 4000.0), shrink), [false, true, true]);
}
