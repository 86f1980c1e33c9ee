//! The batch kernel (raw FIFO samples straight to a batch frame's counts):
//! bit for bit the f32 correction rounded to the frame's power-of-two LSB,
//! so within half a count (plus the f32 kernel's own bound) of the f64
//! reference, and its clip flags those of the raw samples and of the range.

mod model_support;

use model_support::*;
use triad::model::batch_kernel::{fixed_point_lsb, to_counts, MAX_COUNTS};
use triad::model::{BatchKernel, Corrector, Triad};
use triad::sensor::RawSample;

/// f32's unit roundoff.
const U: f64 = 1.0 / (1u64 << 24) as f64;

#[test]
fn the_frame_lsb_is_a_power_of_two_between_one_and_a_half_and_three_chip_lsbs() {
    let mut rng = rng(0x15B);
    for _ in 0..200 {
        let scale = random_scale(&mut rng);
        for chip_lsb in [scale.accel.si_per_lsb, scale.gyro.si_per_lsb] {
            let lsb = f64::from(fixed_point_lsb(chip_lsb));
            assert_eq!(lsb.log2().fract(), 0.0, "{lsb} is not a power of two");
            let ratio = lsb / chip_lsb;
            assert!((1.5..3.0).contains(&ratio), "{lsb} is {ratio} chip LSBs");
        }
    }
    // The ICM-42688-P at ±16 g and ±2000 °/s (PROTOCOL.md §20's example).
    assert_eq!(fixed_point_lsb(16.0 * 9.80665 / 32768.0), 1.0 / 128.0);
    assert_eq!(
        fixed_point_lsb(2000.0f64.to_radians() / 32768.0),
        1.0 / 512.0
    );
}

#[test]
fn counts_are_the_f32_correction_rounded_and_within_half_a_count_of_the_reference() {
    let mut rng = rng(0xBA7C);
    let mut checked = 0usize;
    for _ in 0..300 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        let corrector = Corrector::new(&cal, &scale, random_orientation(&mut rng)).unwrap();
        let kernel = BatchKernel::new(&corrector);
        let raw: Vec<RawSample> = (0..32).map(|_| random_raw(&mut rng)).collect();
        let mut out = [[0i16; 6]; 32];
        let clip = kernel.correct(&raw, &mut out);
        let mut any = (false, false);
        for (r, counts) in raw.iter().zip(&out) {
            let f = corrector.correct(r);
            let reference = corrector.reference(r);
            for k in 0..3 {
                for (triad, lsb, value, exact, got, any_clip) in [
                    (
                        Triad::Accel,
                        kernel.accel_lsb(),
                        f.accel[k],
                        reference.accel[k],
                        counts[k],
                        &mut any.0,
                    ),
                    (
                        Triad::Gyro,
                        kernel.gyro_lsb(),
                        f.gyro[k],
                        reference.gyro[k],
                        counts[3 + k],
                        &mut any.1,
                    ),
                ] {
                    let (expected, clipped) = to_counts(value, lsb);
                    assert_eq!(got, expected, "{triad:?}[{k}] of {r:?}");
                    *any_clip |= clipped;
                    if !clipped {
                        // Half a count, plus the f32 kernel's own error
                        // (≤ 5.00001·u·S_i, derived in tests/model_f32.rs).
                        let error = (f64::from(got) * f64::from(lsb) - exact).abs();
                        let raw_triad = if triad == Triad::Accel {
                            r.accel
                        } else {
                            r.gyro
                        };
                        let s_i = magnitude(&corrector, triad, raw_triad)[k];
                        assert!(
                            error <= 0.5 * f64::from(lsb) + 5.00001 * U * s_i,
                            "{triad:?}[{k}]: {error}, lsb {lsb}, counts {got}, f32 {value}, f64 {exact}"
                        );
                        checked += 1;
                    }
                }
            }
            let at_limit = triad::model::ClipFlags::of(r, corrector.scale());
            any.0 |= at_limit.accel;
            any.1 |= at_limit.gyro;
        }
        assert_eq!((clip.accel, clip.gyro), any);
    }
    assert!(checked > 50_000, "only {checked} values in range");
}

#[test]
fn a_raw_axis_at_its_limit_or_a_value_beyond_the_range_flags_its_triad() {
    let mut rng = rng(0xC11);
    let scale = random_scale(&mut rng);
    let cal = triad::model::Calibration {
        id: 1,
        accel: triad::model::TriadCalibration::IDENTITY,
        gyro: triad::model::TriadCalibration::IDENTITY,
        g_sensitivity: None,
    };
    let corrector = Corrector::new(&cal, &scale, Default::default()).unwrap();
    let kernel = BatchKernel::new(&corrector);
    let still = RawSample {
        accel: [100, -200, 300],
        gyro: [1, 2, 3],
        temperature: 0,
    };
    let mut out = [[0i16; 6]; 2];
    let clip = kernel.correct(&[still, still], &mut out);
    assert_eq!((clip.accel, clip.gyro), (false, false));
    let at_limit = RawSample {
        gyro: [1, i32::from(i16::MIN), 3],
        ..still
    };
    let clip = kernel.correct(&[still, at_limit], &mut out);
    assert_eq!((clip.accel, clip.gyro), (false, true));
    // Counts never take −32768, so the range is symmetric.
    assert!(out.iter().flatten().all(|&c| c >= -MAX_COUNTS));
}

/// A calibration whose correction can carry a value beyond ±MAX_COUNTS (the
/// accelerometer's x scale 0.55: its inverse nearly doubles x): the batch's
/// counts are still to_counts of the f32 correction, clipped where the value
/// is beyond the range, and the accelerometer's flag is set by the range
/// alone (no raw axis is at a limit code).
#[test]
fn values_beyond_the_range_clip_bit_for_bit_and_flag_their_triad() {
    let mut rng = rng(0xC1A9);
    let scale = triad::sensor::icm42688::config::Config::default().scale();
    let mut cal = triad::model::Calibration {
        id: 2,
        accel: triad::model::TriadCalibration::IDENTITY,
        gyro: triad::model::TriadCalibration::IDENTITY,
        g_sensitivity: None,
    };
    cal.accel.scale_misalignment[0][0] = 0.55;
    let corrector = Corrector::new(&cal, &scale, Default::default()).unwrap();
    let kernel = BatchKernel::new(&corrector);
    let mut raw: Vec<RawSample> = (0..32)
        .map(|_| {
            let mut r = random_raw(&mut rng);
            r.accel = r.accel.map(|x| x.clamp(-32767, 32766));
            r.gyro = r.gyro.map(|x| x.clamp(-32767, 32766));
            r
        })
        .collect();
    raw[5].accel[0] = 32000;
    let mut out = [[0i16; 6]; 32];
    let clip = kernel.correct(&raw, &mut out);
    let mut beyond = 0;
    for (r, counts) in raw.iter().zip(&out) {
        let f = corrector.correct(r);
        for k in 0..3 {
            let (a, a_clip) = to_counts(f.accel[k], kernel.accel_lsb());
            let (g, g_clip) = to_counts(f.gyro[k], kernel.gyro_lsb());
            assert_eq!((counts[k], counts[3 + k]), (a, g), "{r:?}");
            assert!(!g_clip);
            beyond += usize::from(a_clip);
        }
    }
    assert!(beyond > 0, "sample 5's x is beyond the range");
    assert_eq!((clip.accel, clip.gyro), (true, false));
    // The same batch without the samples that clip is not flagged.
    let keep: Vec<RawSample> = raw
        .iter()
        .filter(|r| {
            let f = corrector.correct(r);
            (0..3).all(|k| !to_counts(f.accel[k], kernel.accel_lsb()).1)
        })
        .copied()
        .collect();
    assert!(!keep.is_empty() && keep.len() < raw.len());
    let clip = kernel.correct(&keep, &mut out);
    assert_eq!((clip.accel, clip.gyro), (false, false));
}
