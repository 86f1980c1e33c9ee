//! LSM6DSOX register addresses and bit fields.
//!
//! Source: ST LSM6DSOX datasheet DS12814 (DocID 026935): §8 "Register
//! mapping" for addresses and reset values, §9 "Register description" for
//! the bit fields, §4.1 Table 2 and §4.3 Table 4 for sensitivities. FIFO
//! behaviour: ST application note AN5272 §9.

/// §9 FIFO_CTRL1: watermark bits 7:0 (in FIFO words).
pub const FIFO_CTRL1: u8 = 0x07;
/// §9 FIFO_CTRL2: bit 0 watermark bit 8.
pub const FIFO_CTRL2: u8 = 0x08;
/// §9 FIFO_CTRL3: BDR_GY (bits 7:4), BDR_XL (bits 3:0): batch data rates.
pub const FIFO_CTRL3: u8 = 0x09;
/// §9 FIFO_CTRL4: bits 2:0 FIFO_MODE.
pub const FIFO_CTRL4: u8 = 0x0A;
/// §9 COUNTER_BDR_REG1: bit 7 dataready_pulsed.
pub const COUNTER_BDR_REG1: u8 = 0x0B;
/// §9 INT1_CTRL: events routed to INT1.
pub const INT1_CTRL: u8 = 0x0D;
/// §9 WHO_AM_I.
pub const WHO_AM_I: u8 = 0x0F;
/// §9 CTRL1_XL: ODR_XL (bits 7:4), FS_XL (bits 3:2).
pub const CTRL1_XL: u8 = 0x10;
/// §9 CTRL2_G: ODR_G (bits 7:4), FS_G (bits 3:2), FS_125 (bit 1).
pub const CTRL2_G: u8 = 0x11;
/// §9 CTRL3_C: BOOT, BDU, H_LACTIVE, PP_OD, SIM, IF_INC, SW_RESET.
pub const CTRL3_C: u8 = 0x12;
/// §9 CTRL5_C: ROUNDING, ST_G (bits 3:2), ST_XL (bits 1:0): self-test.
pub const CTRL5_C: u8 = 0x14;
/// §9 CTRL10_C: the last of the ten control registers CTRL1_XL..=CTRL10_C
/// (0x10..=0x19) the self-test procedure sets.
pub const CTRL10_C: u8 = 0x19;
/// §9 STATUS_REG: TDA (bit 2), GDA (bit 1), XLDA (bit 0).
pub const STATUS_REG: u8 = 0x1E;
/// §9 OUTX_L_G: first of the six gyro output bytes (x, y, z little-endian).
pub const OUTX_L_G: u8 = 0x22;
/// §9 OUTX_L_A: first of the six accel output bytes (x, y, z little-endian).
pub const OUTX_L_A: u8 = 0x28;
/// §9 OUT_TEMP_L: first of the 14-byte block temperature, gyro x/y/z,
/// accel x/y/z (little-endian words) that ends at OUTZ_H_A (0x2D).
pub const OUT_TEMP_L: u8 = 0x20;
/// §9 FIFO_STATUS1: DIFF_FIFO bits 7:0 (unread words).
pub const FIFO_STATUS1: u8 = 0x3A;
/// §9 FIFO_DATA_OUT_TAG: the tag of the oldest FIFO word; its six data
/// bytes follow at 0x79..=0x7E, and a burst wraps from 0x7E back to 0x78.
pub const FIFO_DATA_OUT_TAG: u8 = 0x78;

/// §9: the LSM6DSOX identity.
pub const WHO_AM_I_VALUE: u8 = 0x6C;

/// CTRL3_C bit 7: reboot memory content (a command: self-clearing).
pub const BOOT: u8 = 1 << 7;
/// CTRL3_C bit 6: block data update (output words never mix two samples).
pub const BDU: u8 = 1 << 6;
/// CTRL3_C bit 5: interrupt pins active low.
pub const H_LACTIVE: u8 = 1 << 5;
/// CTRL3_C bit 4: interrupt pins open drain.
pub const PP_OD: u8 = 1 << 4;
/// CTRL3_C bit 2: register address auto-increment in bursts (reset value 1).
pub const IF_INC: u8 = 1 << 2;
/// CTRL3_C bit 0: software reset (self-clearing).
pub const SW_RESET: u8 = 1 << 0;
/// Wait after SW_RESET before checking that the bit cleared. DS12814 §9
/// (CTRL3_C) says only that the bit clears itself when the reset is done;
/// ST's reference driver polls it. The driver waits this long, checks once,
/// and reports `ResetNotDone` if the bit is still set.
pub const SW_RESET_WAIT_US: u32 = 100;

/// CTRL5_C ST_XL = 01: accelerometer positive self-test.
pub const ST_XL_POSITIVE: u8 = 0b01;
/// CTRL5_C ST_G = 01: gyroscope positive self-test.
pub const ST_G_POSITIVE: u8 = 0b01 << 2;

/// COUNTER_BDR_REG1 bit 7: data-ready pulsed (75 µs) instead of latched.
pub const DATAREADY_PULSED: u8 = 1 << 7;

/// INT1_CTRL bit 3: FIFO watermark on INT1.
pub const INT1_FIFO_TH: u8 = 1 << 3;
/// INT1_CTRL bit 1: gyro data ready on INT1.
pub const INT1_DRDY_G: u8 = 1 << 1;
/// INT1_CTRL bit 0: accelerometer data ready on INT1.
pub const INT1_DRDY_XL: u8 = 1 << 0;

/// STATUS_REG bit 1: new gyro sample.
pub const GDA: u8 = 1 << 1;
/// STATUS_REG bit 0: new accel sample.
pub const XLDA: u8 = 1 << 0;

/// ODR / BDR field position in CTRL1_XL, CTRL2_G (bits 7:4).
pub const ODR_SHIFT: u8 = 4;
/// FS field position in CTRL1_XL, CTRL2_G (bits 3:2).
pub const FS_SHIFT: u8 = 2;
/// CTRL2_G bit 1: ±125 °/s, overriding FS_G.
pub const FS_125: u8 = 1 << 1;

/// FIFO_CTRL4 FIFO_MODE = 000: bypass (FIFO off, and emptied).
pub const FIFO_MODE_BYPASS: u8 = 0b000;
/// FIFO_CTRL4 FIFO_MODE = 001: FIFO mode, stops collecting when full.
pub const FIFO_MODE_FIFO: u8 = 0b001;
/// FIFO_CTRL4 FIFO_MODE = 110: continuous, new words overwrite the oldest.
pub const FIFO_MODE_CONTINUOUS: u8 = 0b110;

/// FIFO_STATUS2 bit 6: FIFO overrun (full, and a word has been lost).
pub const FIFO_OVR_IA: u8 = 1 << 6;
/// FIFO_STATUS2 bit 3: overrun since the last read of FIFO_STATUS2 (latched).
pub const FIFO_OVR_LATCHED: u8 = 1 << 3;
/// FIFO depth, words: 3 KiB of 6-byte data words (DS12814 §1 "3 kbytes").
pub const FIFO_CAPACITY_WORDS: u16 = 512;
/// FIFO_STATUS2 bits 1:0: DIFF_FIFO bits 9:8.
pub const DIFF_FIFO_HIGH_MASK: u8 = 0b11;

/// §9 FIFO tag: TAG_SENSOR (bits 7:3) of a gyro word.
pub const TAG_GYRO: u8 = 0x01;
/// §9 FIFO tag: TAG_SENSOR of an accel word.
pub const TAG_ACCEL: u8 = 0x02;
/// TAG_SENSOR field position.
pub const TAG_SENSOR_SHIFT: u8 = 3;
/// Bytes per FIFO word: tag + 6 data.
pub const FIFO_WORD_LEN: usize = 7;
/// FIFO words per 6-axis sample (one gyro word, one accel word).
pub const WORDS_PER_SAMPLE: u16 = 2;

/// §4.3 Table 4: temperature sensitivity, LSB/°C.
pub const TEMP_LSB_PER_C: f64 = 256.0;
/// §4.3 Table 4: temperature at output 0, °C.
pub const TEMP_OFFSET_C: f64 = 25.0;

/// §6.3: I²C address with SA0/SDO low.
pub const I2C_ADDRESS_SA0_LOW: u8 = 0x6A;
/// §6.3: I²C address with SA0/SDO high.
pub const I2C_ADDRESS_SA0_HIGH: u8 = 0x6B;
