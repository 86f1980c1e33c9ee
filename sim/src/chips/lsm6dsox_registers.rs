//! The LSM6DSOX register addresses and bit fields the chip model answers to
//! (DS12814). Kept apart from the driver's map on purpose: the driver's is
//! private to the core, and a model that borrowed the driver's constants
//! would agree with a wrong address in the driver, so the driver-over-model
//! tests could not catch it. The driver's own tests check its addresses
//! against literals from the data sheet.

/// §9 FUNC_CFG_ACCESS (in every page): bit 7 FUNC_CFG_ACCESS selects the
/// embedded-functions page, bit 6 SHUB_REG_ACCESS the sensor-hub page.
pub const FUNC_CFG_ACCESS: u8 = 0x01;
/// FUNC_CFG_ACCESS bit 7: embedded-functions registers.
pub const EMBEDDED_PAGE: u8 = 1 << 7;
/// FUNC_CFG_ACCESS bit 6: sensor-hub registers.
pub const SENSOR_HUB_PAGE: u8 = 1 << 6;
/// §9 CTRL4_C: bit 2 I2C_disable.
pub const CTRL4_C: u8 = 0x13;
/// CTRL4_C bit 2: I²C off (SPI only).
pub const I2C_DISABLE: u8 = 1 << 2;
/// §9 CTRL8_XL: bit 1 XL_FS_MODE (the ±2 g folding of FS_XL = 01).
pub const CTRL8_XL: u8 = 0x17;
/// CTRL8_XL bit 1: XL_FS_MODE.
pub const XL_FS_MODE: u8 = 1 << 1;
/// §9 CTRL10_C: bit 5 TIMESTAMP_EN.
pub const CTRL10_C: u8 = 0x19;
/// CTRL10_C bit 5: timestamp counter on.
pub const TIMESTAMP_EN: u8 = 1 << 5;

/// §10 embedded functions: EMB_FUNC_EN_A (pedometer, tilt, significant motion).
pub const EMB_FUNC_EN_A: u8 = 0x04;
/// §10 embedded functions: EMB_FUNC_EN_B (FSM, MLC, FIFO compression, pedometer adv.).
pub const EMB_FUNC_EN_B: u8 = 0x05;
/// §10 embedded functions: PAGE_RW (reads and writes of the advanced pages).
pub const PAGE_RW: u8 = 0x17;
/// §10 embedded functions: FSM_ENABLE_A.
pub const FSM_ENABLE_A: u8 = 0x46;
/// §10 embedded functions: FSM_ENABLE_B.
pub const FSM_ENABLE_B: u8 = 0x47;

/// §9 FIFO_CTRL1: watermark bits 7:0 (in FIFO words).
pub const FIFO_CTRL1: u8 = 0x07;
/// §9 FIFO_CTRL2: bit 0 watermark bit 8.
pub const FIFO_CTRL2: u8 = 0x08;
/// §9 FIFO_CTRL3: BDR_GY (bits 7:4), BDR_XL (bits 3:0): batch data rates.
pub const FIFO_CTRL3: u8 = 0x09;
/// §9 FIFO_CTRL4: bits 2:0 FIFO_MODE.
pub const FIFO_CTRL4: u8 = 0x0A;
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
/// §9 CTRL5_C: ROUNDING, ST_G (bits 3:2), ST_XL (bits 1:0).
pub const CTRL5_C: u8 = 0x14;
/// §9 STATUS_REG: TDA (bit 2), GDA (bit 1), XLDA (bit 0).
pub const STATUS_REG: u8 = 0x1E;
/// §9 OUT_TEMP_L: first of the 14-byte block temperature, gyro x/y/z,
/// accel x/y/z (little-endian words) that ends at OUTZ_H_A (0x2D).
pub const OUT_TEMP_L: u8 = 0x20;
/// §9 OUTX_L_G: first gyro output byte.
pub const OUTX_L_G: u8 = 0x22;
/// §9 OUTX_L_A: first accel output byte.
pub const OUTX_L_A: u8 = 0x28;
/// §9 OUTZ_H_A: last byte of the sample block.
pub const OUTZ_H_A: u8 = 0x2D;
/// §9 FIFO_STATUS1: DIFF_FIFO bits 7:0 (unread words).
pub const FIFO_STATUS1: u8 = 0x3A;
/// §9 FIFO_STATUS2: flags and DIFF_FIFO bits 9:8.
pub const FIFO_STATUS2: u8 = 0x3B;
/// §9 FIFO_DATA_OUT_TAG: the tag of the oldest FIFO word; its six data
/// bytes follow at 0x79..=0x7E, and a burst wraps from 0x7E back to 0x78.
pub const FIFO_DATA_OUT_TAG: u8 = 0x78;
/// §9 FIFO_DATA_OUT_Z_H: last byte of a FIFO word; reading it pops the word.
pub const FIFO_DATA_OUT_Z_H: u8 = 0x7E;

/// §9: the LSM6DSOX identity.
pub const WHO_AM_I_VALUE: u8 = 0x6C;

/// CTRL3_C bit 2: register address auto-increment in bursts (reset value 1).
pub const IF_INC: u8 = 1 << 2;
/// CTRL3_C bit 0: software reset (self-clearing).
pub const SW_RESET: u8 = 1 << 0;
/// CTRL3_C reset value (§8): only IF_INC set.
pub const CTRL3_C_RESET: u8 = IF_INC;

/// CTRL5_C ST_XL field (bits 1:0): 00 off, 01 positive, 10 negative, 11 not allowed.
pub const ST_XL_MASK: u8 = 0b11;
/// CTRL5_C ST_G field (bits 3:2): 00 off, 01 positive, 10 not allowed, 11 negative.
pub const ST_G_SHIFT: u8 = 2;

/// INT1_CTRL bit 3: FIFO watermark on INT1.
pub const INT1_FIFO_TH: u8 = 1 << 3;
/// INT1_CTRL bit 1: gyro data ready on INT1.
pub const INT1_DRDY_G: u8 = 1 << 1;
/// INT1_CTRL bit 0: accel data ready on INT1.
pub const INT1_DRDY_XL: u8 = 1 << 0;

/// STATUS_REG bit 2: new temperature.
pub const TDA: u8 = 1 << 2;
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
/// FIFO_CTRL4 FIFO_MODE = 001: FIFO mode, stops when full.
pub const FIFO_MODE_FIFO: u8 = 0b001;
/// FIFO_CTRL4 FIFO_MODE = 110: continuous, new words overwrite the oldest.
pub const FIFO_MODE_CONTINUOUS: u8 = 0b110;
/// FIFO_CTRL4 FIFO_MODE field.
pub const FIFO_MODE_MASK: u8 = 0b111;

/// FIFO_STATUS2 bit 7: watermark reached.
pub const FIFO_WTM_IA: u8 = 1 << 7;
/// FIFO_STATUS2 bit 6: FIFO overrun (full, and a word has been lost).
pub const FIFO_OVR_IA: u8 = 1 << 6;
/// FIFO_STATUS2 bit 5: FIFO full at the next ODR.
pub const FIFO_FULL_IA: u8 = 1 << 5;
/// FIFO_STATUS2 bit 3: overrun since the last read of FIFO_STATUS2 (latched).
pub const FIFO_OVR_LATCHED: u8 = 1 << 3;
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
/// FIFO depth: 3 KiB of 6-byte data words (DS12814 §1 "3 kbytes"; AN5272 §9).
pub const FIFO_CAPACITY_WORDS: u16 = 512;
/// The FIFO's words with their tags, bytes.
pub const FIFO_BYTES: usize = FIFO_CAPACITY_WORDS as usize * FIFO_WORD_LEN;
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

/// Output code limits: the full two's-complement range of the 16-bit words.
pub const LIMIT_MIN: i16 = i16::MIN;
/// See [`LIMIT_MIN`].
pub const LIMIT_MAX: i16 = i16::MAX;
