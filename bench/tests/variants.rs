//! The benchmark's variants on the host: the same functions the benchmark
//! firmware times on the emulated cores (`cargo xtask bench`, whose outputs
//! `cargo xtask test` checks against these bit for bit).

use triad::model::FixedCorrector;
use triad::protocol::{Decoder, Flags};
use triad::sensor::RawSample;
use triad_bench::inputs::{self, raw_batch};
use triad_bench::kernels::{NoMeter, Output};
use triad_bench::{Bench, Variant, BATCH, BATCHES};

fn all_inputs() -> Vec<RawSample> {
    let mut batch = [RawSample::default(); BATCH];
    (0..BATCHES)
        .flat_map(|i| {
            raw_batch(i, &mut batch);
            batch
        })
        .collect()
}

#[test]
fn inputs_span_the_raw_range_with_limit_codes_and_a_slow_temperature_ramp() {
    let raws = all_inputs();
    assert_eq!(raws.len(), BATCH * BATCHES);
    let axes = || raws.iter().flat_map(|r| r.accel.iter().chain(&r.gyro));
    let (lo, hi) = (axes().min().unwrap(), axes().max().unwrap());
    assert_eq!((*lo, *hi), (i32::from(i16::MIN), i32::from(i16::MAX)));
    // Every batch holds an accel and a gyro limit code (samples 7 and 13).
    for batch in raws.chunks(BATCH) {
        assert_eq!(batch[7].accel[0], i32::from(i16::MAX));
        assert_eq!(batch[13].gyro[2], i32::from(i16::MIN));
        // One temperature LSB per ten samples: 10 LSB across a batch.
        let rise = batch[BATCH - 1].temperature - batch[0].temperature;
        assert_eq!(rise, (BATCH as i16 - 1) / 10);
    }
    let scale = inputs::scale();
    for r in &raws {
        let t = scale.temperature_c(r.temperature);
        assert!((-40.0..=85.0).contains(&t), "{t} °C");
    }
}

#[test]
fn every_variant_runs_and_its_digest_depends_on_its_outputs() {
    let realistic = Bench::realistic();
    let extreme = Bench::new(&inputs::extreme());
    for v in Variant::ALL {
        let a = realistic.run(v, &mut NoMeter).unwrap();
        assert_eq!(
            a,
            realistic.run(v, &mut NoMeter).unwrap(),
            "{v:?} is deterministic"
        );
        // The refold and g-sensitivity rows have calibrations of their own.
        let uses_calibration = v.read_watermark().is_none()
            && v.without_g_sensitivity().is_none()
            && !matches!(v, Variant::RefoldEverySample | Variant::RefoldLowRate);
        if let Some(base) = v.without_g_sensitivity() {
            assert_ne!(
                a,
                realistic.run(base, &mut NoMeter).unwrap(),
                "{v:?}: G changes the outputs"
            );
        }
        let b = extreme.run(v, &mut NoMeter).unwrap();
        assert_eq!(
            a != b,
            uses_calibration,
            "{v:?}: digest follows the calibration"
        );
    }
}

/// The full_f32 row's samples, in order.
fn full_f32_samples(bench: &Bench) -> Vec<triad::model::Sample> {
    let mut samples = Vec::new();
    bench
        .each_output(Variant::FullF32, &mut NoMeter, |o| {
            if let Output::Sample(s) = o {
                samples.push(*s)
            }
        })
        .unwrap();
    samples
}

/// The pipeline row's frames carry exactly the full_f32 row's values (the
/// decimation is 1), with the clip flags, in sequence, with valid CRCs.
#[test]
fn pipeline_frames_decode_to_the_full_f32_samples() {
    let bench = Bench::realistic();
    let samples = full_f32_samples(&bench);
    let mut bytes = Vec::new();
    bench
        .each_output(Variant::Pipeline, &mut NoMeter, |o| {
            if let Output::Frame(f) = o {
                let end = f.0.iter().position(|&b| b == 0).unwrap();
                bytes.extend_from_slice(&f.0[..=end]);
            }
        })
        .unwrap();
    let mut decoder = Decoder::new();
    let frames: Vec<_> = decoder.feed(&bytes).map(|f| f.unwrap()).collect();
    assert_eq!(frames.len(), samples.len());
    assert_eq!(decoder.stats().crc_errors, 0);
    for (n, (f, s)) in frames.iter().zip(&samples).enumerate() {
        assert_eq!(f.sequence, n as u32);
        assert_eq!(
            (f.accel, f.gyro, f.temperature),
            (s.accel, s.gyro, s.temperature)
        );
        assert_eq!(
            f.flags.contains(Flags::ACCEL_CLIPPED),
            s.clip.accel,
            "frame {n}"
        );
        assert_eq!(
            f.flags.contains(Flags::GYRO_CLIPPED),
            s.clip.gyro,
            "frame {n}"
        );
    }
    assert!(samples.iter().any(|s| s.clip.accel) && samples.iter().any(|s| s.clip.gyro));
}

/// With the extreme valid calibration the fixed-point row neither overflows
/// nor exceeds its proven bound (src/model/fixed.rs) against the f64 reference.
#[test]
fn fixed_point_row_stays_within_its_bound_with_the_extreme_calibration() {
    let bench = Bench::new(&inputs::extreme());
    let corrector = bench.corrector().unwrap();
    let bound = FixedCorrector::new(&corrector).unwrap().error_bound();
    let raws = all_inputs();
    let mut n = 0;
    bench
        .each_output(Variant::FullFixed, &mut NoMeter, |o| {
            let Output::Fixed(s) = o else {
                panic!("fixed output")
            };
            let got = s.to_f64();
            let exact = corrector.reference(&raws[n]);
            // The bound is against the exact K·raw + k; the f64 reference
            // (Gaussian elimination) is itself off by a few f64 ulps of values
            // below 2000 SI units, far below the 1e-9 allowed for it here.
            for i in 0..3 {
                let (ea, eg) = (got.accel[i] - exact.accel[i], got.gyro[i] - exact.gyro[i]);
                assert!(
                    ea.abs() <= bound[0] + 1e-9,
                    "sample {n}: {ea:e} > {:e}",
                    bound[0]
                );
                assert!(
                    eg.abs() <= bound[1] + 1e-9,
                    "sample {n}: {eg:e} > {:e}",
                    bound[1]
                );
            }
            n += 1;
        })
        .unwrap();
    assert_eq!(n, raws.len());
}

/// The batch rows' counts are the full_f32 row's values rounded to the
/// frame's counts, and each sample carries its FIFO batch's clip flags: the
/// OR of the full_f32 samples' flags and of the range clips over the batch.
#[test]
fn batch_rows_are_the_full_f32_values_in_counts_with_their_fifo_batch_flags() {
    use triad::model::batch_kernel::to_counts;
    let bench = Bench::realistic();
    let samples = full_f32_samples(&bench);
    for v in [Variant::BatchF32W8, Variant::BatchF32W32] {
        let w = v.batch_watermark().unwrap();
        let mut rows = Vec::new();
        bench
            .each_output(v, &mut NoMeter, |o| {
                let Output::Counts(c) = o else {
                    panic!("counts output")
                };
                rows.push(*c)
            })
            .unwrap();
        assert_eq!(rows.len(), samples.len());
        for (batch_rows, batch_samples) in rows.chunks(BATCH).zip(samples.chunks(BATCH)) {
            for (fifo_rows, fifo_samples) in batch_rows.chunks(w).zip(batch_samples.chunks(w)) {
                let (mut accel, mut gyro) = (false, false);
                for (c, s) in fifo_rows.iter().zip(fifo_samples) {
                    for k in 0..3 {
                        let (a, a_clip) = to_counts(s.accel[k], c.lsb[0]);
                        let (g, g_clip) = to_counts(s.gyro[k], c.lsb[1]);
                        assert_eq!((c.counts[k], c.counts[3 + k]), (a, g), "{v:?}");
                        accel |= a_clip;
                        gyro |= g_clip;
                    }
                    accel |= s.clip.accel;
                    gyro |= s.clip.gyro;
                }
                for c in fifo_rows {
                    assert_eq!((c.clip.accel, c.clip.gyro), (accel, gyro), "{v:?}");
                }
            }
        }
    }
}
