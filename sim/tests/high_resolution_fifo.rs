//! triad's ICM-42688-P driver on the high-resolution FIFO (DS-000347 §6.1
//! packet 4) against the chip model: each 20-bit value is the truth
//! quantised at the data sheet's 18-bit (accelerometer, 8192 LSB/g at
//! ±16 g) and 19-bit (gyroscope, 131 LSB/(°/s) at ±2000 °/s) sensitivity,
//! computed here independently of the model; the corrector then gives the
//! truth within that quantisation, four and eight times finer than the
//! 16-bit FIFO's at the same ranges; the driver refuses what the format
//! cannot do.

mod common;

use common::RandomSource;
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::model::{Calibration, Corrector, Orientation};
use triad::sensor::icm42688::config::{high_resolution_scale, Config, FifoMode};
use triad::sensor::icm42688::{AccelRange, FifoConfig, GyroRange, Icm42688, Icm42688Chip, Odr};
use triad::sensor::lsm6dsox::Lsm6dsox;
use triad::sensor::{Error, FifoImu, Imu, RawSample, Settings};
use triad::units::{deg_to_rad, rad_to_deg, STANDARD_GRAVITY};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::source::{SampleSource, TrueSample};

/// 1 kHz: the model's sample period, ns.
const PERIOD_NS: u64 = 1_000_000;

fn fifo_config(high_resolution: bool, watermark: u16) -> Config {
    Config {
        fifo: Some(FifoConfig {
            watermark,
            mode: FifoMode::StopOnFull,
            high_resolution,
        }),
        ..Config::default()
    }
}

/// The 20-bit value the chip reports for `value`: rounded to the nearest
/// code of `bits` meaningful bits at `per_unit` codes per unit, saturated
/// one code inside the most negative (the "no data" marker), shifted to
/// the top of the 20-bit field.
fn expected_20_bit(value: f64, per_unit: f64, bits: u32) -> i32 {
    let limit = f64::from((1 << (bits - 1)) - 1);
    let code = (value * per_unit).round().clamp(-limit, limit) as i32;
    code << (20 - bits)
}

fn expected_hires(t: &TrueSample) -> ([i32; 3], [i32; 3]) {
    (
        t.specific_force
            .map(|a| expected_20_bit(a / STANDARD_GRAVITY, 8192.0, 18)),
        t.angular_rate
            .map(|w| expected_20_bit(rad_to_deg(w), 131.0, 19)),
    )
}

/// Drains `n` samples of `source` through the FIFO of a driver started with `config`.
fn drain<S: SampleSource>(source: S, config: &Config, n: usize) -> (Vec<RawSample>, Corrector) {
    let mut imu = Icm42688::new_spi(Icm42688Model::new(source));
    imu.init(&mut NoopDelay::new(), config).unwrap();
    let corrector = Corrector::new(
        &Calibration::identity(0),
        &imu.scale(),
        Orientation::RotationNone,
    )
    .unwrap();
    let mut samples = Vec::new();
    let mut out = [RawSample::default(); 32];
    while samples.len() < n {
        imu.bus_mut().advance(PERIOD_NS);
        if !imu.bus().int1() {
            continue;
        }
        let read = imu.read_fifo(&mut out).unwrap();
        assert!(!read.overflowed, "{read:?}");
        samples.extend_from_slice(&out[..read.samples]);
    }
    assert!(
        imu.bus().unmodelled().is_empty(),
        "{:?}",
        imu.bus().unmodelled().accesses().collect::<Vec<_>>()
    );
    (samples, corrector)
}

/// Largest |corrected − truth| over the samples, in m/s² and rad/s.
fn worst_errors(samples: &[RawSample], corrector: &Corrector, seed: u64) -> (f64, f64) {
    let mut truth = RandomSource::new(seed, 15.0 * STANDARD_GRAVITY, deg_to_rad(1900.0));
    let (mut accel, mut gyro) = (0.0f64, 0.0f64);
    for s in samples {
        let t = truth.next_sample();
        let c = corrector.correct(s);
        assert!(!c.clip.accel && !c.clip.gyro, "{s:?}");
        for axis in 0..3 {
            accel = accel.max((f64::from(c.accel[axis]) - t.specific_force[axis]).abs());
            gyro = gyro.max((f64::from(c.gyro[axis]) - t.angular_rate[axis]).abs());
        }
    }
    (accel, gyro)
}

#[test]
fn every_20_bit_value_is_the_truth_at_the_data_sheets_18_and_19_bits() {
    let source = RandomSource::new(3, 15.0 * STANDARD_GRAVITY, deg_to_rad(1900.0));
    let (samples, _) = drain(source, &fifo_config(true, 32), 2000);
    let mut truth = source;
    for (k, s) in samples.iter().enumerate() {
        let t = truth.next_sample();
        let (accel, gyro) = expected_hires(&t);
        assert_eq!((s.accel, s.gyro), (accel, gyro), "sample {k}");
        // §6.1 packet 4: the temperature is the register's 16-bit value.
        let temperature = ((t.temperature - 25.0) * 132.48).round() as i16;
        assert_eq!(s.temperature, temperature, "sample {k}");
        // The low bits the data sheet says read 0.
        assert!(s.accel.iter().all(|a| a & 0b11 == 0) && s.gyro.iter().all(|g| g & 1 == 0));
    }
}

#[test]
fn the_corrector_gives_the_truth_within_the_finer_quantisation() {
    let seed = 5;
    let source = || RandomSource::new(seed, 15.0 * STANDARD_GRAVITY, deg_to_rad(1900.0));
    let (hires, hires_corrector) = drain(source(), &fifo_config(true, 32), 4000);
    let (sixteen, sixteen_corrector) = drain(source(), &fifo_config(false, 32), 4000);
    let (accel, gyro) = worst_errors(&hires, &hires_corrector, seed);
    let (accel_16, gyro_16) = worst_errors(&sixteen, &sixteen_corrector, seed);
    // Half a code of the meaningful bits, plus the f32 kernel's rounding
    // of values up to 16 g and 35 rad/s (relative 2⁻²², tests/model_f32.rs).
    let f32_margin = |full_scale: f64| full_scale * 2f64.powi(-22);
    let accel_bound = 0.5 * STANDARD_GRAVITY / 8192.0 + f32_margin(16.0 * STANDARD_GRAVITY);
    let gyro_bound = 0.5 * deg_to_rad(1.0 / 131.0) + f32_margin(deg_to_rad(2000.0));
    assert!(accel <= accel_bound, "accel {accel:e} > {accel_bound:e}");
    assert!(gyro <= gyro_bound, "gyro {gyro:e} > {gyro_bound:e}");
    // The 16-bit FIFO at the same ranges quantises 4× (accelerometer) and
    // 8× (gyroscope) coarser: over 4000 samples its worst error is well
    // beyond the high-resolution bound (it nears half its own code).
    assert!(accel_16 > 3.0 * accel_bound, "16-bit accel {accel_16:e}");
    assert!(gyro_16 > 6.0 * gyro_bound, "16-bit gyro {gyro_16:e}");
    // The fixed-point corrector takes the 20-bit inputs too (its i64
    // form, src/model/fixed.rs), within its proven bound of the f64 reference.
    let fixed = hires_corrector.to_fixed().unwrap();
    assert_eq!(fixed.uses_32_bit_products(), [false, false, true]);
    let bound = fixed.error_bound();
    for s in &hires {
        let got = fixed.correct(s).to_f64();
        let exact = hires_corrector.reference(s);
        for axis in 0..3 {
            assert!((got.accel[axis] - exact.accel[axis]).abs() <= bound[0] + 1e-9);
            assert!((got.gyro[axis] - exact.gyro[axis]).abs() <= bound[1] + 1e-9);
        }
    }
    assert!(bound[0] <= 0.5 * high_resolution_scale().accel.si_per_lsb);
    assert!(bound[1] <= 0.5 * high_resolution_scale().gyro.si_per_lsb);
}

#[test]
fn beyond_the_fixed_range_an_axis_saturates_and_its_triad_is_flagged() {
    let t = TrueSample {
        specific_force: [20.0 * STANDARD_GRAVITY, -20.0 * STANDARD_GRAVITY, 1.0],
        angular_rate: [deg_to_rad(2500.0), 0.0, deg_to_rad(-2500.0)],
        temperature: 25.0,
    };
    let (samples, corrector) = drain(common::ConstantSource(t), &fifo_config(true, 4), 4);
    let s = samples[0];
    assert_eq!(s.accel[..2], [524_284, -524_284]);
    assert_eq!([s.gyro[0], s.gyro[2]], [524_286, -524_286]);
    let c = corrector.correct(&s);
    assert!(c.clip.accel && c.clip.gyro);
    // One code inside is a measurement.
    let inside = RawSample {
        accel: [524_280, -524_280, 0],
        gyro: [524_284, -524_284, 0],
        temperature: 0,
    };
    let c = corrector.correct(&inside);
    assert!(!c.clip.accel && !c.clip.gyro);
}

#[test]
fn a_slower_accelerometer_holds_its_value_between_its_own_samples() {
    let config = Config {
        accel_odr: Odr::Hz500,
        ..fifo_config(true, 16)
    };
    let source = RandomSource::new(9, 10.0, 5.0);
    let (samples, corrector) = drain(source, &config, 64);
    // The accelerometer's first sample comes with the gyro's first or
    // second; after it no marker is left and each value lasts two samples.
    let first = samples.iter().position(|s| s.accel[0] != -524_288).unwrap();
    assert!(first <= 1, "{first}");
    for pair in samples[first..].chunks_exact(2) {
        assert_eq!(pair[0].accel, pair[1].accel);
        assert_ne!(pair[0].gyro, pair[1].gyro);
    }
    assert!(samples[first..]
        .iter()
        .all(|s| !corrector.correct(s).clip.accel));
}

#[test]
fn the_format_is_refused_where_it_cannot_hold() {
    let refused = |config: &Config| {
        let mut imu = Icm42688::new_spi(Icm42688Model::new(common::RampSource::default()));
        match imu.init(&mut NoopDelay::new(), config) {
            Err(Error::InvalidConfig { what, value }) => (what, value),
            other => panic!("{config:?}: {other:?}"),
        }
    };
    let (what, value) = refused(&Config {
        accel_range: AccelRange::G4,
        ..fifo_config(true, 8)
    });
    assert!(what.contains("±16 g") && what.contains("§6.1"), "{what}");
    assert_eq!(value, 2);
    let (what, _) = refused(&Config {
        gyro_range: GyroRange::Dps250,
        ..fifo_config(true, 8)
    });
    assert!(what.contains("±2000 °/s"), "{what}");
    // 20-byte packets: 102 fit the 2 KiB FIFO.
    let (what, value) = refused(&fifo_config(true, 103));
    assert!(what.contains("1..=102"), "{what}");
    assert_eq!(value, 103);

    let mut lsm = Lsm6dsox::new_spi(Lsm6dsoxModel::new(common::RampSource::default()));
    let lsm_config = triad::sensor::lsm6dsox::Config {
        fifo: Some(FifoConfig {
            watermark: 8,
            mode: FifoMode::StopOnFull,
            high_resolution: true,
        }),
        ..Default::default()
    };
    assert!(matches!(
        lsm.init(&mut NoopDelay::new(), &lsm_config),
        Err(Error::InvalidConfig { what, .. }) if what.contains("high-resolution")
    ));

    let settings = Settings {
        high_resolution: true,
        ..Settings::DEFAULT
    };
    assert!(matches!(
        settings.config::<Icm42688Chip, ()>(),
        Err(Error::InvalidConfig { value: 1, .. })
    ));
    let settings = Settings {
        watermark: 16,
        ..settings
    };
    let config = settings.config::<Icm42688Chip, ()>().unwrap();
    assert!(config.fifo.unwrap().high_resolution);
    assert_eq!(config.scale(), high_resolution_scale());
}

#[test]
fn register_reads_come_on_the_20_bit_scale_too() {
    // With the format configured, a data-register read (16 bits at ±16 g
    // and ±2000 °/s) is brought to the FIFO's scale: × 16.
    let t = TrueSample {
        specific_force: [1.0, -2.0, 9.80665],
        angular_rate: [0.1, -0.2, 0.3],
        temperature: 30.0,
    };
    let mut imu = Icm42688::new_spi(Icm42688Model::new(common::ConstantSource(t)));
    imu.init(&mut NoopDelay::new(), &fifo_config(true, 8))
        .unwrap();
    imu.bus_mut().advance(PERIOD_NS);
    let s = imu.read_sample().unwrap();
    let sixteen = |v: f64, per_unit: f64| ((v * per_unit).round() as i32) << 4;
    assert_eq!(
        s.accel,
        t.specific_force
            .map(|a| sixteen(a / STANDARD_GRAVITY, 2048.0))
    );
    assert_eq!(s.gyro, t.angular_rate.map(|w| sixteen(rad_to_deg(w), 16.4)));
}
