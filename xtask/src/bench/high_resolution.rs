//! What the ICM-42688-P's high-resolution FIFO (DS-000347 §6.1: 20-bit
//! packets 4, 18 meaningful bits of accelerometer at ±16 g and 19 of
//! gyroscope at ±2000 °/s) gains over its 16-bit FIFO at the same ranges:
//! the noise floor at rest, in LSB and in SI units, of the chip model fed by
//! the simulator with the data sheet's noise densities, read through
//! triad's driver. What it costs (instructions per sample) is the whole
//! firmware's rows built with it ([`super::whole_firmware`]).

use std::fmt::Write;

use anyhow::{Context, Result};
use triad::model::{Calibration, Corrector, Orientation};
use triad::sensor::icm42688::config::{Config, FifoMode};
use triad::sensor::icm42688::{FifoConfig, Icm42688};
use triad::sensor::{FifoImu, Imu, RawSample};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::motion::Motion;
use triad_sim::scenes::scene::Scene;
use triad_sim::scenes::simulator::Simulator;

/// The chip's output data rate, Hz (the driver's default).
const RATE_HZ: f64 = 1000.0;
/// Samples at rest per path: 20 s.
const SAMPLES: usize = 20_000;
/// DS-000347 Table 2: accelerometer noise spectral density, 70 µg/√Hz.
const ACCEL_NOISE_G_PER_SQRT_HZ: f64 = 70e-6;
/// DS-000347 Table 1: gyroscope rate noise spectral density, 0.0028 °/s/√Hz.
const GYRO_NOISE_DPS_PER_SQRT_HZ: f64 = 0.0028;
/// The simulator's seed (one realisation of the noise for both paths).
const SEED: u64 = 11;

/// One FIFO format's figures at rest, each the mean over the three axes.
#[derive(Clone, Copy, Debug)]
pub struct NoiseFloor {
    /// The format's name in the report.
    pub name: &'static str,
    /// One LSB of the meaningful bits, m/s² and rad/s.
    pub lsb_si: [f64; 2],
    /// The standard deviation of the driver's values, m/s² and rad/s.
    pub sigma_si: [f64; 2],
    /// The RMS of the values less what the simulator handed the chip
    /// model: the format's quantisation, m/s² and rad/s.
    pub quantisation_si: [f64; 2],
    /// The standard deviation of what the simulator handed the chip model
    /// (the noise before any quantisation), m/s² and rad/s.
    pub source_sigma_si: [f64; 2],
}

/// The scene: the chip level and still, white noise at the data sheet's densities.
fn scene() -> Scene {
    let mut scene = Scene::new(RATE_HZ, Motion::Static { attitude: [0.0; 3] });
    scene.accel.white_noise = Some([ACCEL_NOISE_G_PER_SQRT_HZ * STANDARD_GRAVITY; 3]);
    scene.gyro.white_noise = Some([deg_to_rad(GYRO_NOISE_DPS_PER_SQRT_HZ); 3]);
    scene
}

/// The standard deviation of `v`.
fn sigma(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// One format's noise floor: `high_resolution` or the 16-bit packets,
/// both at ±16 g and ±2000 °/s (the driver's default ranges, the ones the
/// 20-bit format has).
pub fn measure(high_resolution: bool) -> Result<NoiseFloor> {
    let scene = scene();
    let simulator = Simulator::new(&scene, SEED).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let mut source = Simulator::new(&scene, SEED).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let mut imu = Icm42688::new_spi(Icm42688Model::new(simulator));
    let config = Config {
        fifo: Some(FifoConfig {
            watermark: 32,
            mode: FifoMode::StopOnFull,
            high_resolution,
        }),
        ..Config::default()
    };
    imu.init(&mut NoDelay, &config)
        .map_err(|e| anyhow::anyhow!("the chip model starts: {e:?}"))?;
    let scale = imu.scale();
    let corrector = Corrector::new(&Calibration::identity(0), &scale, Orientation::RotationNone)?;
    let mut raws = Vec::with_capacity(SAMPLES);
    let mut buffer = [RawSample::default(); 32];
    let period_ns = (1e9 / RATE_HZ) as u64;
    while raws.len() < SAMPLES {
        imu.bus_mut().advance(period_ns);
        let read = imu
            .read_fifo(&mut buffer)
            .map_err(|e| anyhow::anyhow!("reading the FIFO: {e:?}"))?;
        anyhow::ensure!(!read.overflowed, "the FIFO overflowed: {read:?}");
        raws.extend_from_slice(&buffer[..read.samples]);
    }
    raws.truncate(SAMPLES);
    // Per triad and axis: the values, and what the source handed the model.
    let mut values = vec![[[0.0f64; SAMPLES]; 3]; 2];
    let mut truths = vec![[[0.0f64; SAMPLES]; 3]; 2];
    for (n, raw) in raws.iter().enumerate() {
        let c = corrector.reference(raw);
        let t = source.step().measured;
        for axis in 0..3 {
            values[0][axis][n] = c.accel[axis];
            values[1][axis][n] = c.gyro[axis];
            truths[0][axis][n] = t.specific_force[axis];
            truths[1][axis][n] = t.angular_rate[axis];
        }
        anyhow::ensure!(!c.clip.accel && !c.clip.gyro, "sample {n} clipped");
    }
    let mean_over_axes = |f: &dyn Fn(usize, usize) -> f64, triad: usize| {
        (0..3).map(|axis| f(triad, axis)).sum::<f64>() / 3.0
    };
    let per_triad = |f: &dyn Fn(usize, usize) -> f64| [mean_over_axes(f, 0), mean_over_axes(f, 1)];
    let quantisation = |triad: usize, axis: usize| {
        let v = &values[triad][axis];
        let t = &truths[triad][axis];
        (v.iter().zip(t).map(|(v, t)| (v - t).powi(2)).sum::<f64>() / SAMPLES as f64).sqrt()
    };
    // The meaningful bits' LSB: the 20-bit value's has 2 (accelerometer)
    // and 1 (gyroscope) bits below them that always read 0.
    let lsb_si = match high_resolution {
        true => [scale.accel.si_per_lsb * 4.0, scale.gyro.si_per_lsb * 2.0],
        false => [scale.accel.si_per_lsb, scale.gyro.si_per_lsb],
    };
    Ok(NoiseFloor {
        name: match high_resolution {
            true => "20-bit FIFO (packet 4: 18-bit accel, 19-bit gyro)",
            false => "16-bit FIFO (packet 3)",
        },
        lsb_si,
        sigma_si: per_triad(&|triad, axis| sigma(&values[triad][axis])),
        quantisation_si: per_triad(&quantisation),
        source_sigma_si: per_triad(&|triad, axis| sigma(&truths[triad][axis])),
    })
}

/// Both formats' figures.
pub fn measure_both() -> Result<[NoiseFloor; 2]> {
    Ok([
        measure(false).context("the 16-bit FIFO's noise floor")?,
        measure(true).context("the 20-bit FIFO's noise floor")?,
    ])
}

/// The section of docs/BENCHMARKS.md.
pub fn markdown(floors: &[NoiseFloor; 2]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "## The ICM-42688-P's high-resolution FIFO\n\n\
         The chip model fed by the simulator at rest (level, still, {RATE_HZ:.0} Hz) with the data \
         sheet's white noise ({:.0} µg/√Hz, {:.4} °/s/√Hz: DS-000347 Tables 1 and 2), read through \
         triad's driver from its FIFO at ±16 g and ±2000 °/s in each format, {SAMPLES} samples of one \
         noise realisation (seed {SEED}) for both; the values are the counts times the scale the \
         driver reports, mean over the three axes. σ is the values' standard deviation (the noise \
         floor), in SI units and in LSB of the format's meaningful bits; the quantisation is the RMS of \
         the values less what the simulator handed the model (what the format adds to the noise); the \
         source σ is the noise before any quantisation. The cost in instructions per sample is the \
         whole firmware's rows marked 20-bit below (`cargo xtask bench --whole-firmware --rate R \
         --watermark W --high-resolution`). The 20-bit format streams a data frame per sample (a \
         batch frame's 16-bit counts would drop the extra bits), so its wire bytes per sample are a \
         data frame's.\n",
        ACCEL_NOISE_G_PER_SQRT_HZ * 1e6,
        GYRO_NOISE_DPS_PER_SQRT_HZ
    );
    let _ = writeln!(
        md,
        "| format | triad | LSB | σ (SI) | σ (LSB) | quantisation (SI) | quantisation / σ | source σ (SI) |\n\
         |---|---|---:|---:|---:|---:|---:|---:|"
    );
    for f in floors {
        for (t, (triad, unit)) in [("accelerometer", "m/s²"), ("gyroscope", "rad/s")]
            .into_iter()
            .enumerate()
        {
            let _ = writeln!(
                md,
                "| {} | {triad} | {:.3e} {unit} | {:.4e} | {:.2} | {:.3e} | {:.3} | {:.4e} |",
                f.name,
                f.lsb_si[t],
                f.sigma_si[t],
                f.sigma_si[t] / f.lsb_si[t],
                f.quantisation_si[t],
                f.quantisation_si[t] / f.sigma_si[t],
                f.source_sigma_si[t],
            );
        }
    }
    md
}

/// A delay that returns at once: the chip model's time moves only when the
/// benchmark advances it.
struct NoDelay;

impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _ns: u32) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The figures say what quantisation theory says: a uniform rounding
    /// error of LSB/√12 for each format (the noise spans several codes of
    /// either, so the error is uniform), the 20-bit format's four
    /// (accelerometer) and eight (gyroscope) times smaller; the noise floor
    /// itself is the source's within the quantisation added in quadrature.
    #[test]
    fn each_format_adds_its_own_lsb_over_root_12() {
        let floors = measure_both().unwrap();
        for f in &floors {
            for t in 0..2 {
                let expected = f.lsb_si[t] / 12f64.sqrt();
                let ratio = f.quantisation_si[t] / expected;
                assert!((0.95..1.05).contains(&ratio), "{} {t}: {ratio}", f.name);
                let quadrature = (f.source_sigma_si[t].powi(2) + expected.powi(2)).sqrt();
                let ratio = f.sigma_si[t] / quadrature;
                assert!((0.98..1.02).contains(&ratio), "{} {t}: {ratio}", f.name);
            }
        }
        let [sixteen, twenty] = floors;
        assert!((sixteen.lsb_si[0] / twenty.lsb_si[0] - 4.0).abs() < 1e-9);
        // 16.4 vs 131 LSB/(°/s): the data sheet's roundings, not exactly 8.
        assert!((sixteen.lsb_si[1] / twenty.lsb_si[1] - 131.0 / 16.4).abs() < 1e-9);
        println!("{}", markdown(&floors));
    }
}
