//! triad's drivers with the accelerometer and the gyroscope at different
//! output data rates, against the chip models: samples come at the faster
//! sensor's rate, each carrying the faster sensor's new value and the slower
//! sensor's latest one (held), on data ready and from the FIFO (the
//! ICM-42688-P's packets; the LSM6DSOX's tagged words, one sample per time
//! slot); settings that make no sense are refused before any write.

mod common;

use common::RampSource;
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::model::Triad;
use triad::sensor::icm42688::{Icm42688, Icm42688Chip, Odr as IcmOdr};
use triad::sensor::lsm6dsox::{Lsm6dsox, Lsm6dsoxChip, Odr as LsmOdr};
use triad::sensor::{Config, Error, FifoConfig, FifoImu, FifoMode, Imu, RawSample, Settings};
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;

/// Which of consecutive samples changed their accelerometer and their
/// gyroscope reading. The ramp source moves accel x by about 2 LSB and gyro
/// y by about 1.9 LSB per true sample at ±16 g and ±2000 °/s, so a new
/// reading always differs from the previous one.
fn changes(samples: &[RawSample]) -> (Vec<bool>, Vec<bool>) {
    samples
        .windows(2)
        .map(|w| (w[1].accel[0] != w[0].accel[0], w[1].gyro[1] != w[0].gyro[1]))
        .unzip()
}

/// Before the slower sensor's first sample (fewer than `ratio` samples)
/// its triad reads the chip's invalid marker, -32768 on every axis (which
/// the corrector flags as clipped); after it, the slower triad's changes
/// come every `ratio`-th sample, held between, and no marker appears.
fn assert_held_every(samples: &[RawSample], slower: Triad, ratio: usize) {
    let slow_triad = |s: &RawSample| match slower {
        Triad::Accel => s.accel,
        Triad::Gyro => s.gyro,
    };
    let before = samples
        .iter()
        .take_while(|s| slow_triad(s) == [i32::from(i16::MIN); 3])
        .count();
    assert!(
        before < ratio,
        "{before} samples before the slower sensor's first"
    );
    let samples = &samples[before..];
    assert!(
        samples
            .iter()
            .all(|s| !s.accel.contains(&i32::from(i16::MIN))
                && !s.gyro.contains(&i32::from(i16::MIN))),
        "no invalid marker after both sensors' first samples"
    );
    let (accel, gyro) = changes(samples);
    let (slow, fast) = match slower {
        Triad::Accel => (accel, gyro),
        Triad::Gyro => (gyro, accel),
    };
    assert!(
        fast.iter().all(|&c| c),
        "the faster sensor is new in every sample"
    );
    let new: Vec<usize> = (0..slow.len()).filter(|&i| slow[i]).collect();
    assert!(
        new.len() >= slow.len() / ratio - 1,
        "{} new of {}",
        new.len(),
        slow.len()
    );
    assert!(
        new.windows(2).all(|w| w[1] - w[0] == ratio),
        "the slower sensor is new every {ratio} samples, held between: {new:?}"
    );
}

fn icm_config(accel: IcmOdr, gyro: IcmOdr, fifo: Option<FifoConfig>) -> Config<Icm42688Chip> {
    Config {
        accel_odr: accel,
        gyro_odr: gyro,
        fifo,
        ..Config::default()
    }
}

#[test]
fn icm42688_on_data_ready_holds_the_slower_accelerometer() {
    let mut imu = Icm42688::new_spi(Icm42688Model::new(RampSource::default()));
    let config = icm_config(IcmOdr::Hz500, IcmOdr::Hz1000, None);
    imu.init(&mut NoopDelay::new(), &config).unwrap();
    assert_eq!(imu.config().sample_rate_hz(), 1000.0);
    let mut samples = Vec::new();
    for _ in 0..200 {
        let ns = imu.bus().ns_to_next_sample().expect("sampling");
        imu.bus_mut().advance(ns);
        samples.push(
            imu.read_new_sample()
                .expect("data ready at the gyro's rate"),
        );
    }
    assert_held_every(&samples, Triad::Accel, 2);
}

#[test]
fn icm42688_fifo_holds_the_slower_sensor_in_packets_without_its_data() {
    for (accel, gyro, slower, ratio) in [
        (IcmOdr::Hz500, IcmOdr::Hz1000, Triad::Accel, 2),
        (IcmOdr::Hz1000, IcmOdr::Hz200, Triad::Gyro, 5),
    ] {
        let fifo = FifoConfig {
            watermark: 8,
            mode: FifoMode::StopOnFull,
            high_resolution: false,
        };
        let mut imu = Icm42688::new_spi(Icm42688Model::new(RampSource::default()));
        imu.init(&mut NoopDelay::new(), &icm_config(accel, gyro, Some(fifo)))
            .unwrap();
        let mut samples = Vec::new();
        let mut out = [RawSample::default(); 32];
        for _ in 0..400 {
            imu.bus_mut().advance(1_000_000);
            if imu.bus().int1() {
                let read = imu.read_fifo(&mut out).unwrap();
                assert!(!read.overflowed);
                samples.extend_from_slice(&out[..read.samples]);
            }
        }
        // One packet per 1 ms instant (the faster sensor's), W = 8 per drain.
        assert_eq!(samples.len(), 400, "{accel:?}/{gyro:?}");
        assert_held_every(&samples, slower, ratio);
    }
}

#[test]
fn lsm6dsox_on_data_ready_interrupts_at_the_faster_accelerometer() {
    let mut imu = Lsm6dsox::new_spi(Lsm6dsoxModel::new(RampSource::default()));
    let config = Config::<Lsm6dsoxChip> {
        accel_odr: LsmOdr::Hz1666,
        gyro_odr: LsmOdr::Hz833,
        ..Config::default()
    };
    imu.init(&mut NoopDelay::new(), &config).unwrap();
    assert_eq!(imu.config().sample_rate_hz(), 1666.0);
    assert_eq!(imu.bus().peek(0x0D), 0x01, "INT1_CTRL: INT1_DRDY_XL");
    let mut samples = Vec::new();
    for _ in 0..200 {
        let ns = imu.bus().ns_to_next_sample().expect("sampling");
        imu.bus_mut().advance(ns);
        assert!(imu.bus().int1(), "INT1 at every accelerometer sample");
        samples.push(imu.read_sample().unwrap());
    }
    assert_held_every(&samples, Triad::Gyro, 2);
}

#[test]
fn lsm6dsox_fifo_at_two_rates_gives_one_sample_per_slot_the_slower_held() {
    // Each faster and slower sensor; an output of 32 (the firmware's) and
    // one of 5, which cuts the FIFO's slots between drains.
    for (accel, gyro, slower, ratio) in [
        (LsmOdr::Hz1666, LsmOdr::Hz833, Triad::Gyro, 2),
        // 52 and 208 Hz: a whole ratio in the model's nominal rates (833
        // and 208 are not: 4.005), as the chip's dividers give.
        (LsmOdr::Hz52, LsmOdr::Hz208, Triad::Accel, 4),
    ] {
        for room in [32usize, 5] {
            let what = format!("{accel:?}/{gyro:?}, output of {room}");
            let mut imu = Lsm6dsox::new_spi(Lsm6dsoxModel::new(RampSource::default()));
            let config = Config::<Lsm6dsoxChip> {
                accel_odr: accel,
                gyro_odr: gyro,
                fifo: Some(FifoConfig {
                    watermark: 8,
                    mode: FifoMode::StopOnFull,
                    high_resolution: false,
                }),
                ..Config::default()
            };
            imu.init(&mut NoopDelay::new(), &config).unwrap();
            // FIFO_CTRL1: 8 slots are 8 words of the faster sensor and
            // 8 / ratio of the slower.
            assert_eq!(imu.bus().peek(0x07), 8 + 8 / ratio as u8, "{what}");
            let mut samples = Vec::new();
            let mut out = vec![RawSample::default(); room];
            let mut slots = 0usize;
            for _ in 0..600 {
                let ns = imu.bus().ns_to_next_sample().expect("sampling");
                imu.bus_mut().advance(ns);
                slots += 1;
                if !imu.bus().int1() {
                    continue;
                }
                for drain in 0.. {
                    assert!(drain < 100, "{what}: the FIFO never drains");
                    let read = imu.read_fifo(&mut out).unwrap();
                    assert!(!read.overflowed, "{what}");
                    samples.extend_from_slice(&out[..read.samples]);
                    // What waits is what the chip made and was not delivered
                    // (the slower sensor's pattern known from its first word).
                    if samples.len() > ratio {
                        assert_eq!(
                            usize::from(read.remaining),
                            slots - samples.len(),
                            "{what}: after {} samples",
                            samples.len()
                        );
                    }
                    if read.remaining == 0 {
                        break;
                    }
                }
            }
            assert!(samples.len() > 550, "{what}: {}", samples.len());
            assert_held_every(&samples, slower, ratio);
        }
    }
}

#[test]
fn settings_name_the_slower_sensor_and_refuse_what_makes_no_sense() {
    let settings = |slower| Settings {
        rate_hz: Some(1000),
        slower,
        watermark: 1,
        high_resolution: false,
    };
    let config = settings(Some((Triad::Accel, 500)))
        .config::<Icm42688Chip, ()>()
        .unwrap();
    assert_eq!(
        (config.accel_odr, config.gyro_odr),
        (IcmOdr::Hz500, IcmOdr::Hz1000)
    );
    let config = settings(Some((Triad::Gyro, 200)))
        .config::<Icm42688Chip, ()>()
        .unwrap();
    assert_eq!(
        (config.accel_odr, config.gyro_odr),
        (IcmOdr::Hz1000, IcmOdr::Hz200)
    );
    for (slower, value) in [
        ((Triad::Gyro, 2000), 2000),
        ((Triad::Accel, 1000), 1000),
        ((Triad::Accel, 300), 300),
    ] {
        let error = settings(Some(slower))
            .config::<Icm42688Chip, ()>()
            .unwrap_err();
        assert!(
            matches!(error, Error::InvalidConfig { value: v, .. } if v == value),
            "{slower:?}: {error:?}"
        );
    }
}
