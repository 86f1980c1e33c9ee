//! ICM-42688-P driver against embedded-hal-mock: every operation's exact bus
//! transactions, on SPI and on I²C. Register addresses and values are written
//! here as literals from DS-000347 §13/§14, independently of the driver's constants.

mod common;

use common::{both_buses, destroy, i2c_interface, r, spi_interface, w, Op};
use embedded_hal::i2c::{ErrorKind, NoAcknowledgeSource};
use embedded_hal_mock::eh1::delay::{CheckedDelay, NoopDelay, Transaction as DelayTrans};
use embedded_hal_mock::eh1::i2c::{Mock as I2cMock, Transaction as I2cTrans};
use triad::sensor::icm42688::config::{Config, FifoMode};
use triad::sensor::icm42688::{
    AccelRange, FifoConfig, GyroRange, Icm42688, Icm42688Chip, InterruptPin, Odr,
};
use triad::sensor::{Error, FifoImu, FifoRead, FullScale, Imu, RawSample};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

const I2C_ADDRESS: u8 = 0x69;

/// Identity check and soft reset, common to every init.
fn reset_ops() -> Vec<Op> {
    vec![
        w(0x76, 0x00),    // REG_BANK_SEL: bank 0
        r(0x75, &[0x47]), // WHO_AM_I
        w(0x11, 0x01),    // DEVICE_CONFIG: SOFT_RESET_CONFIG
        r(0x2D, &[0x10]), // INT_STATUS: RESET_DONE_INT
        w(0x4C, 0x70),    // INTF_CONFIG0: count in records, big-endian count and data
        w(0x14, 0x03),    // INT_CONFIG: INT1 pulsed, push-pull, active high
        w(0x64, 0x00),    // INT_CONFIG1: INT_ASYNC_RESET cleared
    ]
}

/// The whole init for the default configuration (±16 g, ±2000 °/s, 1 kHz, data ready).
fn default_init_ops() -> Vec<Op> {
    let mut ops = reset_ops();
    ops.extend([
        w(0x4F, 0x06), // GYRO_CONFIG0: ±2000 °/s, 1 kHz
        w(0x50, 0x06), // ACCEL_CONFIG0: ±16 g, 1 kHz
        w(0x65, 0x08), // INT_SOURCE0: UI_DRDY_INT1_EN
        w(0x4E, 0x0F), // PWR_MGMT0: gyro and accel low noise
    ]);
    ops
}

fn init_delays() -> CheckedDelay {
    // 1 ms after the soft reset, 200 µs after power-on (§14 DEVICE_CONFIG, PWR_MGMT0).
    CheckedDelay::new(&[DelayTrans::delay_us(1000), DelayTrans::delay_us(200)])
}

fn fifo_config(watermark: u16) -> Config {
    Config {
        fifo: Some(FifoConfig {
            watermark,
            mode: FifoMode::StopOnFull,
            high_resolution: false,
        }),
        ..Config::default()
    }
}

#[test]
fn init_default_spi_sends_the_exact_sequence() {
    let mut imu = Icm42688::new(spi_interface(&default_init_ops()));
    let mut delay = init_delays();
    imu.init(&mut delay, &Config::default()).unwrap();
    delay.done();
    destroy(imu.into_interface());
}

#[test]
fn init_default_i2c_sends_the_exact_sequence() {
    let mut imu = Icm42688::new(i2c_interface(I2C_ADDRESS, &default_init_ops()));
    let mut delay = init_delays();
    imu.init(&mut delay, &Config::default()).unwrap();
    delay.done();
    destroy(imu.into_interface());
}

#[test]
fn init_writes_typed_ranges_and_rate_codes() {
    let config = Config {
        accel_range: AccelRange::G4,
        gyro_range: GyroRange::Dps500,
        accel_odr: Odr::Hz200,
        gyro_odr: Odr::Hz200,
        interrupt: InterruptPin {
            active_high: false,
            push_pull: false,
            latched: true,
        },
        fifo: None,
    };
    let mut ops = reset_ops();
    ops[5] = w(0x14, 0x04); // INT_CONFIG: latched, open drain, active low
    ops.extend([
        w(0x4F, 0x47), // GYRO_FS_SEL 010 (±500 °/s), GYRO_ODR 0111 (200 Hz)
        w(0x50, 0x47), // ACCEL_FS_SEL 010 (±4 g), ACCEL_ODR 0111 (200 Hz)
        w(0x65, 0x08),
        w(0x4E, 0x0F),
    ]);
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Icm42688::new(bus);
        imu.init(&mut NoopDelay::new(), &config).unwrap();
        imu.into_interface().finish();
    }
}

#[test]
fn init_with_fifo_sets_watermark_mode_and_interrupt_source() {
    let mut ops = reset_ops();
    ops.extend([
        w(0x4F, 0x06),
        w(0x50, 0x06),
        w(0x5F, 0x07), // FIFO_CONFIG1: accel, gyro, temperature
        w(0x60, 0x80), // FIFO_CONFIG2: watermark 128, bits 7:0
        w(0x61, 0x00), // FIFO_CONFIG3: watermark bits 11:8
        w(0x16, 0x80), // FIFO_CONFIG: stop-on-full
        w(0x65, 0x04), // INT_SOURCE0: FIFO_THS_INT1_EN
        w(0x4E, 0x0F),
    ]);
    // Watermarks beyond the 128-packet FIFO, or 0, are refused before any bus traffic.
    let mut imu = Icm42688::new(spi_interface(&[]));
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &fifo_config(300)),
        Err(Error::InvalidConfig {
            what: "FIFO watermark (packets, 1..=128)",
            value: 300
        })
    );
    destroy(imu.into_interface());
    let mut imu = Icm42688::new(spi_interface(&[]));
    assert!(matches!(
        imu.init(&mut NoopDelay::new(), &fifo_config(0)),
        Err(Error::InvalidConfig { value: 0, .. })
    ));
    destroy(imu.into_interface());

    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Icm42688::new(bus);
        imu.init(&mut NoopDelay::new(), &fifo_config(128)).unwrap();
        imu.into_interface().finish();
    }
}

#[test]
fn init_reports_the_identity_read_and_stops() {
    let ops = [w(0x76, 0x00), r(0x75, &[0x98])];
    let mut imu = Icm42688::new(spi_interface(&ops));
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::WrongChip {
            expected: 0x47,
            found: 0x98
        })
    );
    destroy(imu.into_interface());
}

#[test]
fn init_reports_a_reset_that_did_not_complete() {
    let ops = [
        w(0x76, 0x00),
        r(0x75, &[0x47]),
        w(0x11, 0x01),
        r(0x2D, &[0x08]),
    ];
    let mut imu = Icm42688::new(i2c_interface(I2C_ADDRESS, &ops));
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::ResetNotDone { status: 0x08 })
    );
    destroy(imu.into_interface());
}

#[test]
fn i2c_nack_is_a_bus_error_carrying_the_kind() {
    let nack = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
    let bus = I2cMock::new(&[I2cTrans::write(I2C_ADDRESS, vec![0x76, 0x00]).with_error(nack)]);
    let mut imu = Icm42688::new_i2c(bus, I2C_ADDRESS);
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::Bus(nack))
    );
    imu.release().done();
}

/// The 14-byte block of TEMP_DATA1..GYRO_DATA_Z0 for `s`, big-endian.
fn block(s: &RawSample) -> Vec<u8> {
    let mut b = s.temperature.to_be_bytes().to_vec();
    for v in s.accel.iter().chain(s.gyro.iter()) {
        b.extend((*v as i16).to_be_bytes());
    }
    b
}

const SAMPLE: RawSample = RawSample {
    accel: [1, -2, 2048],
    gyro: [-32768, 32767, 0x1234],
    temperature: -300,
};

#[test]
fn read_sample_is_one_14_byte_burst_from_temp_data1() {
    let ops = [r(0x1D, &block(&SAMPLE))];
    let mut imu = Icm42688::new(spi_interface(&ops));
    assert_eq!(imu.read_sample(), Ok(SAMPLE));
    destroy(imu.into_interface());
    let mut imu = Icm42688::new(i2c_interface(I2C_ADDRESS, &ops));
    assert_eq!(imu.read_sample(), Ok(SAMPLE));
    destroy(imu.into_interface());
}

#[test]
fn read_new_sample_checks_data_ready_first() {
    let ops = [r(0x2D, &[0x08]), r(0x1D, &block(&SAMPLE)), r(0x2D, &[0x04])];
    let mut imu = Icm42688::new(spi_interface(&ops));
    assert_eq!(imu.read_new_sample(), Ok(SAMPLE));
    assert_eq!(
        imu.read_new_sample(),
        Err(Error::NoNewData { status: 0x04 })
    );
    destroy(imu.into_interface());
}

/// A FIFO packet 3 for `s` (§6.1): header 0x68, accel, gyro, 8-bit temperature, timestamp.
fn packet(s: &RawSample, temp8: i8, timestamp: u16) -> Vec<u8> {
    let mut p = vec![0x68];
    for v in s.accel.iter().chain(s.gyro.iter()) {
        p.extend((*v as i16).to_be_bytes());
    }
    p.push(temp8 as u8);
    p.extend(timestamp.to_be_bytes());
    p
}

fn numbered(k: i16) -> RawSample {
    RawSample {
        accel: [k, -k, 100 + k].map(i32::from),
        gyro: [2 * k, -3 * k, 7].map(i32::from),
        temperature: (k % 100) * 64,
    }
}

#[test]
fn read_fifo_reads_count_then_whole_packets() {
    let data: Vec<u8> = (0..3)
        .flat_map(|k| packet(&numbered(k), (k % 100) as i8, 1000 * k as u16))
        .collect();
    let ops = [r(0x2D, &[0x04, 0x00, 0x03]), r(0x30, &data)];
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Icm42688::new(bus);
        let mut out = [RawSample::default(); 8];
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!(
            read,
            FifoRead {
                samples: 3,
                remaining: 0,
                overflowed: false,
                lost: 0,
                lost_is_lower_bound: false,
            }
        );
        for k in 0..3 {
            assert_eq!(out[k as usize], numbered(k));
        }
        imu.into_interface().finish();
    }
}

#[test]
fn read_fifo_reads_no_more_than_the_buffer_holds() {
    let data = packet(&numbered(5), 5, 0);
    let ops = [r(0x2D, &[0x00, 0x00, 0x02]), r(0x30, &data)];
    let mut imu = Icm42688::new(spi_interface(&ops));
    let mut out = [RawSample::default(); 1];
    let read = imu.read_fifo(&mut out).unwrap();
    assert_eq!((read.samples, read.remaining), (1, 1));
    assert_eq!(out[0], numbered(5));
    destroy(imu.into_interface());
}

#[test]
fn read_fifo_splits_large_reads_into_32_packet_bursts() {
    let all: Vec<u8> = (0..40)
        .flat_map(|k| packet(&numbered(k), k as i8, 0))
        .collect();
    let ops = [
        r(0x2D, &[0x04, 0x00, 40]),
        r(0x30, &all[..32 * 16]),
        r(0x30, &all[32 * 16..]),
    ];
    let mut imu = Icm42688::new(spi_interface(&ops));
    let mut out = [RawSample::default(); 64];
    assert_eq!(imu.read_fifo(&mut out).unwrap().samples, 40);
    assert!((0..40).all(|k| out[k as usize] == numbered(k)));
    destroy(imu.into_interface());
}

#[test]
fn read_fifo_empty_reads_only_the_count() {
    let ops = [r(0x2D, &[0x00, 0x00, 0x00])];
    let mut imu = Icm42688::new(i2c_interface(I2C_ADDRESS, &ops));
    let mut out = [RawSample::default(); 4];
    assert_eq!(imu.read_fifo(&mut out), Ok(FifoRead::default()));
    destroy(imu.into_interface());
}

#[test]
fn read_fifo_on_overflow_reads_lost_count_and_flushes() {
    let ops = [
        r(0x2D, &[0x06, 0x00, 0x80]), // FIFO_FULL | FIFO_THS, 128 packets
        r(0x6C, &[0x05, 0x01]),       // FIFO_LOST_PKT = 0x0105 = 261
        w(0x4B, 0x02),                // SIGNAL_PATH_RESET: FIFO_FLUSH
    ];
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Icm42688::new(bus);
        let mut out = [RawSample::default(); 4];
        assert_eq!(
            imu.read_fifo(&mut out),
            Ok(FifoRead {
                samples: 0,
                remaining: 0,
                overflowed: true,
                lost: 261 + 128,
                lost_is_lower_bound: false,
            })
        );
        imu.into_interface().finish();
    }
}

#[test]
fn read_fifo_with_a_count_beyond_the_fifo_flushes_it_and_reports_a_loss() {
    // 129 records where the FIFO holds 128: nothing is read from FIFO_DATA.
    let ops = [
        r(0x2D, &[0x04, 0x00, 0x81]),
        w(0x4B, 0x02), // SIGNAL_PATH_RESET: FIFO_FLUSH
    ];
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Icm42688::new(bus);
        let mut out = [RawSample::default(); 4];
        let read = imu.read_fifo(&mut out).unwrap();
        assert_eq!(
            (
                read.samples,
                read.overflowed,
                read.lost,
                read.lost_is_lower_bound
            ),
            (0, true, 1, true),
            "no FIFO configured: at least the one sample that raised data-ready"
        );
        imu.into_interface().finish();
    }
}

#[test]
fn read_fifo_rejects_a_packet_without_accel_and_gyro() {
    let mut data = packet(&numbered(1), 0, 0);
    data[0] = 0xFF; // what an empty FIFO reads
    let ops = [r(0x2D, &[0x00, 0x00, 0x01]), r(0x30, &data)];
    let mut imu = Icm42688::new(spi_interface(&ops));
    let mut out = [RawSample::default(); 4];
    assert_eq!(
        imu.read_fifo(&mut out),
        Err(Error::BadFifoPacket { header: 0xFF })
    );
    destroy(imu.into_interface());
}

#[test]
fn reset_fifo_writes_fifo_flush() {
    let mut imu = Icm42688::new(i2c_interface(I2C_ADDRESS, &[w(0x4B, 0x02)]));
    imu.reset_fifo().unwrap();
    destroy(imu.into_interface());
}

#[test]
fn read_ranges_decodes_both_config_registers() {
    let ops = [r(0x4F, &[0x6F, 0x29]), r(0x4F, &[0x00, 0x8B])];
    let mut imu = Icm42688::new(spi_interface(&ops));
    assert_eq!(
        imu.read_ranges(),
        Ok((AccelRange::G8, GyroRange::Dps250, Odr::Hz500, Odr::Hz50))
    );
    // ACCEL_FS_SEL 100 is reserved: reported with the register value.
    assert_eq!(
        imu.read_ranges(),
        Err(Error::InvalidConfig {
            what: "ACCEL_CONFIG0",
            value: 0x8B
        })
    );
    destroy(imu.into_interface());
}

#[test]
fn scale_is_the_datasheet_sensitivity_in_si() {
    let mut imu = Icm42688::new(spi_interface(&default_init_ops()));
    // Reset configuration: ±16 g at 2048 LSB/g, ±2000 °/s at 16.4 LSB/(°/s).
    let s = imu.scale();
    assert_eq!(s.accel.si_per_lsb, STANDARD_GRAVITY / 2048.0);
    assert_eq!(s.accel.full_scale, 16.0 * STANDARD_GRAVITY);
    assert_eq!(s.gyro.si_per_lsb, deg_to_rad(1.0 / 16.4));
    assert_eq!(s.gyro.full_scale, deg_to_rad(2000.0));
    // Temp °C = TEMP_DATA/132.48 + 25 (§14 TEMP_DATA).
    assert!((s.temperature_c(13248) - 125.0).abs() < 1e-12);
    imu.init(&mut NoopDelay::new(), &Config::default()).unwrap();
    destroy(imu.into_interface());
    let table = [
        (AccelRange::G2, 16384.0),
        (AccelRange::G4, 8192.0),
        (AccelRange::G8, 4096.0),
        (AccelRange::G16, 2048.0),
    ];
    for (range, lsb_per_g) in table {
        assert_eq!(
            range.scale::<Icm42688Chip>().si_per_lsb,
            STANDARD_GRAVITY / lsb_per_g
        );
    }
    let table = [
        (GyroRange::Dps15_625, 2097.2),
        (GyroRange::Dps31_25, 1048.6),
        (GyroRange::Dps62_5, 524.3),
        (GyroRange::Dps125, 262.0),
        (GyroRange::Dps250, 131.0),
        (GyroRange::Dps500, 65.5),
        (GyroRange::Dps1000, 32.8),
        (GyroRange::Dps2000, 16.4),
    ];
    for (range, lsb_per_dps) in table {
        assert_eq!(range.scale().si_per_lsb, deg_to_rad(1.0 / lsb_per_dps));
    }
}
