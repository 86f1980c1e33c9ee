//! The LSM6DSOX driver against the register-level chip model, on SPI and
//! I²C: configuration changes behaviour, values are the source's quantised at
//! the configured sensitivity, the tagged FIFO keeps order, overruns are
//! reported, and every injected fault shows as its own error or flag.

mod common;

use common::{ConstantSource, RampSource, RandomSource};
use embedded_hal::i2c::{ErrorKind as I2cErrorKind, NoAcknowledgeSource};
use embedded_hal::spi::{ErrorKind as SpiErrorKind, Operation, SpiDevice};
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::sensor::interface::{I2cInterface, SpiInterface};
use triad::sensor::lsm6dsox::{
    AccelRange, Config, FifoConfig, FifoMode, GyroRange, Lsm6dsox, Lsm6dsoxChip, Odr,
};
use triad::sensor::{Error, FifoImu, FullScale, Imu, ImuScale, RawSample};
use triad_sim::chips::fault::Fault;
use triad_sim::chips::lsm6dsox_model::Lsm6dsoxModel;
use triad_sim::chips::source::{SampleSource, TrueSample};

type SpiImu<S> = Lsm6dsox<SpiInterface<Lsm6dsoxModel<S>>>;
type I2cImu<S> = Lsm6dsox<I2cInterface<Lsm6dsoxModel<S>>>;

fn spi_imu<S: SampleSource>(source: S, config: &Config) -> SpiImu<S> {
    let mut imu = Lsm6dsox::new_spi(Lsm6dsoxModel::new(source));
    imu.init(&mut NoopDelay::new(), config).unwrap();
    imu
}

fn i2c_imu<S: SampleSource>(source: S, config: &Config) -> I2cImu<S> {
    let mut imu = Lsm6dsox::new_i2c(Lsm6dsoxModel::new(source).with_sa0(true), 0x6B);
    imu.init(&mut NoopDelay::new(), config).unwrap();
    imu
}

/// Codes rounded to nearest and saturated to the 16-bit range, computed
/// independently of the model (which multiplies by LSB/SI; the two differ by
/// a few ulp, which moves a code only within ~1e-12 LSB of a half-code
/// boundary: never met by these sources).
fn code(value: f64, si_per_lsb: f64) -> i16 {
    (value / si_per_lsb).round().clamp(-32768.0, 32767.0) as i16
}

fn expected(scale: &ImuScale, t: &TrueSample) -> RawSample {
    let mut s = RawSample::default();
    for axis in 0..3 {
        s.accel[axis] = i32::from(code(t.specific_force[axis], scale.accel.si_per_lsb));
        s.gyro[axis] = i32::from(code(t.angular_rate[axis], scale.gyro.si_per_lsb));
    }
    s.temperature = code(t.temperature - 25.0, 1.0 / 256.0);
    s
}

/// The time (ns since the sensors started) at which sample `k` (1-based)
/// appears at `odr`: ⌈k · 10¹² / rate[mHz]⌉.
fn sample_time_ns(k: u64, odr: Odr) -> u64 {
    (k * 1_000_000_000_000).div_ceil(u64::from(odr.millihertz()))
}

#[test]
fn every_range_and_rate_round_trips_and_sets_sensitivity_and_timing() {
    for (i, odr) in Odr::ALL.into_iter().enumerate() {
        let accel_range = AccelRange::ALL[i % 4];
        let gyro_range = GyroRange::ALL[i % 5];
        let cfg = Config {
            accel_range,
            gyro_range,
            accel_odr: odr,
            gyro_odr: odr,
            ..Config::default()
        };
        // Inputs within ±1.2 full scale: some axes saturate, most do not.
        let fs = (
            accel_range.scale::<Lsm6dsoxChip>().full_scale,
            gyro_range.scale().full_scale,
        );
        let source = RandomSource::new(i as u64 + 1, 1.2 * fs.0, 1.2 * fs.1);
        let mut twin = source;
        let mut imu = spi_imu(source, &cfg);
        assert_eq!(
            imu.read_ranges().unwrap(),
            (accel_range, gyro_range, odr, odr)
        );
        let scale = imu.scale();
        assert_eq!(
            (scale.accel, scale.gyro),
            (accel_range.scale::<Lsm6dsoxChip>(), gyro_range.scale())
        );
        let mut now = 0;
        for k in 1..=50 {
            let due = sample_time_ns(k, odr);
            imu.bus_mut().advance(due - 1 - now);
            assert!(
                matches!(imu.read_new_sample(), Err(Error::NoNewData { .. })),
                "{odr:?} sample {k} early"
            );
            imu.bus_mut().advance(1);
            now = due;
            let read = imu.read_new_sample().unwrap();
            assert_eq!(read, expected(&scale, &twin.next_sample()), "{cfg:?}");
        }
        assert_eq!(imu.bus().samples_produced(), 50);
    }
}

#[test]
fn i2c_reads_the_same_values_as_spi() {
    let cfg = Config {
        accel_range: AccelRange::G2,
        gyro_range: GyroRange::Dps250,
        accel_odr: Odr::Hz833,
        gyro_odr: Odr::Hz833,
        ..Config::default()
    };
    let mut spi = spi_imu(RandomSource::new(3, 25.0, 5.0), &cfg);
    let mut i2c = i2c_imu(RandomSource::new(3, 25.0, 5.0), &cfg);
    let mut twin = RandomSource::new(3, 25.0, 5.0);
    let mut now = 0;
    for k in 1..=100 {
        let due = sample_time_ns(k, Odr::Hz833);
        spi.bus_mut().advance(due - now);
        i2c.bus_mut().advance(due - now);
        now = due;
        let want = expected(&spi.scale(), &twin.next_sample());
        assert_eq!(spi.read_sample().unwrap(), want);
        assert_eq!(i2c.read_sample().unwrap(), want);
    }
}

#[test]
fn beyond_full_scale_reads_the_limit_codes_and_sets_the_clip_flag() {
    let over = TrueSample {
        specific_force: [200.0, -200.0, 1.0],
        // 2578 °/s: beyond the ±2000 °/s range and beyond what its codes
        // reach (32767 × 70 mdps = 2294 °/s).
        angular_rate: [45.0, -45.0, 0.1],
        temperature: 25.0,
    };
    let mut imu = spi_imu(ConstantSource(over), &Config::default()); // ±16 g, ±2000 °/s
    imu.bus_mut().advance(2_000_000);
    let s = imu.read_sample().unwrap();
    assert_eq!(s.accel[..2], [32767, -32768]);
    assert_eq!(s.gyro[..2], [32767, -32768]);
    assert!(imu.bus().clipped());

    let inside = TrueSample {
        specific_force: [150.0, -150.0, 1.0], // 15.3 g
        angular_rate: [34.0, -34.0, 0.1],     // 1948 °/s
        temperature: 25.0,
    };
    let mut imu = spi_imu(ConstantSource(inside), &Config::default());
    imu.bus_mut().advance(2_000_000);
    let s = imu.read_sample().unwrap();
    assert!(s
        .accel
        .iter()
        .chain(s.gyro.iter())
        .all(|v| *v > -32768 && *v < 32767));
    assert!(!imu.bus().clipped());
}

#[test]
fn temperature_reads_back_within_half_an_lsb() {
    for celsius in [-40.0, 0.0, 25.0, 36.6, 85.0] {
        let t = TrueSample {
            temperature: celsius,
            ..TrueSample::default()
        };
        let mut imu = spi_imu(ConstantSource(t), &Config::default());
        imu.bus_mut().advance(2_000_000);
        let raw = imu.read_sample().unwrap().temperature;
        // Round-to-nearest error: at most half of 1/256 °C.
        assert!((imu.scale().temperature_c(raw) - celsius).abs() <= 0.5 / 256.0 + 1e-12);
    }
}

#[test]
fn model_register_map_has_the_datasheet_reset_values_and_sw_reset_restores_them() {
    let mut model = Lsm6dsoxModel::new(RampSource::default());
    // (address, reset value), DS12814 §8.
    let resets = [
        (0x02, 0x3F), // PIN_CTRL
        (0x07, 0x00), // FIFO_CTRL1
        (0x0A, 0x00), // FIFO_CTRL4
        (0x0D, 0x00), // INT1_CTRL
        (0x0F, 0x6C), // WHO_AM_I
        (0x10, 0x00), // CTRL1_XL
        (0x11, 0x00), // CTRL2_G
        (0x12, 0x04), // CTRL3_C
        (0x18, 0xE0), // CTRL9_XL
    ];
    let read = |model: &mut Lsm6dsoxModel<RampSource>, address: u8| {
        let mut b = [0u8];
        model
            .transaction(&mut [Operation::Write(&[address | 0x80]), Operation::Read(&mut b)])
            .unwrap();
        b[0]
    };
    for (address, value) in resets {
        assert_eq!(read(&mut model, address), value, "register {address:#04x}");
    }
    let mut imu = Lsm6dsox::new_spi(model);
    imu.init(&mut NoopDelay::new(), &Config::default()).unwrap();
    assert_eq!(imu.bus().peek(0x10), 0x74);
    imu.bus_mut()
        .transaction(&mut [Operation::Write(&[0x12, 0x01])])
        .unwrap();
    let mut model = imu.release();
    for (address, value) in resets {
        assert_eq!(
            read(&mut model, address),
            value,
            "after SW_RESET {address:#04x}"
        );
    }
}

#[test]
fn without_if_inc_a_burst_rereads_one_register() {
    let mut imu = spi_imu(ConstantSource(RampSource::sample(3)), &Config::default());
    imu.bus_mut().advance(2_000_000);
    let good = imu.read_sample().unwrap();
    imu.bus_mut()
        .transaction(&mut [Operation::Write(&[0x12, 0x40])]) // BDU, IF_INC off
        .unwrap();
    let bad = imu.read_sample().unwrap();
    // Every byte is OUT_TEMP_L: the words are [L, L] repeated.
    let l = good.temperature.to_le_bytes()[0];
    assert_eq!(bad.accel, [i32::from(i16::from_le_bytes([l, l])); 3]);
}

fn fifo_cfg(watermark: u16, mode: FifoMode, odr: Odr) -> Config {
    Config {
        accel_odr: odr,
        gyro_odr: odr,
        fifo: Some(FifoConfig {
            watermark,
            mode,
            high_resolution: false,
        }),
        ..Config::default()
    }
}

/// A sample out of the FIFO: accel and gyro of sample `k`, temperature of
/// the latest sample (`latest`) read from OUT_TEMP during the drain.
fn expected_fifo(scale: &ImuScale, k: u64, latest: u64) -> RawSample {
    let mut s = expected(scale, &RampSource::sample(k));
    s.temperature = expected(scale, &RampSource::sample(latest)).temperature;
    s
}

#[test]
fn fifo_drains_in_order_without_loss_below_the_watermark() {
    for watermark in [1u16, 8, 32] {
        let mut imu = spi_imu(
            RampSource::default(),
            &fifo_cfg(watermark, FifoMode::StopOnFull, Odr::Hz833),
        );
        let scale = imu.scale();
        let mut out = [RawSample::default(); 32];
        let mut k = 0u64;
        let mut now = 0;
        for tick in 1..=1000 {
            let due = sample_time_ns(tick, Odr::Hz833);
            imu.bus_mut().advance(due - now);
            now = due;
            if !imu.bus().int1() {
                continue;
            }
            let read = imu.read_fifo(&mut out).unwrap();
            assert!(!read.overflowed && read.lost == 0);
            assert_eq!(read.samples, usize::from(watermark), "tick {tick}");
            for s in &out[..read.samples] {
                assert_eq!(*s, expected_fifo(&scale, k, tick - 1), "sample {k}");
                k += 1;
            }
        }
        assert_eq!(k, 1000 - 1000 % u64::from(watermark));
    }
}

#[test]
fn fifo_overrun_is_reported_with_a_lower_bound_and_recovers() {
    for mode in [FifoMode::StopOnFull, FifoMode::Stream] {
        let mut imu = spi_imu(RampSource::default(), &fifo_cfg(16, mode, Odr::Hz12_5));
        let scale = imu.scale();
        // 300 samples into a 256-sample (512-word) FIFO at 12.5 Hz (80 ms).
        imu.bus_mut().advance(300 * 80_000_000);
        let mut out = [RawSample::default(); 32];
        let read = imu.read_fifo(&mut out).unwrap();
        assert!(read.overflowed && read.lost_is_lower_bound, "{mode:?}");
        // The 256 samples the reset discarded; the 44 the full FIFO dropped are not counted.
        assert_eq!(read.lost, 256);
        assert!(u64::from(read.lost) <= 300);
        imu.bus_mut().advance(16 * 80_000_000);
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!((read.samples, read.lost, read.overflowed), (16, 0, false));
        for (i, s) in out[..16].iter().enumerate() {
            assert_eq!(*s, expected_fifo(&scale, 300 + i as u64, 315));
        }
    }
}

#[test]
fn injected_fifo_overflow_is_reported() {
    let mut imu = i2c_imu(
        RampSource::default(),
        &fifo_cfg(8, FifoMode::StopOnFull, Odr::Hz104),
    );
    imu.bus_mut().inject(Fault::FifoOverflow { lost: 10 });
    let read = imu.read_fifo(&mut [RawSample::default(); 8]).unwrap();
    assert!(read.overflowed);
    assert_eq!(read.lost, 256);
    imu.bus_mut().advance(8 * sample_time_ns(1, Odr::Hz104) + 1);
    assert_eq!(
        imu.read_fifo(&mut [RawSample::default(); 8])
            .unwrap()
            .samples,
        8
    );
}

#[test]
fn bus_errors_are_reported_and_the_driver_resumes() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().advance(2_000_000);
    imu.bus_mut().inject(Fault::BusError { transactions: 2 });
    assert_eq!(imu.read_sample(), Err(Error::Bus(SpiErrorKind::Other)));
    assert_eq!(imu.read_sample(), Err(Error::Bus(SpiErrorKind::Other)));
    assert_eq!(
        imu.read_sample().unwrap(),
        expected(&imu.scale(), &RampSource::sample(0))
    );

    let mut imu = i2c_imu(RampSource::default(), &Config::default());
    imu.bus_mut().inject(Fault::BusError { transactions: 1 });
    let nack = I2cErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
    assert_eq!(imu.read_sample(), Err(Error::Bus(nack)));
    imu.bus_mut().advance(2_000_000);
    assert!(imu.read_new_sample().is_ok());
}

#[test]
fn wrong_address_is_a_nack() {
    let mut imu = Lsm6dsox::new_i2c(Lsm6dsoxModel::new(RampSource::default()), 0x6B);
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::Bus(I2cErrorKind::NoAcknowledge(
            NoAcknowledgeSource::Address
        )))
    );
}

#[test]
fn wrong_identity_is_reported_with_the_value_read() {
    let mut model = Lsm6dsoxModel::new(RampSource::default());
    model.inject(Fault::WrongWhoAmI(0x47));
    let mut imu = Lsm6dsox::new_spi(model);
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::WrongChip {
            expected: 0x6C,
            found: 0x47
        })
    );
    imu.bus_mut().clear_faults();
    imu.init(&mut NoopDelay::new(), &Config::default()).unwrap();
}

#[test]
fn stuck_output_shows_as_no_new_data_and_clears() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    let period = sample_time_ns(1, Odr::Hz833);
    imu.bus_mut().advance(period);
    assert!(imu.read_new_sample().is_ok());
    imu.bus_mut().inject(Fault::StuckOutput);
    for _ in 0..5 {
        imu.bus_mut().advance(period);
        assert_eq!(imu.read_new_sample(), Err(Error::NoNewData { status: 0 }));
    }
    imu.bus_mut().clear_faults();
    imu.bus_mut().advance(period);
    assert_eq!(
        imu.read_new_sample().unwrap(),
        expected(&imu.scale(), &RampSource::sample(1))
    );
}

#[test]
fn nothing_panics_on_arbitrary_bus_traffic() {
    let mut model = Lsm6dsoxModel::new(RandomSource::new(11, 500.0, 100.0));
    let mut rng = RandomSource::new(5, 1.0, 1.0);
    for i in 0..20_000u32 {
        let byte = (rng.next_sample().specific_force[0].abs() * 255.0) as u8;
        let mut buf = [byte; 9];
        let mut other = [0u8; 3];
        let result = match i % 4 {
            0 => model.transaction(&mut [Operation::Write(&[byte, byte ^ 0x5A])]),
            1 => model
                .transaction(&mut [Operation::Write(&[byte | 0x80]), Operation::Read(&mut buf)]),
            2 => model.transaction(&mut [Operation::TransferInPlace(&mut buf)]),
            _ => model.transaction(&mut [Operation::Transfer(&mut other, &[0xF8, 0x3A])]),
        };
        assert!(result.is_ok());
        model.advance(u64::from(byte) * 10_000);
    }
}

#[test]
fn bus_bytes_per_sample_for_burst_and_fifo_reads() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().reset_bus_bytes();
    imu.read_sample().unwrap();
    assert_eq!(imu.bus().bus_bytes(), 15);
    let mut imu = i2c_imu(RampSource::default(), &Config::default());
    imu.bus_mut().reset_bus_bytes();
    imu.read_sample().unwrap();
    assert_eq!(imu.bus().bus_bytes(), 17);
    // RAM figure for the firmware's budget (printed, not asserted).
    println!(
        "Lsm6dsoxModel<RampSource>: {} bytes",
        core::mem::size_of::<Lsm6dsoxModel<RampSource>>()
    );
    println!("LSM6DSOX burst read: SPI 15 B/sample, I2C 17 B/sample");

    // FIFO at watermark N: status (2 B), OUT_TEMP (2 B), then N × (2 words × 7 B).
    for watermark in [1u16, 8, 32] {
        let n = u64::from(watermark);
        let cfg = fifo_cfg(watermark, FifoMode::StopOnFull, Odr::Hz833);
        let mut spi = spi_imu(RampSource::default(), &cfg);
        let mut i2c = i2c_imu(RampSource::default(), &cfg);
        let mut out = [RawSample::default(); 32];
        spi.bus_mut().reset_bus_bytes();
        i2c.bus_mut().reset_bus_bytes();
        spi.bus_mut().advance(sample_time_ns(n, Odr::Hz833));
        i2c.bus_mut().advance(sample_time_ns(n, Odr::Hz833));
        assert_eq!(spi.read_fifo(&mut out).unwrap().samples as u64, n);
        assert_eq!(i2c.read_fifo(&mut out).unwrap().samples as u64, n);
        assert_eq!(spi.bus().bus_bytes(), 3 + 3 + 1 + 14 * n);
        assert_eq!(i2c.bus().bus_bytes(), 5 + 5 + 3 + 14 * n);
        println!(
            "LSM6DSOX FIFO watermark {watermark:2}: SPI {:.3} B/sample, I2C {:.3} B/sample",
            spi.bus().bus_bytes() as f64 / n as f64,
            i2c.bus().bus_bytes() as f64 / n as f64
        );
    }
}

#[test]
fn fifo_reads_smaller_than_the_content_continue_in_order() {
    let mut imu = spi_imu(
        RampSource::default(),
        &fifo_cfg(32, FifoMode::StopOnFull, Odr::Hz104),
    );
    let scale = imu.scale();
    imu.bus_mut().advance(sample_time_ns(40, Odr::Hz104));
    let mut out = [RawSample::default(); 8];
    for chunk in 0..5u64 {
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!(read.samples, 8);
        assert_eq!(u64::from(read.remaining), 40 - 8 * (chunk + 1));
        for (i, s) in out.iter().enumerate() {
            assert_eq!(*s, expected_fifo(&scale, 8 * chunk + i as u64, 39));
        }
    }
    assert_eq!(imu.read_fifo(&mut out).unwrap().samples, 0);
}
