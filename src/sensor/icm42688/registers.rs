//! ICM-42688-P register addresses and bit fields.
//!
//! Source: TDK InvenSense ICM-42688-P datasheet DS-000347 (rev 1.6):
//! §13 "Register map" for addresses and reset values, §14 "User bank 0
//! register map – descriptions" for the bit fields, §6 "FIFO" for packets.
//! All registers below are in user bank 0 unless noted.

/// §13: bank selection, reachable from every bank (bits 2:0).
pub const REG_BANK_SEL: u8 = 0x76;
/// §14 DEVICE_CONFIG: bit 0 SOFT_RESET_CONFIG.
pub const DEVICE_CONFIG: u8 = 0x11;
/// §14 INT_CONFIG: INT1 mode, drive circuit and polarity.
pub const INT_CONFIG: u8 = 0x14;
/// §14 FIFO_CONFIG: bits 7:6 FIFO_MODE.
pub const FIFO_CONFIG: u8 = 0x16;
/// §14 TEMP_DATA1: first byte of the 14-byte sample block (temperature,
/// accel x/y/z, gyro x/y/z, each big-endian) that ends at GYRO_DATA_Z0 (0x2A).
pub const TEMP_DATA1: u8 = 0x1D;
/// §14 ACCEL_DATA_X1: first of the six accel output bytes (x, y, z big-endian).
pub const ACCEL_DATA_X1: u8 = 0x1F;
/// §14 GYRO_DATA_X1: first of the six gyro output bytes (x, y, z big-endian).
pub const GYRO_DATA_X1: u8 = 0x25;
/// §14 INT_STATUS: interrupt status, cleared on read.
pub const INT_STATUS: u8 = 0x2D;
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
/// §14 GYRO_CONFIG1: bits 3:2 GYRO_UI_FILT_ORD, bits 1:0 GYRO_DEC2_M2_ORD.
pub const GYRO_CONFIG1: u8 = 0x51;
/// §14 GYRO_ACCEL_CONFIG0: bits 7:4 ACCEL_UI_FILT_BW, bits 3:0 GYRO_UI_FILT_BW.
pub const GYRO_ACCEL_CONFIG0: u8 = 0x52;
/// §14 ACCEL_CONFIG1: bits 4:3 ACCEL_UI_FILT_ORD, bits 2:1 ACCEL_DEC2_M2_ORD.
pub const ACCEL_CONFIG1: u8 = 0x53;
/// §14 FIFO_CONFIG1: which sensors go into the FIFO.
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
/// §13 (user bank 1) XG_ST_DATA: the gyro x factory self-test code; YG_ST_DATA
/// and ZG_ST_DATA follow at 0x60, 0x61.
pub const XG_ST_DATA_BANK1: u8 = 0x5F;
/// §13 (user bank 2) XA_ST_DATA: the accel x factory self-test code; YA_ST_DATA
/// and ZA_ST_DATA follow at 0x3C, 0x3D.
pub const XA_ST_DATA_BANK2: u8 = 0x3B;

/// §14 WHO_AM_I: the ICM-42688-P identity.
pub const WHO_AM_I_VALUE: u8 = 0x47;

/// DEVICE_CONFIG bit 0: software reset (self-clearing).
pub const SOFT_RESET_CONFIG: u8 = 1 << 0;
/// §14 DEVICE_CONFIG: wait 1 ms after a soft reset before any register access.
pub const SOFT_RESET_WAIT_US: u32 = 1_000;

/// INT_CONFIG bit 2: INT1 latched (1) or pulsed (0).
pub const INT1_MODE_LATCHED: u8 = 1 << 2;
/// INT_CONFIG bit 1: INT1 push-pull (1) or open drain (0).
pub const INT1_DRIVE_PUSH_PULL: u8 = 1 << 1;
/// INT_CONFIG bit 0: INT1 active high (1) or low (0).
pub const INT1_POLARITY_HIGH: u8 = 1 << 0;

/// FIFO_CONFIG bits 7:6 = 01: stream-to-FIFO.
pub const FIFO_MODE_STREAM: u8 = 0b01 << 6;
/// FIFO_CONFIG bits 7:6 = 10: stop-on-full.
pub const FIFO_MODE_STOP_ON_FULL: u8 = 0b10 << 6;

/// INT_STATUS bit 4: reset done.
pub const RESET_DONE_INT: u8 = 1 << 4;
/// INT_STATUS bit 3: UI data ready.
pub const DATA_RDY_INT: u8 = 1 << 3;
/// INT_STATUS bit 1: FIFO full (overflowed).
pub const FIFO_FULL_INT: u8 = 1 << 1;

/// SIGNAL_PATH_RESET bit 1: flush the FIFO.
pub const FIFO_FLUSH: u8 = 1 << 1;

/// INTF_CONFIG0 bit 6: FIFO count (and watermark) in records, not bytes.
pub const FIFO_COUNT_REC: u8 = 1 << 6;
/// INTF_CONFIG0 bit 5: FIFO count big-endian (reset value 1).
pub const FIFO_COUNT_ENDIAN: u8 = 1 << 5;
/// INTF_CONFIG0 bit 4: sensor data big-endian (reset value 1).
pub const SENSOR_DATA_ENDIAN: u8 = 1 << 4;

/// PWR_MGMT0 bits 3:2 = 11: gyro low-noise mode.
pub const GYRO_MODE_LOW_NOISE: u8 = 0b11 << 2;
/// PWR_MGMT0 bits 1:0 = 11: accel low-noise mode.
pub const ACCEL_MODE_LOW_NOISE: u8 = 0b11;
/// §14 PWR_MGMT0: no register write for 200 µs after turning a sensor on.
pub const POWER_ON_WAIT_US: u32 = 200;
/// §14 DATA registers: -32768 marks an invalid sample (sensor not yet producing).
pub const INVALID_SAMPLE: i16 = i16::MIN;

/// PWR_MGMT0 bits 3:0: both sensors' modes (00: off).
pub const SENSOR_MODES_MASK: u8 = 0x0F;

/// GYRO_CONFIG1 GYRO_UI_FILT_ORD field (bits 3:2).
pub const GYRO_UI_FILT_ORD_MASK: u8 = 0b11 << 2;
/// GYRO_UI_FILT_ORD = 10: third-order UI filter.
pub const GYRO_UI_FILT_ORD_3RD: u8 = 0b10 << 2;
/// ACCEL_CONFIG1 ACCEL_UI_FILT_ORD field (bits 4:3).
pub const ACCEL_UI_FILT_ORD_MASK: u8 = 0b11 << 3;
/// ACCEL_UI_FILT_ORD = 10: third-order UI filter.
pub const ACCEL_UI_FILT_ORD_3RD: u8 = 0b10 << 3;
/// GYRO_ACCEL_CONFIG0 GYRO_UI_FILT_BW field (bits 3:0).
pub const GYRO_UI_FILT_BW_MASK: u8 = 0x0F;
/// GYRO_UI_FILT_BW = 4: bandwidth max(400 Hz, ODR)/10.
pub const GYRO_UI_FILT_BW_ODR_10: u8 = 4;
/// GYRO_ACCEL_CONFIG0 ACCEL_UI_FILT_BW field (bits 7:4).
pub const ACCEL_UI_FILT_BW_MASK: u8 = 0xF0;
/// ACCEL_UI_FILT_BW = 4: bandwidth max(400 Hz, ODR)/10.
pub const ACCEL_UI_FILT_BW_ODR_10: u8 = 4 << 4;

/// SELF_TEST_CONFIG bits 2:0: gyro self-test on x, y, z.
pub const EN_G_ST: u8 = 0b111;
/// SELF_TEST_CONFIG bits 5:3: accel self-test on x, y, z.
pub const EN_A_ST: u8 = 0b111 << 3;
/// SELF_TEST_CONFIG bit 6: power for the accel self-test (set with EN_A_ST).
pub const ACCEL_ST_POWER: u8 = 1 << 6;

/// GYRO_CONFIG0 / ACCEL_CONFIG0 full-scale field position (bits 7:5).
pub const FS_SEL_SHIFT: u8 = 5;
/// GYRO_CONFIG0 / ACCEL_CONFIG0 ODR field (bits 3:0).
pub const ODR_MASK: u8 = 0x0F;

/// FIFO_CONFIG1 bit 4: FIFO_HIRES_EN, 20-byte packets 4 with 20-bit data (§6.1).
pub const FIFO_HIRES_EN: u8 = 1 << 4;
/// FIFO_CONFIG1 bit 2: temperature in FIFO packets.
pub const FIFO_TEMP_EN: u8 = 1 << 2;
/// FIFO_CONFIG1 bit 1: gyro in FIFO packets.
pub const FIFO_GYRO_EN: u8 = 1 << 1;
/// FIFO_CONFIG1 bit 0: accel in FIFO packets.
pub const FIFO_ACCEL_EN: u8 = 1 << 0;

/// INT_SOURCE0 bit 3: data ready drives INT1.
pub const UI_DRDY_INT1_EN: u8 = 1 << 3;
/// INT_SOURCE0 bit 2: FIFO watermark drives INT1.
pub const FIFO_THS_INT1_EN: u8 = 1 << 2;

/// §6.1 FIFO packet 3 (accel + gyro + temperature + timestamp): 16 bytes.
pub const FIFO_PACKET_LEN: usize = 16;
/// §6: the FIFO holds 2 KiB, i.e. this many 16-byte packets.
pub const FIFO_CAPACITY_PACKETS: u16 = 2048 / FIFO_PACKET_LEN as u16;
/// §6.1 FIFO packet 4 (header, accel and gyro bits 19:4, 16-bit
/// temperature, timestamp, then bits 3:0 of each axis): 20 bytes.
pub const FIFO_PACKET_HIRES_LEN: usize = 20;
/// §6: the 2 KiB FIFO holds this many 20-byte packets 4.
pub const FIFO_CAPACITY_HIRES_PACKETS: u16 = 2048 / FIFO_PACKET_HIRES_LEN as u16;
/// §6.1 packet 4: the accelerometer's 20-bit value has 18 meaningful bits
/// (bits 1:0 read 0) at ±16 g whatever ACCEL_FS_SEL says, 8192 LSB/g of the
/// 18-bit value: 32768 per unit of the 20-bit value the driver delivers.
pub const HIRES_ACCEL_LSB_PER_G: f64 = 8192.0 * 4.0;
/// §6.1 packet 4: the gyroscope's 20-bit value has 19 meaningful bits (bit 0
/// reads 0) at ±2000 °/s whatever GYRO_FS_SEL says, 131 LSB/(°/s) of the
/// 19-bit value: 262 per unit of the 20-bit value.
pub const HIRES_GYRO_LSB_PER_DPS: f64 = 131.0 * 2.0;
/// The largest 20-bit accelerometer code (18 bits, shifted left by 2; the
/// most negative 18-bit code reads as the "no data" marker, so a saturated
/// axis reads ± this).
pub const HIRES_ACCEL_LIMIT: i32 = ((1 << 17) - 1) << 2;
/// The largest 20-bit gyroscope code (19 bits, shifted left by 1).
pub const HIRES_GYRO_LIMIT: i32 = ((1 << 18) - 1) << 1;
/// §6.1: the 20-bit "no valid data" value, -524288; its magnitude bounds every 20-bit code.
pub const HIRES_MAGNITUDE: u32 = 1 << 19;
/// §6.2 FIFO header bit 7: FIFO empty / invalid packet.
pub const HEADER_MSG: u8 = 1 << 7;
/// §6.2 FIFO header bit 6: packet holds accel data.
pub const HEADER_ACCEL: u8 = 1 << 6;
/// §6.2 FIFO header bit 5: packet holds gyro data.
pub const HEADER_GYRO: u8 = 1 << 5;
/// §6.2 FIFO header bit 4: 20-bit (high resolution) packet.
pub const HEADER_20: u8 = 1 << 4;

/// §14 TEMP_DATA: temperature sensitivity, LSB per °C (Temp = TEMP_DATA/132.48 + 25).
pub const TEMP_LSB_PER_C: f64 = 132.48;
/// Temperature at reading 0, °C.
pub const TEMP_OFFSET_C: f64 = 25.0;

/// The default I²C address (AP_AD0 pin low), §9.3; 0x69 with AP_AD0 high.
pub const I2C_ADDRESS_AD0_LOW: u8 = 0x68;
/// The I²C address with AP_AD0 high.
pub const I2C_ADDRESS_AD0_HIGH: u8 = 0x69;
