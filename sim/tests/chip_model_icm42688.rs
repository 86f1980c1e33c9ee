//! The ICM-42688-P driver against the register-level chip model, on SPI and
//! I²C: configuration changes behaviour, values are the source's quantised at
//! the configured sensitivity, the FIFO keeps order and counts losses, and
//! every injected fault shows as its own error or flag.

mod common;

use common::{expected_code, ConstantSource, RampSource, RandomSource};
use embedded_hal::i2c::{ErrorKind as I2cErrorKind, NoAcknowledgeSource};
use embedded_hal::spi::{ErrorKind as SpiErrorKind, Operation, SpiDevice};
use embedded_hal_mock::eh1::delay::NoopDelay;
use triad::sensor::icm42688::config::{Config, FifoMode};
use triad::sensor::icm42688::{AccelRange, FifoConfig, GyroRange, Icm42688, Icm42688Chip, Odr};
use triad::sensor::interface::{I2cInterface, SpiInterface};
use triad::sensor::{Error, FifoImu, FullScale, Imu, RawSample};
use triad_sim::chips::fault::Fault;
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::source::{SampleSource, TrueSample};

const LIMIT: i16 = 32767;

type SpiImu<S> = Icm42688<SpiInterface<Icm42688Model<S>>>;
type I2cImu<S> = Icm42688<I2cInterface<Icm42688Model<S>>>;

fn spi_imu<S: SampleSource>(source: S, config: &Config) -> SpiImu<S> {
    let mut imu = Icm42688::new_spi(Icm42688Model::new(source));
    imu.init(&mut NoopDelay::new(), config).unwrap();
    imu
}

fn i2c_imu<S: SampleSource>(source: S, config: &Config) -> I2cImu<S> {
    let mut imu = Icm42688::new_i2c(Icm42688Model::new(source).with_ad0(true), 0x69);
    imu.init(&mut NoopDelay::new(), config).unwrap();
    imu
}

/// The codes a chip at `imu`'s scale reports for `t` (independent rounding:
/// value / (SI per LSB); the model multiplies by LSB per SI instead. The two
/// differ by a few ulp, which changes a code only within ~1e-12 LSB of a
/// half-code boundary: never met by these sources).
fn expected(scale: &triad::sensor::ImuScale, t: &TrueSample) -> RawSample {
    let mut s = RawSample::default();
    for axis in 0..3 {
        s.accel[axis] = i32::from(expected_code(
            t.specific_force[axis],
            scale.accel.si_per_lsb,
            LIMIT,
        ));
        s.gyro[axis] = i32::from(expected_code(
            t.angular_rate[axis],
            scale.gyro.si_per_lsb,
            LIMIT,
        ));
    }
    s.temperature = expected_code(t.temperature - 25.0, 1.0 / 132.48, LIMIT);
    s
}

fn config(accel_range: AccelRange, gyro_range: GyroRange, odr: Odr) -> Config {
    Config {
        accel_range,
        gyro_range,
        accel_odr: odr,
        gyro_odr: odr,
        ..Config::default()
    }
}

#[test]
fn every_range_and_rate_round_trips_and_sets_sensitivity_and_timing() {
    for (i, odr) in Odr::ALL.into_iter().enumerate() {
        let accel_range = AccelRange::ALL[i % 4];
        let gyro_range = GyroRange::ALL[i % 8];
        let cfg = config(accel_range, gyro_range, odr);
        // Inputs within ±1.2 full scale: some axes saturate, most do not.
        let fs = (
            accel_range.scale::<Icm42688Chip>().full_scale,
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
        assert_eq!(scale.accel, accel_range.scale::<Icm42688Chip>());
        assert_eq!(scale.gyro, gyro_range.scale());
        let period = u64::from(odr.period_ns());
        for _ in 0..50 {
            // Just short of a period: nothing new.
            imu.bus_mut().advance(period - 1);
            assert!(matches!(
                imu.read_new_sample(),
                Err(Error::NoNewData { .. })
            ));
            imu.bus_mut().advance(1);
            let read = imu.read_new_sample().unwrap();
            assert_eq!(read, expected(&scale, &twin.next_sample()), "{cfg:?}");
        }
        assert_eq!(imu.bus().samples_produced(), 50);
    }
}

#[test]
fn i2c_reads_the_same_values_as_spi() {
    let cfg = config(AccelRange::G2, GyroRange::Dps250, Odr::Hz1000);
    let mut spi = spi_imu(RandomSource::new(3, 25.0, 5.0), &cfg);
    let mut i2c = i2c_imu(RandomSource::new(3, 25.0, 5.0), &cfg);
    let mut twin = RandomSource::new(3, 25.0, 5.0);
    for _ in 0..100 {
        spi.bus_mut().advance(1_000_000);
        i2c.bus_mut().advance(1_000_000);
        let want = expected(&spi.scale(), &twin.next_sample());
        assert_eq!(spi.read_sample().unwrap(), want);
        assert_eq!(i2c.read_sample().unwrap(), want);
    }
}

#[test]
fn several_periods_at_once_leave_the_latest_sample_in_the_registers() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().advance(5_500_000); // 5.5 periods at 1 kHz
    assert_eq!(imu.bus().samples_produced(), 5);
    let want = expected(&imu.scale(), &RampSource::sample(4));
    assert_eq!(imu.read_sample().unwrap(), want);
    imu.bus_mut().advance(500_000); // the half period left completes the 6th
    assert_eq!(imu.bus().samples_produced(), 6);
}

#[test]
fn beyond_full_scale_reads_the_limit_codes_and_sets_the_clip_flag() {
    let over = TrueSample {
        specific_force: [200.0, -200.0, 1.0],
        angular_rate: [40.0, -40.0, 0.1],
        temperature: 25.0,
    };
    let mut imu = spi_imu(ConstantSource(over), &Config::default()); // ±16 g, ±2000 °/s
    imu.bus_mut().advance(1_000_000);
    let s = imu.read_sample().unwrap();
    assert_eq!(s.accel[..2], [LIMIT, -LIMIT].map(i32::from));
    assert_eq!(s.gyro[..2], [LIMIT, -LIMIT].map(i32::from));
    assert_eq!(
        s.accel[2],
        i32::from(expected_code(1.0, imu.scale().accel.si_per_lsb, LIMIT))
    );
    assert!(imu.bus().clipped());

    let inside = TrueSample {
        specific_force: [150.0, -150.0, 1.0], // 15.3 g
        angular_rate: [34.0, -34.0, 0.1],     // 1948 °/s
        temperature: 25.0,
    };
    let mut imu = spi_imu(ConstantSource(inside), &Config::default());
    imu.bus_mut().advance(1_000_000);
    let s = imu.read_sample().unwrap();
    assert!(s
        .accel
        .iter()
        .chain(s.gyro.iter())
        .all(|v| v.abs() < i32::from(LIMIT)));
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
        imu.bus_mut().advance(1_000_000);
        let raw = imu.read_sample().unwrap().temperature;
        // Quantisation error of round-to-nearest: at most half of 1/132.48 °C.
        let half_lsb = 0.5 / 132.48;
        assert!((imu.scale().temperature_c(raw) - celsius).abs() <= half_lsb + 1e-12);
    }
}

#[test]
fn powered_off_chip_produces_nothing_and_reads_the_invalid_marker() {
    // Straight after power-on, before init: both sensors off (PWR_MGMT0 = 0).
    let mut model = Icm42688Model::new(RampSource::default());
    model.advance(10_000_000);
    assert_eq!(model.samples_produced(), 0);
    let mut imu = Icm42688::new_spi(model);
    assert_eq!(
        imu.read_sample().unwrap(),
        RawSample {
            accel: [i32::from(i16::MIN); 3],
            gyro: [i32::from(i16::MIN); 3],
            temperature: i16::MIN
        }
    );
}

#[test]
fn model_register_map_has_the_datasheet_reset_values() {
    let mut model = Icm42688Model::new(RampSource::default());
    // (address, reset value), DS-000347 §13.
    let resets = [
        (0x11, 0x00), // DEVICE_CONFIG
        (0x14, 0x00), // INT_CONFIG
        (0x16, 0x00), // FIFO_CONFIG
        (0x4C, 0x30), // INTF_CONFIG0
        (0x4E, 0x00), // PWR_MGMT0
        (0x4F, 0x06), // GYRO_CONFIG0
        (0x50, 0x06), // ACCEL_CONFIG0
        (0x64, 0x10), // INT_CONFIG1
        (0x65, 0x10), // INT_SOURCE0
        (0x75, 0x47), // WHO_AM_I
        (0x76, 0x00), // REG_BANK_SEL
    ];
    for (address, value) in resets {
        let mut b = [0u8];
        model
            .transaction(&mut [Operation::Write(&[address | 0x80]), Operation::Read(&mut b)])
            .unwrap();
        assert_eq!(b[0], value, "register {address:#04x}");
    }
}

#[test]
fn soft_reset_restores_reset_values_and_init_leaves_bank_zero() {
    let cfg = config(AccelRange::G2, GyroRange::Dps125, Odr::Hz100);
    let mut imu = spi_imu(RampSource::default(), &cfg);
    assert_eq!(imu.bus().peek(0x50), 0x68);
    // Leave the chip in bank 2, as firmware that crashed mid-configuration might.
    imu.bus_mut()
        .transaction(&mut [Operation::Write(&[0x76, 0x02])])
        .unwrap();
    let mut b = [0u8];
    imu.bus_mut()
        .transaction(&mut [Operation::Write(&[0x75 | 0x80]), Operation::Read(&mut b)])
        .unwrap();
    assert_eq!(b[0], 0x00, "WHO_AM_I is a bank-0 register");
    // init selects bank 0 before WHO_AM_I, resets, and reconfigures.
    imu.init(&mut NoopDelay::new(), &Config::default()).unwrap();
    assert_eq!(imu.bus().peek(0x50), 0x06);
    assert_eq!(imu.bus().peek(0x4E), 0x0F);
}

fn fifo_cfg(watermark: u16, mode: FifoMode) -> Config {
    Config {
        fifo: Some(FifoConfig {
            watermark,
            mode,
            high_resolution: false,
        }),
        ..Config::default()
    }
}

/// A sample as it comes out of the FIFO: the temperature has 8 bits (2.07 LSB/°C)
/// and the driver puts it on the register scale (× 64).
fn expected_fifo(scale: &triad::sensor::ImuScale, t: &TrueSample) -> RawSample {
    let mut s = expected(scale, t);
    s.temperature = expected_code(t.temperature - 25.0, 1.0 / 2.07, 127) * 64;
    s
}

#[test]
fn fifo_drains_in_order_without_loss_below_the_watermark() {
    for watermark in [1u16, 8, 32] {
        let mut imu = spi_imu(
            RampSource::default(),
            &fifo_cfg(watermark, FifoMode::StopOnFull),
        );
        let scale = imu.scale();
        let mut out = [RawSample::default(); 32];
        let mut k = 0u64;
        for tick in 0..1000u64 {
            imu.bus_mut().advance(1_000_000);
            if !imu.bus().int1() {
                continue;
            }
            let read = imu.read_fifo(&mut out).unwrap();
            assert!(!read.overflowed && read.lost == 0);
            assert_eq!(read.samples, usize::from(watermark), "tick {tick}");
            for s in &out[..read.samples] {
                assert_eq!(
                    *s,
                    expected_fifo(&scale, &RampSource::sample(k)),
                    "sample {k}"
                );
                k += 1;
            }
        }
        assert_eq!(k, 1000 - 1000 % u64::from(watermark));
    }
}

#[test]
fn fifo_overflow_reports_the_exact_loss_and_recovers() {
    for mode in [FifoMode::StopOnFull, FifoMode::Stream] {
        let mut imu = spi_imu(RampSource::default(), &fifo_cfg(16, mode));
        let scale = imu.scale();
        imu.bus_mut().advance(200 * 1_000_000); // 200 samples into a 128-packet FIFO
        let mut out = [RawSample::default(); 32];
        let read = imu.read_fifo(&mut out).unwrap();
        assert!(read.overflowed);
        // 72 dropped (or overwritten) by the full FIFO + 128 discarded by the flush.
        assert_eq!(read.lost, 200, "{mode:?}");
        assert_eq!(read.samples, 0);
        // After the flush the FIFO restarts with the next sample.
        imu.bus_mut().advance(16 * 1_000_000);
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!((read.samples, read.lost, read.overflowed), (16, 0, false));
        for (i, s) in out[..16].iter().enumerate() {
            assert_eq!(
                *s,
                expected_fifo(&scale, &RampSource::sample(200 + i as u64))
            );
        }
    }
}

#[test]
fn injected_fifo_overflow_is_reported_with_its_loss() {
    let mut imu = i2c_imu(RampSource::default(), &fifo_cfg(8, FifoMode::StopOnFull));
    imu.bus_mut().advance(3 * 1_000_000);
    imu.bus_mut().inject(Fault::FifoOverflow { lost: 10 });
    let mut out = [RawSample::default(); 8];
    let read = imu.read_fifo(&mut out).unwrap();
    assert!(read.overflowed);
    assert_eq!(read.lost, 128 + 10);
    imu.bus_mut().advance(8 * 1_000_000);
    assert_eq!(imu.read_fifo(&mut out).unwrap().samples, 8);
}

#[test]
fn bus_errors_are_reported_and_the_driver_resumes() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().advance(1_000_000);
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
    imu.bus_mut().advance(1_000_000);
    assert!(imu.read_sample().is_ok());
}

#[test]
fn wrong_address_is_a_nack() {
    let mut imu = Icm42688::new_i2c(Icm42688Model::new(RampSource::default()), 0x69);
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::Bus(I2cErrorKind::NoAcknowledge(
            NoAcknowledgeSource::Address
        )))
    );
}

#[test]
fn wrong_identity_is_reported_with_the_value_read() {
    let mut model = Icm42688Model::new(RampSource::default());
    model.inject(Fault::WrongWhoAmI(0x6C));
    let mut imu = Icm42688::new_spi(model);
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::WrongChip {
            expected: 0x47,
            found: 0x6C
        })
    );
    imu.bus_mut().clear_faults();
    imu.init(&mut NoopDelay::new(), &Config::default()).unwrap();
}

#[test]
fn stuck_output_shows_as_no_new_data_and_clears() {
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().advance(1_000_000);
    assert!(imu.read_new_sample().is_ok());
    imu.bus_mut().inject(Fault::StuckOutput);
    for _ in 0..5 {
        imu.bus_mut().advance(1_000_000);
        assert_eq!(imu.read_new_sample(), Err(Error::NoNewData { status: 0 }));
    }
    imu.bus_mut().clear_faults();
    imu.bus_mut().advance(1_000_000);
    assert_eq!(
        imu.read_new_sample().unwrap(),
        expected(&imu.scale(), &RampSource::sample(1))
    );
}

#[test]
fn nothing_panics_on_arbitrary_bus_traffic() {
    // Every address read and written with arbitrary values, in every bank,
    // through every SPI operation kind; the model must neither panic nor hang.
    let mut model = Icm42688Model::new(RandomSource::new(11, 500.0, 100.0));
    let mut rng = RandomSource::new(5, 1.0, 1.0);
    for i in 0..20_000u32 {
        let byte = (rng.next_sample().specific_force[0].abs() * 255.0) as u8;
        let mut buf = [byte; 5];
        let mut other = [0u8; 3];
        let ops = match i % 4 {
            0 => model.transaction(&mut [Operation::Write(&[byte, byte ^ 0x5A])]),
            1 => model
                .transaction(&mut [Operation::Write(&[byte | 0x80]), Operation::Read(&mut buf)]),
            2 => model.transaction(&mut [Operation::TransferInPlace(&mut buf)]),
            _ => model.transaction(&mut [Operation::Transfer(&mut other, &[byte | 0x80, 0x2E])]),
        };
        assert!(ops.is_ok());
        model.advance(u64::from(byte) * 10_000);
    }
}

#[test]
fn bus_bytes_per_sample_for_burst_and_fifo_reads() {
    // Burst: SPI 1 address byte + 14 data; I²C address+register, address+14 data.
    let mut imu = spi_imu(RampSource::default(), &Config::default());
    imu.bus_mut().reset_bus_bytes();
    imu.bus_mut().advance(1_000_000);
    imu.read_sample().unwrap();
    assert_eq!(imu.bus().bus_bytes(), 15);
    let mut imu = i2c_imu(RampSource::default(), &Config::default());
    imu.bus_mut().reset_bus_bytes();
    imu.read_sample().unwrap();
    assert_eq!(imu.bus().bus_bytes(), 17);
    // RAM figure for the firmware's budget (printed, not asserted).
    println!(
        "Icm42688Model<RampSource>: {} bytes",
        core::mem::size_of::<Icm42688Model<RampSource>>()
    );
    println!("ICM-42688-P burst read: SPI 15 B/sample, I2C 17 B/sample");

    // FIFO at watermark N: status+count (1+3 SPI, 2+1+3 I²C), then N × 16-byte packets.
    for watermark in [1u16, 8, 32] {
        let n = u64::from(watermark);
        let mut spi = spi_imu(
            RampSource::default(),
            &fifo_cfg(watermark, FifoMode::StopOnFull),
        );
        let mut i2c = i2c_imu(
            RampSource::default(),
            &fifo_cfg(watermark, FifoMode::StopOnFull),
        );
        let mut out = [RawSample::default(); 32];
        spi.bus_mut().reset_bus_bytes();
        i2c.bus_mut().reset_bus_bytes();
        spi.bus_mut().advance(n * 1_000_000);
        i2c.bus_mut().advance(n * 1_000_000);
        assert_eq!(spi.read_fifo(&mut out).unwrap().samples as u64, n);
        assert_eq!(i2c.read_fifo(&mut out).unwrap().samples as u64, n);
        assert_eq!(spi.bus().bus_bytes(), 4 + 1 + 16 * n);
        assert_eq!(i2c.bus().bus_bytes(), 6 + 3 + 16 * n);
        println!(
            "ICM-42688-P FIFO watermark {watermark:2}: SPI {:.3} B/sample, I2C {:.3} B/sample",
            spi.bus().bus_bytes() as f64 / n as f64,
            i2c.bus().bus_bytes() as f64 / n as f64
        );
    }
}

#[test]
fn fifo_reads_smaller_than_the_content_continue_in_order() {
    let mut imu = spi_imu(RampSource::default(), &fifo_cfg(32, FifoMode::StopOnFull));
    let scale = imu.scale();
    imu.bus_mut().advance(40 * 1_000_000);
    let mut out = [RawSample::default(); 8];
    for chunk in 0..5u64 {
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!(read.samples, 8);
        assert_eq!(u64::from(read.remaining), 40 - 8 * (chunk + 1));
        for (i, s) in out.iter().enumerate() {
            let k = 8 * chunk + i as u64;
            assert_eq!(*s, expected_fifo(&scale, &RampSource::sample(k)));
        }
    }
    assert_eq!(imu.read_fifo(&mut out).unwrap().samples, 0);
}
