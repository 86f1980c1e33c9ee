//! LSM6DSOX driver against embedded-hal-mock: every operation's exact bus
//! transactions, on SPI and on I²C. Register addresses and values are written
//! here as literals from DS12814 §8/§9, independently of the driver's constants.

mod common;

use common::{both_buses, destroy, i2c_interface, r, spi_interface, w, Op};
use embedded_hal::i2c::{ErrorKind, NoAcknowledgeSource};
use embedded_hal_mock::eh1::delay::{CheckedDelay, NoopDelay, Transaction as DelayTrans};
use embedded_hal_mock::eh1::i2c::{Mock as I2cMock, Transaction as I2cTrans};
use triad::sensor::lsm6dsox::{
    AccelRange, Config, FifoConfig, FifoMode, GyroRange, InterruptPin, Lsm6dsox, Lsm6dsoxChip, Odr,
};
use triad::sensor::{Error, FifoImu, FifoRead, FullScale, Imu, RawSample};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

const I2C_ADDRESS: u8 = 0x6B;

/// Identity check, software reset, CTRL3_C and data-ready style.
fn reset_ops() -> Vec<Op> {
    vec![
        r(0x0F, &[0x6C]), // WHO_AM_I
        w(0x12, 0x05),    // CTRL3_C: IF_INC | SW_RESET
        r(0x12, &[0x04]), // CTRL3_C: SW_RESET cleared
        w(0x12, 0x44),    // CTRL3_C: BDU | IF_INC, INT active high push-pull
        w(0x0B, 0x80),    // COUNTER_BDR_REG1: dataready_pulsed
    ]
}

/// The whole init for the default configuration (±16 g, ±2000 °/s, 833 Hz, data ready).
fn default_init_ops() -> Vec<Op> {
    let mut ops = reset_ops();
    ops.extend([
        w(0x0D, 0x02), // INT1_CTRL: INT1_DRDY_G
        w(0x10, 0x74), // CTRL1_XL: ODR 0111 (833 Hz), FS_XL 01 (±16 g)
        w(0x11, 0x7C), // CTRL2_G: ODR 0111 (833 Hz), FS_G 11 (±2000 °/s)
    ]);
    ops
}

#[test]
fn init_default_sends_the_exact_sequence_on_both_buses() {
    for bus in both_buses(I2C_ADDRESS, &default_init_ops()) {
        let mut imu = Lsm6dsox::new(bus);
        // 100 µs after SW_RESET before checking it cleared.
        let mut delay = CheckedDelay::new(&[DelayTrans::delay_us(100)]);
        imu.init(&mut delay, &Config::default()).unwrap();
        delay.done();
        imu.into_interface().finish();
    }
}

#[test]
fn init_writes_typed_ranges_rate_and_pin_codes() {
    let config = Config {
        accel_range: AccelRange::G4,
        gyro_range: GyroRange::Dps125,
        accel_odr: Odr::Hz104,
        gyro_odr: Odr::Hz104,
        interrupt: InterruptPin {
            active_high: false,
            push_pull: false,
            latched: true,
        },
        fifo: None,
    };
    let ops = [
        r(0x0F, &[0x6C]),
        w(0x12, 0x05),
        r(0x12, &[0x04]),
        w(0x12, 0x74), // BDU | H_LACTIVE | PP_OD | IF_INC
        w(0x0B, 0x00), // latched data ready
        w(0x0D, 0x02),
        w(0x10, 0x48), // ODR 0100 (104 Hz), FS_XL 10 (±4 g)
        w(0x11, 0x42), // ODR 0100, FS_125
    ];
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Lsm6dsox::new(bus);
        imu.init(&mut NoopDelay::new(), &config).unwrap();
        imu.into_interface().finish();
    }
}

#[test]
fn init_with_fifo_sets_watermark_in_words_batch_rate_and_mode() {
    let mut ops = reset_ops();
    ops.extend([
        w(0x07, 0x90), // FIFO_CTRL1: watermark 200 samples = 400 words = 0x190, bits 7:0
        w(0x08, 0x01), // FIFO_CTRL2: watermark bit 8
        w(0x09, 0x77), // FIFO_CTRL3: BDR_GY = BDR_XL = 833 Hz
        w(0x0A, 0x06), // FIFO_CTRL4: continuous mode
        w(0x0D, 0x08), // INT1_CTRL: INT1_FIFO_TH
        w(0x10, 0x74),
        w(0x11, 0x7C),
    ]);
    let config = Config {
        fifo: Some(FifoConfig {
            watermark: 200,
            mode: FifoMode::Stream,
            high_resolution: false,
        }),
        ..Config::default()
    };
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Lsm6dsox::new(bus);
        imu.init(&mut NoopDelay::new(), &config).unwrap();
        imu.into_interface().finish();
    }
    // 256 samples = 512 words would not fit the 9-bit watermark.
    let mut imu = Lsm6dsox::new(spi_interface(&[]));
    let too_big = Config {
        fifo: Some(FifoConfig {
            watermark: 256,
            mode: FifoMode::StopOnFull,
            high_resolution: false,
        }),
        ..Config::default()
    };
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &too_big),
        Err(Error::InvalidConfig {
            what: "FIFO watermark (samples, 1..=255)",
            value: 256
        })
    );
    destroy(imu.into_interface());
}

#[test]
fn init_reports_the_identity_read_and_stops() {
    let mut imu = Lsm6dsox::new(i2c_interface(I2C_ADDRESS, &[r(0x0F, &[0x6A])]));
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::WrongChip {
            expected: 0x6C,
            found: 0x6A
        })
    );
    destroy(imu.into_interface());
}

#[test]
fn init_reports_a_reset_bit_that_stayed_set() {
    let ops = [r(0x0F, &[0x6C]), w(0x12, 0x05), r(0x12, &[0x05])];
    let mut imu = Lsm6dsox::new(spi_interface(&ops));
    assert_eq!(
        imu.init(&mut NoopDelay::new(), &Config::default()),
        Err(Error::ResetNotDone { status: 0x05 })
    );
    destroy(imu.into_interface());
}

#[test]
fn i2c_nack_is_a_bus_error_carrying_the_kind() {
    let nack = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Data);
    let bus =
        I2cMock::new(
            &[I2cTrans::write_read(I2C_ADDRESS, vec![0x20], vec![0; 14]).with_error(nack)],
        );
    let mut imu = Lsm6dsox::new_i2c(bus, I2C_ADDRESS);
    assert_eq!(imu.read_sample(), Err(Error::Bus(nack)));
    imu.release().done();
}

const SAMPLE: RawSample = RawSample {
    accel: [1, -2, 2048],
    gyro: [-32768, 32767, 0x1234],
    temperature: -300,
};

/// OUT_TEMP_L..OUTZ_H_A for `s`: temperature, gyro, accel, little-endian.
fn block(s: &RawSample) -> Vec<u8> {
    let mut b = s.temperature.to_le_bytes().to_vec();
    for v in s.gyro.iter().chain(s.accel.iter()) {
        b.extend((*v as i16).to_le_bytes());
    }
    b
}

#[test]
fn read_sample_is_one_14_byte_burst_from_out_temp_l() {
    for bus in both_buses(I2C_ADDRESS, &[r(0x20, &block(&SAMPLE))]) {
        let mut imu = Lsm6dsox::new(bus);
        assert_eq!(imu.read_sample(), Ok(SAMPLE));
        imu.into_interface().finish();
    }
}

#[test]
fn read_new_sample_needs_both_data_ready_bits() {
    let ops = [
        r(0x1E, &[0x07]),
        r(0x20, &block(&SAMPLE)),
        r(0x1E, &[0x02]), // gyro only
    ];
    let mut imu = Lsm6dsox::new(spi_interface(&ops));
    assert_eq!(imu.read_new_sample(), Ok(SAMPLE));
    assert_eq!(
        imu.read_new_sample(),
        Err(Error::NoNewData { status: 0x02 })
    );
    destroy(imu.into_interface());
}

/// A FIFO word: tag (sensor << 3 | counter << 1 | parity) and three LE words.
fn word(sensor: u8, counter: u8, v: [i32; 3]) -> Vec<u8> {
    let mut tag = (sensor << 3) | (counter << 1);
    tag |= (tag.count_ones() & 1) as u8;
    let mut b = vec![tag];
    for x in v {
        b.extend((x as i16).to_le_bytes());
    }
    b
}

fn numbered(k: i16) -> RawSample {
    RawSample {
        accel: [k, -k, 100 + k].map(i32::from),
        gyro: [2 * k, -3 * k, 7].map(i32::from),
        temperature: 512,
    }
}

#[test]
fn read_fifo_reads_status_temperature_then_word_pairs() {
    // Pairs in either order: gyro first for k = 0, accel first for k = 1.
    let mut data = word(1, 1, numbered(0).gyro);
    data.extend(word(2, 1, numbered(0).accel));
    data.extend(word(2, 2, numbered(1).accel));
    data.extend(word(1, 2, numbered(1).gyro));
    let ops = [
        r(0x3A, &[0x05, 0x80]), // DIFF_FIFO = 5 words, WTM_IA
        r(0x20, &512i16.to_le_bytes()),
        r(0x78, &data),
    ];
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Lsm6dsox::new(bus);
        let mut out = [RawSample::default(); 4];
        assert_eq!(
            imu.read_fifo(&mut out),
            Ok(FifoRead {
                samples: 2,
                remaining: 0, // the odd fifth word is half a sample
                overflowed: false,
                lost: 0,
                lost_is_lower_bound: false
            })
        );
        assert_eq!(out[..2], [numbered(0), numbered(1)]);
        imu.into_interface().finish();
    }
}

#[test]
fn read_fifo_splits_large_reads_into_32_sample_bursts() {
    let all: Vec<u8> = (0..40)
        .flat_map(|k| {
            let mut p = word(1, 0, numbered(k).gyro);
            p.extend(word(2, 0, numbered(k).accel));
            p
        })
        .collect();
    let ops = [
        r(0x3A, &[80, 0x00]),
        r(0x20, &512i16.to_le_bytes()),
        r(0x78, &all[..32 * 14]),
        r(0x78, &all[32 * 14..]),
    ];
    let mut imu = Lsm6dsox::new(spi_interface(&ops));
    let mut out = [RawSample::default(); 64];
    assert_eq!(imu.read_fifo(&mut out).unwrap().samples, 40);
    assert!((0..40).all(|k| out[k as usize] == numbered(k)));
    destroy(imu.into_interface());
}

#[test]
fn read_fifo_empty_reads_only_the_status() {
    let mut imu = Lsm6dsox::new(i2c_interface(I2C_ADDRESS, &[r(0x3A, &[0x00, 0x00])]));
    assert_eq!(
        imu.read_fifo(&mut [RawSample::default(); 2]),
        Ok(FifoRead::default())
    );
    destroy(imu.into_interface());
}

#[test]
fn read_fifo_on_overrun_resets_and_reports_a_lower_bound() {
    let config = Config {
        fifo: Some(FifoConfig {
            watermark: 16,
            mode: FifoMode::StopOnFull,
            high_resolution: false,
        }),
        ..Config::default()
    };
    let mut ops = reset_ops();
    ops.extend([
        w(0x07, 32),
        w(0x08, 0),
        w(0x09, 0x77),
        w(0x0A, 0x01),
        w(0x0D, 0x08),
        w(0x10, 0x74),
        w(0x11, 0x7C),
        r(0x3A, &[0x00, 0xEA]), // 512 words; WTM, OVR, FULL, OVR_LATCHED; DIFF_FIFO[9:8] = 10
        w(0x0A, 0x00),          // FIFO_CTRL4: bypass empties the FIFO
        w(0x0A, 0x01),          // FIFO_CTRL4: FIFO mode again
    ]);
    for bus in both_buses(I2C_ADDRESS, &ops) {
        let mut imu = Lsm6dsox::new(bus);
        imu.init(&mut NoopDelay::new(), &config).unwrap();
        assert_eq!(
            imu.read_fifo(&mut [RawSample::default(); 4]),
            Ok(FifoRead {
                samples: 0,
                remaining: 0,
                overflowed: true,
                lost: 256,
                lost_is_lower_bound: true
            })
        );
        imu.into_interface().finish();
    }
}

#[test]
fn read_fifo_rejects_a_pair_that_is_not_gyro_and_accel() {
    let mut data = word(1, 0, [1, 2, 3]);
    data.extend(word(1, 1, [4, 5, 6])); // two gyro words
    let ops = [r(0x3A, &[0x02, 0x00]), r(0x20, &[0, 0]), r(0x78, &data)];
    let mut imu = Lsm6dsox::new(spi_interface(&ops));
    let tag = data[7];
    assert_eq!(
        imu.read_fifo(&mut [RawSample::default(); 1]),
        Err(Error::BadFifoPacket { header: tag })
    );
    destroy(imu.into_interface());
}

#[test]
fn read_ranges_decodes_both_control_registers() {
    let ops = [r(0x10, &[0x8C, 0x34]), r(0x10, &[0x00, 0x34])];
    let mut imu = Lsm6dsox::new(i2c_interface(I2C_ADDRESS, &ops));
    assert_eq!(
        imu.read_ranges(),
        Ok((AccelRange::G8, GyroRange::Dps500, Odr::Hz52, Odr::Hz1666))
    );
    // ODR_XL 0000: accelerometer powered down.
    assert_eq!(
        imu.read_ranges(),
        Err(Error::InvalidConfig {
            what: "CTRL1_XL",
            value: 0x00
        })
    );
    destroy(imu.into_interface());
}

#[test]
fn scale_is_the_datasheet_sensitivity_in_si() {
    // Before init: the reset ranges ±2 g and ±250 °/s.
    let imu = Lsm6dsox::new(spi_interface(&[]));
    let s = imu.scale();
    assert_eq!(s.accel.si_per_lsb, 0.061e-3 * STANDARD_GRAVITY);
    assert_eq!(s.gyro.si_per_lsb, deg_to_rad(8.75e-3));
    // 256 LSB/°C, 0 LSB at 25 °C (§4.3 Table 4).
    assert_eq!(s.temperature_c(256 * 10), 35.0);
    destroy(imu.into_interface());
    let table = [
        (AccelRange::G2, 0.061),
        (AccelRange::G4, 0.122),
        (AccelRange::G8, 0.244),
        (AccelRange::G16, 0.488),
    ];
    for (range, mg) in table {
        assert_eq!(
            range.scale::<Lsm6dsoxChip>().si_per_lsb,
            mg * 1e-3 * STANDARD_GRAVITY
        );
        assert_eq!(
            range.scale::<Lsm6dsoxChip>().full_scale,
            range.g() * STANDARD_GRAVITY
        );
    }
    let table = [
        (GyroRange::Dps125, 4.375),
        (GyroRange::Dps250, 8.75),
        (GyroRange::Dps500, 17.5),
        (GyroRange::Dps1000, 35.0),
        (GyroRange::Dps2000, 70.0),
    ];
    for (range, mdps) in table {
        assert_eq!(range.scale().si_per_lsb, deg_to_rad(mdps * 1e-3));
    }
}
