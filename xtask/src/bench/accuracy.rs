//! The accuracy of each variant against the f64 reference (Gaussian
//! elimination on (I+Σ), `Corrector::reference`), on the benchmark's inputs:
//! every axis uniform over the whole i16 range plus limit codes, for the
//! realistic and the extreme valid calibration.

use anyhow::Result;
use triad::model::batch_kernel::MAX_COUNTS;
use triad::sensor::RawSample;
use triad_bench::inputs;
use triad_bench::kernels::{NoMeter, Output};
use triad_bench::{Bench, Variant, BATCH, BATCHES};

/// Error statistics of one variant against the reference, over all six axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// Largest |error| in sensor LSB.
    pub max_lsb: f64,
    /// Root mean square error in sensor LSB.
    pub rms_lsb: f64,
    /// Largest |error| in parts per million of the full scale.
    pub max_ppm_full_scale: f64,
}

/// A variant with its accuracy for the realistic and the extreme calibration.
pub type VariantAccuracy = (Variant, Option<Accuracy>, Option<Accuracy>);

/// Per variant: accuracy with the realistic and with the extreme calibration
/// (a batch row's clipped counts, at ±MAX_COUNTS and flagged, are left out)
/// (`None` where the row does not depend on the calibration or has no
/// sample output to compare: the refold rows use their own calibration with
/// temperature terms, the pipeline row streams frames of the full_f32
/// values, the sensor-read rows correct nothing; the g-sensitivity rows
/// have the realistic calibration with a G only).
pub fn all() -> Result<Vec<VariantAccuracy>> {
    let realistic = Bench::new(&inputs::realistic());
    let extreme = Bench::new(&inputs::extreme());
    Variant::ALL
        .into_iter()
        .map(|v| {
            Ok(match v {
                Variant::Pipeline
                | Variant::ReadBurst
                | Variant::ReadFifo1
                | Variant::ReadFifo8
                | Variant::ReadFifo32 => (v, None, None),
                Variant::RefoldEverySample | Variant::RefoldLowRate => {
                    (v, Some(of(&realistic, v)?), None)
                }
                // The realistic calibration with a g-sensitivity, against
                // its own reference.
                Variant::FullF32G | Variant::FullFixedG | Variant::BatchF32W32G => {
                    let with_g = Bench::new(&inputs::with_g_sensitivity());
                    (v, Some(of(&with_g, v)?), None)
                }
                _ => (v, Some(of(&realistic, v)?), Some(of(&extreme, v)?)),
            })
        })
        .collect()
}

/// Every raw input of a run, in the order the kernels see them.
fn all_inputs() -> Vec<RawSample> {
    let mut batch = [RawSample::default(); BATCH];
    (0..BATCHES)
        .flat_map(|i| {
            inputs::raw_batch(i, &mut batch);
            batch
        })
        .collect()
}

fn of(bench: &Bench, variant: Variant) -> Result<Accuracy> {
    let refolds = matches!(variant, Variant::RefoldEverySample | Variant::RefoldLowRate);
    let corrector = if refolds {
        Bench::temperature_corrector()?
    } else {
        bench.corrector()?
    };
    let scale = *corrector.scale();
    let lsb = [scale.accel.si_per_lsb, scale.gyro.si_per_lsb];
    let full_scale = [scale.accel.full_scale, scale.gyro.full_scale];
    let raws = all_inputs();
    let mut outputs = Vec::with_capacity(raws.len());
    bench.each_output(variant, &mut NoMeter, |o| outputs.push(values(&o)))?;

    let (mut max_lsb, mut sum_sq, mut max_ppm, mut n) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for (raw, out) in raws.iter().zip(&outputs) {
        // The refold rows are judged against the model at each sample's own
        // temperature: the low-rate row's staleness is part of its error.
        let reference = if refolds {
            let mut at_t = corrector.clone();
            at_t.refold(scale.temperature_c(raw.temperature))?;
            at_t.reference(raw)
        } else {
            corrector.reference(raw)
        };
        let exact = [reference.accel, reference.gyro];
        for t in 0..2 {
            for i in 0..3 {
                let error = (out[t][i] - exact[t][i]).abs();
                if error.is_nan() {
                    continue;
                }
                max_lsb = max_lsb.max(error / lsb[t]);
                sum_sq += (error / lsb[t]).powi(2);
                max_ppm = max_ppm.max(error / full_scale[t] * 1e6);
                n += 1;
            }
        }
    }
    Ok(Accuracy {
        max_lsb,
        rms_lsb: (sum_sq / n as f64).sqrt(),
        max_ppm_full_scale: max_ppm,
    })
}

/// A variant's output as accelerometer and gyroscope values in f64 SI units.
fn values(o: &Output<'_>) -> [[f64; 3]; 2] {
    let f = |v: &[f32; 3]| v.map(f64::from);
    match o {
        Output::Triads(t) => [f(&t[0]), f(&t[1])],
        Output::Sample(s) => [f(&s.accel), f(&s.gyro)],
        Output::Fixed(s) => {
            let r = s.to_f64();
            [r.accel, r.gyro]
        }
        Output::F64(s) => s.triads,
        // A count at ±MAX_COUNTS is a clipped value (flagged): not compared.
        Output::Counts(s) => {
            let si = |t: usize| {
                [0, 1, 2].map(|k| match s.counts[3 * t + k] {
                    c if c.abs() == MAX_COUNTS => f64::NAN,
                    c => f64::from(c) * f64::from(s.lsb[t]),
                })
            };
            [si(0), si(1)]
        }
        Output::Frame(_) | Output::Raw(_) => [[f64::NAN; 3]; 2],
    }
}
