//! The ICM-42688-P model on the paths published drivers take (issue 23,
//! items 1–4 and 6), driven register by register as any driver would, each
//! checked against DS-000347: the 20-bit FIFO packet 4, independent
//! accelerometer and gyroscope rates (registers and FIFO), TMST_CONFIG
//! timestamps, banks 1 and 2, APEX_CONFIG0's reset value, I²C switched off,
//! and the FIFO_COUNTH → FIFO_COUNTL latch.

mod common;

use common::bus::{i2c_read1, i2c_write1, read, read1, write};
use common::RampSource;
use triad_sim::chips::icm42688_model::Icm42688Model;
use triad_sim::chips::source::TrueSample;

const STANDARD_GRAVITY: f64 = 9.806_65;
const BANK_SEL: u8 = 0x76;
const FIFO_CONFIG: u8 = 0x16;
const FIFO_STREAM: u8 = 0x40;
const FIFO_COUNTH: u8 = 0x2E;
const FIFO_DATA: u8 = 0x30;
const INTF_CONFIG0: u8 = 0x4C;
const PWR_MGMT0: u8 = 0x4E;
const GYRO_CONFIG0: u8 = 0x4F;
const ACCEL_CONFIG0: u8 = 0x50;
const TMST_CONFIG: u8 = 0x54;
const FIFO_CONFIG1: u8 = 0x5F;
/// PWR_MGMT0: gyro and accel low-noise, temperature on.
const BOTH_LOW_NOISE: u8 = 0x0F;
/// ODR codes (§14): 1 kHz, 500 Hz.
const ODR_1KHZ: u8 = 0x06;
const ODR_500HZ: u8 = 0x0F;
const MS: u64 = 1_000_000;

fn chip() -> Icm42688Model<RampSource> {
    Icm42688Model::new(RampSource::default())
}

fn be(b: &[u8], i: usize) -> i16 {
    i16::from_be_bytes([b[i], b[i + 1]])
}

/// A 20-bit field from its high byte, middle byte and low nibble, sign-extended.
fn twenty_bit(high: u8, middle: u8, low: u8) -> i32 {
    let raw = (i32::from(high) << 12) | (i32::from(middle) << 4) | i32::from(low & 0x0F);
    (raw << 12) >> 12
}

/// FIFO_COUNT as the reset INTF_CONFIG0 reports it: bytes, big-endian.
fn fifo_count(chip: &mut Icm42688Model<RampSource>) -> usize {
    usize::from(u16::from_be_bytes(read::<_, 2>(chip, FIFO_COUNTH)))
}

#[test]
fn hires_fifo_packets_are_20_bytes_with_20_bit_data() {
    // DS-000347 §6.1 packet 4, §14 FIFO_CONFIG1 FIFO_HIRES_EN (bit 4).
    let mut chip = chip();
    write(&mut chip, FIFO_CONFIG1, &[0x17]); // HIRES, TEMP, GYRO, ACCEL
    write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(3 * MS);
    assert_eq!(fifo_count(&mut chip), 3 * 20, "three 20-byte packets");
    let bytes = read::<_, 60>(&mut chip, FIFO_DATA);
    for (k, p) in bytes.chunks_exact(20).enumerate() {
        let truth: TrueSample = RampSource::sample(k as u64);
        // HEADER_ACCEL | HEADER_GYRO | HEADER_20 | timestamp (bits 3:2 = 10).
        assert_eq!(p[0], 0x78, "packet {k} header");
        for axis in 0..3 {
            let accel = twenty_bit(p[1 + 2 * axis], p[2 + 2 * axis], p[17 + axis] >> 4);
            let gyro = twenty_bit(p[7 + 2 * axis], p[8 + 2 * axis], p[17 + axis]);
            // 18-bit accel at ±16 g (8192 LSB/g), 19-bit gyro at ±2000 °/s
            // (131 LSB/(°/s)), whatever the configured ranges.
            let g = truth.specific_force[axis] / STANDARD_GRAVITY;
            assert_eq!(
                accel,
                ((g * 8192.0).round() as i32) << 2,
                "packet {k} accel {axis}"
            );
            let dps = truth.angular_rate[axis].to_degrees();
            assert_eq!(
                gyro,
                ((dps * 131.0).round() as i32) << 1,
                "packet {k} gyro {axis}"
            );
            // A resolution the 16-bit packet does not have (2048 LSB/g at ±16 g).
            assert_eq!(accel & 0b11, 0);
        }
        let temp = be(p, 13);
        assert_eq!(temp, ((truth.temperature - 25.0) * 132.48).round() as i16);
    }
}

#[test]
fn accel_and_gyro_keep_their_own_rates_in_the_registers() {
    // §14 ACCEL_CONFIG0 / GYRO_CONFIG0: independent ODR fields.
    let mut chip = chip();
    write(&mut chip, GYRO_CONFIG0, &[ODR_1KHZ]);
    write(&mut chip, ACCEL_CONFIG0, &[ODR_500HZ]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    let (mut accel_updates, mut gyro_updates) = (0, 0);
    // Before any sample both read the invalid marker (0x8000).
    let mut accel = [0x80, 0, 0x80, 0, 0x80, 0];
    let mut gyro = accel;
    for _ in 0..20 {
        chip.advance(MS);
        let block = read::<_, 12>(&mut chip, 0x1F);
        accel_updates += usize::from(block[..6] != accel);
        gyro_updates += usize::from(block[6..] != gyro);
        accel.copy_from_slice(&block[..6]);
        gyro.copy_from_slice(&block[6..]);
    }
    assert_eq!((accel_updates, gyro_updates), (10, 20));
}

#[test]
fn fifo_packets_mark_the_slower_sensor_invalid_and_one_sensor_packets_are_8_bytes() {
    // §6.1: packet 3 at the faster rate, the slower sensor's field -32768
    // where it has no new sample; packets 1 (accel only) are 8 bytes.
    let mut chip = chip();
    write(&mut chip, GYRO_CONFIG0, &[ODR_1KHZ]);
    write(&mut chip, ACCEL_CONFIG0, &[ODR_500HZ]);
    write(&mut chip, FIFO_CONFIG1, &[0x07]); // TEMP, GYRO, ACCEL
    write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(8 * MS);
    assert_eq!(fifo_count(&mut chip), 8 * 16);
    let bytes = read::<_, 128>(&mut chip, FIFO_DATA);
    let invalid: Vec<bool> = bytes
        .chunks_exact(16)
        .map(|p| be(p, 1) == i16::MIN)
        .collect();
    assert_eq!(
        invalid,
        [true, false, true, false, true, false, true, false]
    );
    assert!(
        bytes.chunks_exact(16).all(|p| be(p, 7) != i16::MIN),
        "gyro every packet"
    );

    // Accelerometer alone in the FIFO: 8-byte packets at its 500 Hz.
    write(&mut chip, FIFO_CONFIG1, &[0x05]); // TEMP, ACCEL
    write(&mut chip, 0x4B, &[0x02]); // SIGNAL_PATH_RESET FIFO_FLUSH
    chip.advance(8 * MS);
    assert_eq!(fifo_count(&mut chip), 4 * 8);
    let bytes = read::<_, 32>(&mut chip, FIFO_DATA);
    assert!(
        bytes.chunks_exact(8).all(|p| p[0] == 0x40),
        "HEADER_ACCEL only: {bytes:02x?}"
    );
}

#[test]
fn timestamps_follow_tmst_config_resolution_and_delta_mode() {
    // §14 TMST_CONFIG: TMST_RES (bit 3) 16 µs, TMST_DELTA_EN (bit 2).
    let timestamps = |tmst_config: u8| {
        let mut chip = chip();
        write(&mut chip, TMST_CONFIG, &[tmst_config]);
        write(&mut chip, FIFO_CONFIG1, &[0x07]);
        write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
        write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
        chip.advance(8 * MS);
        let bytes = read::<_, 128>(&mut chip, FIFO_DATA);
        bytes
            .chunks_exact(16)
            .map(|p| u16::from_be_bytes([p[14], p[15]]))
            .collect::<Vec<_>>()
    };
    let microseconds: Vec<u16> = (1..=8).map(|n| n * 1000).collect();
    assert_eq!(
        timestamps(0x23),
        microseconds,
        "reset value: absolute, 1 µs"
    );
    let ticks: Vec<u16> = (1..=8u16).map(|n| n * 1000 / 16).collect();
    assert_eq!(timestamps(0x2B), ticks, "absolute, 16 µs");
    let deltas: Vec<u16> = (1..=8u16)
        .map(|n| n * 1000 / 16 - (n - 1) * 1000 / 16)
        .collect();
    assert_eq!(
        timestamps(0x2F),
        deltas,
        "delta, 16 µs (62 or 63 ticks per ms)"
    );
}

#[test]
fn banks_1_and_2_have_their_reset_values_and_keep_writes() {
    // DS-000347 §13 user banks 1 and 2: the anti-alias filter registers.
    let mut chip = chip();
    write(&mut chip, BANK_SEL, &[1]);
    assert_eq!(read::<_, 4>(&mut chip, 0x0B), [0xA0, 0x0D, 0xAA, 0x80]);
    write(&mut chip, BANK_SEL, &[2]);
    assert_eq!(read::<_, 3>(&mut chip, 0x03), [0x30, 0x40, 0x62]);
    // A driver's anti-alias setting sticks, per bank.
    write(&mut chip, 0x03, &[0x01]); // ACCEL_AAF_DIS
    write(&mut chip, BANK_SEL, &[1]);
    write(&mut chip, 0x0C, &[0x1F]);
    assert_eq!(read1(&mut chip, 0x0C), 0x1F);
    write(&mut chip, BANK_SEL, &[2]);
    assert_eq!(read1(&mut chip, 0x03), 0x01);
    write(&mut chip, BANK_SEL, &[0]);
    // The bank-0 registers at those addresses are untouched.
    assert_eq!(read1(&mut chip, 0x75), 0x47);
    assert_eq!(read1(&mut chip, GYRO_CONFIG0), 0x06);
}

#[test]
fn apex_config0_resets_to_0x82() {
    // §14 APEX_CONFIG0: DMP_POWER_SAVE = 1, DMP_ODR = 10 (50 Hz).
    assert_eq!(read1(&mut chip(), 0x56), 0x82);
}

#[test]
fn i2c_stops_answering_once_intf_config0_disables_it() {
    // §14 INTF_CONFIG0 UI_SIFS_CFG (bits 1:0) = 11: I²C disabled.
    let mut chip = chip();
    assert_eq!(i2c_read1(&mut chip, 0x68, 0x75), Ok(0x47));
    i2c_write1(&mut chip, 0x68, INTF_CONFIG0, 0x33).unwrap();
    assert!(
        i2c_read1(&mut chip, 0x68, 0x75).is_err(),
        "I²C still answers"
    );
    assert_eq!(read1(&mut chip, 0x75), 0x47, "SPI still does");
}

#[test]
fn reading_fifo_counth_latches_fifo_countl() {
    // §14 FIFO_COUNTH: reading it latches the count for FIFO_COUNTL.
    let mut chip = chip();
    write(&mut chip, FIFO_CONFIG1, &[0x07]);
    write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(15 * MS); // 240 bytes
    let high = read1(&mut chip, FIFO_COUNTH);
    chip.advance(2 * MS); // 272 bytes: the low byte changes, the high byte too
    let low = read1(&mut chip, FIFO_COUNTH + 1);
    assert_eq!(u16::from_be_bytes([high, low]), 240);
    // No latch pending: FIFO_COUNTL alone reads the live count.
    assert_eq!(read1(&mut chip, FIFO_COUNTH + 1), (272 & 0xFF) as u8);
}

#[test]
fn sensor_data_endian_zero_gives_little_endian_registers_and_fifo_words() {
    // §14 INTF_CONFIG0 SENSOR_DATA_ENDIAN (bit 4) = 0: little-endian data.
    let mut chip = chip();
    write(&mut chip, INTF_CONFIG0, &[0x20]); // FIFO_COUNT_ENDIAN only
    write(&mut chip, FIFO_CONFIG1, &[0x07]);
    write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(MS);
    let truth = RampSource::sample(0);
    let temp = ((truth.temperature - 25.0) * 132.48).round() as i16;
    assert_eq!(read::<_, 2>(&mut chip, 0x1D), temp.to_le_bytes());
    let packet = read::<_, 16>(&mut chip, FIFO_DATA);
    let z = truth.specific_force[2] / STANDARD_GRAVITY * 2048.0;
    assert_eq!(packet[5..7], (z.round() as i16).to_le_bytes());
}

#[test]
fn tmst_strobe_latches_the_timestamp_into_bank_1() {
    // §14 SIGNAL_PATH_RESET TMST_STROBE; §13 bank 1 TMSTVAL0..2 (20 bits).
    let mut chip = chip();
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(70 * MS + 400_000); // 70 400 µs of running chip
    write(&mut chip, 0x4B, &[0x04]);
    write(&mut chip, BANK_SEL, &[1]);
    let [b0, b1, b2] = read::<_, 3>(&mut chip, 0x62);
    assert_eq!(u32::from_le_bytes([b0, b1, b2, 0]), 70_400);
}

#[test]
fn the_header_flags_a_changed_odr() {
    // §6.2 HEADER_ODR_GYRO / HEADER_ODR_ACCEL: set on the first packet
    // whose data come at another ODR than the previous packet's.
    let mut chip = chip();
    write(&mut chip, FIFO_CONFIG1, &[0x07]);
    write(&mut chip, FIFO_CONFIG, &[FIFO_STREAM]);
    write(&mut chip, PWR_MGMT0, &[BOTH_LOW_NOISE]);
    chip.advance(2 * MS);
    write(&mut chip, GYRO_CONFIG0, &[0x05]); // 2 kHz
    chip.advance(MS);
    let headers: Vec<u8> = read::<_, 64>(&mut chip, FIFO_DATA)
        .chunks_exact(16)
        .map(|p| p[0])
        .collect();
    // 1 kHz, 1 kHz, then 2 kHz: the gyro at 2 kHz with the accel invalid
    // between its 1 kHz samples.
    assert_eq!(headers, [0x68, 0x68, 0x69, 0x68]);
}
