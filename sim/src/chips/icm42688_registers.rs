//! The ICM-42688-P register addresses and bit fields the chip model answers to
//! (DS-000347). Kept apart from the driver's map on purpose: the driver's is
//! private to the core, and a model that borrowed the driver's constants
//! would agree with a wrong address in the driver, so the driver-over-model
//! tests could not catch it. The driver's own tests check its addresses
//! against literals from the data sheet.

/// §13: bank selection, reachable from every bank (bits 2:0).
pub const REG_BANK_SEL: u8 = 0x76;
/// §14 DEVICE_CONFIG: bit 0 SOFT_RESET_CONFIG.
pub const DEVICE_CONFIG: u8 = 0x11;
/// §14 FIFO_CONFIG: bits 7:6 FIFO_MODE.
pub const FIFO_CONFIG: u8 = 0x16;
/// §14 TEMP_DATA1: first byte of the 14-byte sample block (temperature,
/// accel x/y/z, gyro x/y/z, each big-endian) that ends at GYRO_DATA_Z0 (0x2A).
pub const TEMP_DATA1: u8 = 0x1D;
/// §14 GYRO_DATA_Z0: last byte of the sample block.
pub const GYRO_DATA_Z0: u8 = 0x2A;
/// §14 INT_STATUS: interrupt status, cleared on read.
pub const INT_STATUS: u8 = 0x2D;
/// §14 FIFO_COUNTH: FIFO count high byte; FIFO_COUNTL follows at 0x2F.
pub const FIFO_COUNTH: u8 = 0x2E;
/// §14 FIFO_DATA: the FIFO read port (the address does not auto-increment here).
pub const FIFO_DATA: u8 = 0x30;
/// §14 SIGNAL_PATH_RESET: bit 1 FIFO_FLUSH.
pub const SIGNAL_PATH_RESET: u8 = 0x4B;
/// §14 INTF_CONFIG0: FIFO count format and data endianness.
pub const INTF_CONFIG0: u8 = 0x4C;
/// §14 PWR_MGMT0: accel and gyro power modes, temperature sensor disable.
pub const PWR_MGMT0: u8 = 0x4E;
/// §14 GYRO_CONFIG0: bits 7:5 GYRO_FS_SEL, bits 3:0 GYRO_ODR.
pub const GYRO_CONFIG0: u8 = 0x4F;
/// §14 ACCEL_CONFIG0: bits 7:5 ACCEL_FS_SEL, bits 3:0 ACCEL_ODR.
pub const ACCEL_CONFIG0: u8 = 0x50;
/// §14 TMST_CONFIG: bit 3 TMST_RES, bit 2 TMST_DELTA_EN, bit 0 TMST_EN (reset 0x23).
pub const TMST_CONFIG: u8 = 0x54;
/// §14 APEX_CONFIG0: DMP power save and DMP ODR (reset 0x82).
pub const APEX_CONFIG0: u8 = 0x56;
/// §14 FIFO_CONFIG1: which sensors go into the FIFO, and the 20-bit mode.
pub const FIFO_CONFIG1: u8 = 0x5F;
/// §14 FIFO_CONFIG2: watermark bits 7:0.
pub const FIFO_CONFIG2: u8 = 0x60;
/// §14 FIFO_CONFIG3: watermark bits 11:8.
pub const FIFO_CONFIG3: u8 = 0x61;
/// §14 INT_CONFIG1: bit 4 INT_ASYNC_RESET (must be cleared for proper INT1 operation).
pub const INT_CONFIG1: u8 = 0x64;
/// §14 INT_SOURCE0: which events drive INT1.
pub const INT_SOURCE0: u8 = 0x65;
/// §14 FIFO_LOST_PKT0: lost-packet count, low byte; FIFO_LOST_PKT1 (high) follows at 0x6D.
pub const FIFO_LOST_PKT0: u8 = 0x6C;
/// §14 SELF_TEST_CONFIG: ACCEL_ST_POWER (bit 6), EN_AZ/AY/AX_ST (bits
/// 5:3), EN_GZ/GY/GX_ST (bits 2:0).
pub const SELF_TEST_CONFIG: u8 = 0x70;
/// §14 WHO_AM_I.
pub const WHO_AM_I: u8 = 0x75;
/// §13 user bank 1: SENSOR_CONFIG0, bits 5:0 disable individual axes.
pub const SENSOR_CONFIG0_BANK1: u8 = 0x03;
/// §13 user bank 1: GYRO_CONFIG_STATIC2 (notch filter and anti-alias filter disables).
pub const GYRO_CONFIG_STATIC2_BANK1: u8 = 0x0B;
/// §13 user bank 1: GYRO_CONFIG_STATIC10, the last of the gyro filter registers.
pub const GYRO_CONFIG_STATIC10_BANK1: u8 = 0x13;
/// §13 user bank 1: TMSTVAL0..2, the timestamp latched by TMST_STROBE (20 bits, little-endian).
pub const TMSTVAL0_BANK1: u8 = 0x62;
/// §13 user bank 1: INTF_CONFIG4..6 (I3C and SPI wiring).
pub const INTF_CONFIG4_BANK1: u8 = 0x7A;
/// §13 user bank 2: ACCEL_CONFIG_STATIC2..4 (accelerometer anti-alias filter).
pub const ACCEL_CONFIG_STATIC2_BANK2: u8 = 0x03;
/// §13 user bank 1: XG_ST_DATA, YG_ST_DATA, ZG_ST_DATA (gyro factory self-test codes).
pub const XG_ST_DATA_BANK1: u8 = 0x5F;
/// §13 user bank 2: XA_ST_DATA, YA_ST_DATA, ZA_ST_DATA (accel factory self-test codes).
pub const XA_ST_DATA_BANK2: u8 = 0x3B;

/// §14 WHO_AM_I: the ICM-42688-P identity.
pub const WHO_AM_I_VALUE: u8 = 0x47;

/// DEVICE_CONFIG bit 0: software reset (self-clearing).
pub const SOFT_RESET_CONFIG: u8 = 1 << 0;

/// FIFO_CONFIG bits 7:6 = 00: bypass (FIFO off).
pub const FIFO_MODE_BYPASS: u8 = 0b00 << 6;
/// FIFO_CONFIG bits 7:6 = 01: stream-to-FIFO.
pub const FIFO_MODE_STREAM: u8 = 0b01 << 6;
/// FIFO_CONFIG mode field.
pub const FIFO_MODE_MASK: u8 = 0b11 << 6;

/// INT_STATUS bit 4: reset done.
pub const RESET_DONE_INT: u8 = 1 << 4;
/// INT_STATUS bit 3: UI data ready.
pub const DATA_RDY_INT: u8 = 1 << 3;
/// INT_STATUS bit 2: FIFO reached the watermark.
pub const FIFO_THS_INT: u8 = 1 << 2;
/// INT_STATUS bit 1: FIFO full (overflowed).
pub const FIFO_FULL_INT: u8 = 1 << 1;

/// SIGNAL_PATH_RESET bit 5: DMP_MEM_RESET_EN (not modelled).
pub const DMP_MEM_RESET_EN: u8 = 1 << 5;
/// SIGNAL_PATH_RESET bit 3: ABORT_AND_RESET, restart the ODR counter (not modelled).
pub const ABORT_AND_RESET: u8 = 1 << 3;
/// SIGNAL_PATH_RESET bit 2: TMST_STROBE, latch the timestamp into TMSTVAL (bank 1).
pub const TMST_STROBE: u8 = 1 << 2;
/// SIGNAL_PATH_RESET bit 1: flush the FIFO.
pub const FIFO_FLUSH: u8 = 1 << 1;

/// INTF_CONFIG0 bit 6: FIFO count (and watermark) in records, not bytes.
pub const FIFO_COUNT_REC: u8 = 1 << 6;
/// INTF_CONFIG0 bit 5: FIFO count big-endian (reset value 1).
pub const FIFO_COUNT_ENDIAN: u8 = 1 << 5;

/// INTF_CONFIG0 bit 4: sensor data big-endian (reset value 1).
pub const SENSOR_DATA_ENDIAN: u8 = 1 << 4;
/// INTF_CONFIG0 bits 1:0 UI_SIFS_CFG.
pub const UI_SIFS_CFG_MASK: u8 = 0b11;
/// UI_SIFS_CFG = 10: SPI disabled.
pub const UI_SIFS_DISABLE_SPI: u8 = 0b10;
/// UI_SIFS_CFG = 11: I²C disabled.
pub const UI_SIFS_DISABLE_I2C: u8 = 0b11;

/// TMST_CONFIG bit 3: TMST_RES, timestamp resolution 16 µs (0: 1 µs).
pub const TMST_RES_16US: u8 = 1 << 3;
/// TMST_CONFIG bit 2: TMST_DELTA_EN, the FIFO timestamp is the time since the previous packet.
pub const TMST_DELTA_EN: u8 = 1 << 2;
/// TMST_CONFIG bit 0: TMST_EN, the timestamp counter runs.
pub const TMST_EN: u8 = 1 << 0;

/// PWR_MGMT0 bits 3:2 = 11: gyro low-noise mode.
pub const GYRO_MODE_LOW_NOISE: u8 = 0b11 << 2;

/// GYRO_CONFIG0 / ACCEL_CONFIG0 ODR field (bits 3:0).
pub const ODR_MASK: u8 = 0x0F;

/// FIFO_CONFIG1 bit 4: FIFO_HIRES_EN, packet 4 (20 bytes, 20-bit data).
pub const FIFO_HIRES_EN: u8 = 1 << 4;
/// FIFO_CONFIG1 bit 1: gyro in FIFO packets.
pub const FIFO_GYRO_EN: u8 = 1 << 1;
/// FIFO_CONFIG1 bit 0: accel in FIFO packets.
pub const FIFO_ACCEL_EN: u8 = 1 << 0;

/// SELF_TEST_CONFIG bit 6: ACCEL_ST_POWER (the accel self-test needs it with EN_A*_ST).
pub const ACCEL_ST_POWER: u8 = 1 << 6;
/// SELF_TEST_CONFIG bit 3: EN_AX_ST (EN_AY_ST, EN_AZ_ST follow).
pub const EN_AX_ST: u8 = 1 << 3;
/// SELF_TEST_CONFIG bit 0: EN_GX_ST (EN_GY_ST, EN_GZ_ST follow).
pub const EN_GX_ST: u8 = 1 << 0;

/// INT_CONFIG1 bit 4: INT_ASYNC_RESET, set at reset.
pub const INT_ASYNC_RESET: u8 = 1 << 4;

/// §6.1 FIFO packets 1 (accel + 8-bit temperature) and 2 (gyro + 8-bit
/// temperature): 8 bytes.
pub const FIFO_PACKET_ONE_SENSOR_LEN: usize = 8;
/// §6.1 FIFO packet 3 (accel + gyro + temperature + timestamp): 16 bytes.
pub const FIFO_PACKET_LEN: usize = 16;
/// §6.1 FIFO packet 4 (20-bit accel and gyro, 16-bit temperature, timestamp): 20 bytes.
pub const FIFO_PACKET_HIRES_LEN: usize = 20;
/// §6: the FIFO holds 2 KiB.
pub const FIFO_BYTES: usize = 2048;
/// The most packets 2 KiB can hold (8-byte packets 1 or 2).
pub const FIFO_MAX_PACKETS: usize = FIFO_BYTES / FIFO_PACKET_ONE_SENSOR_LEN;
/// §6: the FIFO holds 2 KiB, i.e. this many 16-byte packets 3.
pub const FIFO_CAPACITY_PACKETS: u16 = (FIFO_BYTES / FIFO_PACKET_LEN) as u16;
/// §6.2 FIFO header bit 4: HEADER_20, a 20-byte packet 4.
pub const HEADER_20: u8 = 1 << 4;
/// §6.2 FIFO header bit 1: HEADER_ODR_ACCEL, the accel ODR differs from the previous accel packet's.
pub const HEADER_ODR_ACCEL: u8 = 1 << 1;
/// §6.2 FIFO header bit 0: HEADER_ODR_GYRO, the gyro ODR differs from the previous gyro packet's.
pub const HEADER_ODR_GYRO: u8 = 1 << 0;
/// §6.2 FIFO header bit 6: packet holds accel data.
pub const HEADER_ACCEL: u8 = 1 << 6;
/// §6.2 FIFO header bit 5: packet holds gyro data.
pub const HEADER_GYRO: u8 = 1 << 5;
/// §6.2 FIFO header bits 3:2 = 10: packet holds the ODR timestamp.
pub const HEADER_TIMESTAMP_ODR: u8 = 0b10 << 2;

/// §6.1: in packet 4 the accelerometer has 18 bits (bits 19:2 of the 20-bit
/// field, the two lowest 0) at the ±16 g full scale whatever ACCEL_FS_SEL says.
pub const HIRES_ACCEL_LSB_PER_G: f64 = 8192.0;
/// §6.1: in packet 4 the gyroscope has 19 bits (bits 19:1, the lowest 0) at
/// the ±2000 °/s full scale whatever GYRO_FS_SEL says.
pub const HIRES_GYRO_LSB_PER_DPS: f64 = 131.0;
/// Largest 18-bit accel code in packet 4; -131072 would read as the 20-bit
/// invalid marker, so a saturated axis reads ±131071.
pub const HIRES_ACCEL_LIMIT: i32 = (1 << 17) - 1;
/// Largest 19-bit gyro code in packet 4 (see [`HIRES_ACCEL_LIMIT`]).
pub const HIRES_GYRO_LIMIT: i32 = (1 << 18) - 1;
/// §6.1: the 20-bit "no valid data" value.
pub const HIRES_INVALID: i32 = -(1 << 19);

/// §14 TEMP_DATA: temperature sensitivity, LSB per °C (Temp = TEMP_DATA/132.48 + 25).
pub const TEMP_LSB_PER_C: f64 = 132.48;
/// §6.1: FIFO temperature sensitivity, LSB per °C (Temp = FIFO_TEMP_DATA/2.07 + 25).
/// 132.48 / 2.07 = 64 exactly, so a FIFO reading times 64 is on the register scale.
pub const FIFO_TEMP_LSB_PER_C: f64 = 2.07;
/// Temperature at reading 0, °C.
pub const TEMP_OFFSET_C: f64 = 25.0;

/// The default I²C address (AP_AD0 pin low), §9.3; 0x69 with AP_AD0 high.
pub const I2C_ADDRESS_AD0_LOW: u8 = 0x68;
/// The I²C address with AP_AD0 high.
pub const I2C_ADDRESS_AD0_HIGH: u8 = 0x69;

/// The largest output code; -32768 is reserved as the "invalid sample"
/// marker (§6.1), so a saturated axis reads ±32767.
pub const LIMIT_CODE: i16 = 32767;
