//! TDK InvenSense ICM-42688-P 6-axis IMU driver, over SPI or I²C.
//!
//! Datasheet DS-000347. The driver keeps the chip in user bank 0, runs both
//! sensors in low-noise mode, and either reads the data registers on data
//! ready or drains the FIFO on its watermark: 16-byte packets 3 (16-bit
//! data), or with [`FifoConfig::high_resolution`] 20-byte packets 4 (§6.1:
//! 20-bit values, 18 meaningful bits of accelerometer at ±16 g and 19 of
//! gyroscope at ±2000 °/s, whatever ACCEL_FS_SEL and GYRO_FS_SEL say; the
//! driver therefore takes that mode only with those ranges).

pub mod config;
mod registers;
mod self_test;

use embedded_hal::delay::DelayNs;

use self::registers as reg;
use super::chip::{Chip, DataRate};
use super::driver::Driver;
use super::error::Error;
use super::fifo::FifoRead;
use super::interface::RegisterInterface;
use super::{CodeRange, Imu, ImuScale, RawSample};
use crate::units::STANDARD_GRAVITY;

pub use self::config::{AccelRange, Config, FifoConfig, FifoMode, GyroRange, InterruptPin, Odr};
pub use self::registers::{I2C_ADDRESS_AD0_HIGH, I2C_ADDRESS_AD0_LOW};

/// The ICM-42688-P: what differs from the other chips ([`Chip`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Icm42688Chip;

/// An ICM-42688-P behind a register interface `I`.
pub type Icm42688<I> = Driver<Icm42688Chip, I>;

impl Chip for Icm42688Chip {
    const NAME: &'static str = "icm42688";
    /// WHO_AM_I (§14).
    const IDENTITY: u8 = reg::WHO_AM_I_VALUE;
    /// DS-000347 §4.5.
    const SPI_MAX_HZ: u32 = 24_000_000;
    /// AP_AD0 low, then high (§9.3).
    const I2C_ADDRESSES: &'static [u8] = &[I2C_ADDRESS_AD0_LOW, I2C_ADDRESS_AD0_HIGH];
    const MAX_WATERMARK: u16 = reg::FIFO_CAPACITY_PACKETS;
    const WATERMARK_WHAT: &'static str = "FIFO watermark (packets, 1..=128)";
    const TEMP_LSB_PER_C: f64 = reg::TEMP_LSB_PER_C;
    const TEMP_OFFSET_C: f64 = reg::TEMP_OFFSET_C;

    type GyroRange = GyroRange;
    type Odr = Odr;
    type FifoState = ();

    /// ACCEL_CONFIG0 ACCEL_FS_SEL (§14).
    fn accel_code(range: AccelRange) -> u8 {
        config::accel_fs_sel(range)
    }

    /// §3.2 Table 2.
    fn accel_si_per_lsb(range: AccelRange) -> f64 {
        STANDARD_GRAVITY / config::accel_lsb_per_g(range)
    }

    /// ±16 g, ±2000 °/s, 1 kHz, data-ready interrupt, FIFO off: the chip's
    /// reset ranges and rate.
    const DEFAULT_CONFIG: Config = Config {
        accel_range: AccelRange::G16,
        gyro_range: GyroRange::Dps2000,
        accel_odr: Odr::Hz1000,
        gyro_odr: Odr::Hz1000,
        interrupt: InterruptPin::DEFAULT,
        fifo: None,
    };
    const RESET_CONFIG: Config = Self::DEFAULT_CONFIG;

    /// The ranges' scales, or with the high-resolution FIFO its fixed 20-bit one.
    fn scale(config: &Config) -> ImuScale {
        match high_resolution(config) {
            true => config::high_resolution_scale(),
            false => config.range_scale(),
        }
    }

    /// Reads WHO_AM_I (bank 0) without changing anything, unless
    /// REG_BANK_SEL (0x76, readable in every bank) names a user bank other
    /// than 0 — as after a warm restart of the microcontroller — when it
    /// selects bank 0 first and reads again.
    fn identify<I: RegisterInterface>(interface: &mut I) -> Result<u8, I::BusError> {
        let mut read = |register| {
            let mut value = [0];
            interface
                .read_registers(register, &mut value)
                .map(|()| value[0])
        };
        let found = read(reg::WHO_AM_I)?;
        if found == Self::IDENTITY || !(1..=4).contains(&read(reg::REG_BANK_SEL)?) {
            return Ok(found);
        }
        interface.write_register(reg::REG_BANK_SEL, 0)?;
        let mut value = [0];
        interface.read_registers(reg::WHO_AM_I, &mut value)?;
        Ok(value[0])
    }

    /// Ranges, rate, INT1 pin and source, FIFO; both sensors on in low-noise mode.
    fn start<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
        delay: &mut impl DelayNs,
        config: &Config,
    ) -> Result<(), Error<I::BusError>> {
        check_high_resolution(config)?;
        // WHO_AM_I lives in bank 0; after a warm restart the chip may be in another.
        driver.write(reg::REG_BANK_SEL, 0)?;
        driver.expect_identity(reg::WHO_AM_I)?;
        driver.write(reg::DEVICE_CONFIG, reg::SOFT_RESET_CONFIG)?;
        delay.delay_us(reg::SOFT_RESET_WAIT_US);
        let status = driver.read_register(reg::INT_STATUS)?;
        if status & reg::RESET_DONE_INT == 0 {
            return Err(Error::ResetNotDone { status });
        }
        // Count the FIFO (and its watermark) in packets, both big-endian.
        driver.write(
            reg::INTF_CONFIG0,
            reg::FIFO_COUNT_REC | reg::FIFO_COUNT_ENDIAN | reg::SENSOR_DATA_ENDIAN,
        )?;
        driver.write(reg::INT_CONFIG, config::int_config(config.interrupt))?;
        // §14 INT_CONFIG1: INT_ASYNC_RESET must be 0 for INT1 to work.
        driver.write(reg::INT_CONFIG1, 0)?;
        driver.write(
            reg::GYRO_CONFIG0,
            (config.gyro_range.code() << reg::FS_SEL_SHIFT) | config.gyro_odr.code(),
        )?;
        driver.write(
            reg::ACCEL_CONFIG0,
            (config::accel_fs_sel(config.accel_range) << reg::FS_SEL_SHIFT)
                | config.accel_odr.code(),
        )?;
        match config.fifo {
            Some(fifo) => {
                let format = match fifo.high_resolution {
                    true => reg::FIFO_HIRES_EN,
                    false => 0,
                };
                driver.write(
                    reg::FIFO_CONFIG1,
                    reg::FIFO_ACCEL_EN | reg::FIFO_GYRO_EN | reg::FIFO_TEMP_EN | format,
                )?;
                let [high, low] = fifo.watermark.to_be_bytes();
                driver.write(reg::FIFO_CONFIG2, low)?;
                driver.write(reg::FIFO_CONFIG3, high)?;
                let mode = match fifo.mode {
                    FifoMode::StopOnFull => reg::FIFO_MODE_STOP_ON_FULL,
                    FifoMode::Stream => reg::FIFO_MODE_STREAM,
                };
                driver.write(reg::FIFO_CONFIG, mode)?;
                driver.write(reg::INT_SOURCE0, reg::FIFO_THS_INT1_EN)?;
            }
            None => driver.write(reg::INT_SOURCE0, reg::UI_DRDY_INT1_EN)?,
        }
        driver.write(
            reg::PWR_MGMT0,
            reg::GYRO_MODE_LOW_NOISE | reg::ACCEL_MODE_LOW_NOISE,
        )?;
        delay.delay_us(reg::POWER_ON_WAIT_US);
        Ok(())
    }

    /// One burst of 14 bytes from TEMP_DATA1 to GYRO_DATA_Z0. With the
    /// high-resolution FIFO configured, brought to its 20-bit scale (the
    /// registers stay 16-bit: `widen`).
    fn read_sample<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
    ) -> Result<RawSample, Error<I::BusError>> {
        let mut b = [0u8; 14];
        driver.read_registers(reg::TEMP_DATA1, &mut b)?;
        let sample = decode_sample_block(&b);
        Ok(match high_resolution(driver.config()) {
            true => widen(&sample, &config::high_resolution_scale()),
            false => sample,
        })
    }

    /// Reads INT_STATUS and FIFO_COUNT in one burst, then the whole packets
    /// that fit in `out` from FIFO_DATA, 32 packets per transaction. On
    /// FIFO_FULL the lost-packet counter is read and the FIFO flushed.
    fn read_fifo<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
        out: &mut [RawSample],
    ) -> Result<FifoRead, Error<I::BusError>> {
        let mut head = [0u8; 3];
        driver.read_registers(reg::INT_STATUS, &mut head)?;
        let [status, count_high, count_low] = head;
        let count = u16::from_be_bytes([count_high, count_low]);
        let high_resolution = high_resolution(driver.config());
        let capacity = match high_resolution {
            true => reg::FIFO_CAPACITY_HIRES_PACKETS,
            false => reg::FIFO_CAPACITY_PACKETS,
        };
        if count > capacity {
            // More than the FIFO holds: the count cannot be trusted, nor
            // what reading that many would bring. Start the FIFO afresh;
            // what it held is lost, at least the watermark that raised this.
            Self::reset_fifo(driver)?;
            return Ok(FifoRead::impossible_count(driver.config().fifo));
        }
        if status & reg::FIFO_FULL_INT != 0 {
            let mut lost = [0u8; 2];
            driver.read_registers(reg::FIFO_LOST_PKT0, &mut lost)?;
            Self::reset_fifo(driver)?;
            let lost = u32::from(u16::from_le_bytes(lost)) + u32::from(count);
            return Ok(FifoRead::overflowed(lost, false));
        }
        let wanted = usize::from(count).min(out.len());
        match high_resolution {
            true => {
                driver.read_fifo_records(reg::FIFO_DATA, &mut out[..wanted], decode_hires_packet)?
            }
            false => {
                driver.read_fifo_records(reg::FIFO_DATA, &mut out[..wanted], decode_fifo_packet)?
            }
        }
        // `wanted` ≤ `count`, so this fits.
        Ok(FifoRead::drained(wanted, count - wanted as u16))
    }

    fn reset_fifo<I: RegisterInterface>(
        driver: &mut Icm42688<I>,
    ) -> Result<(), Error<I::BusError>> {
        driver.write(reg::SIGNAL_PATH_RESET, reg::FIFO_FLUSH)
    }
}

impl<I: RegisterInterface> Icm42688<I> {
    /// Reads back the ranges and rate the chip holds (GYRO_CONFIG0, ACCEL_CONFIG0)
    /// as (accel range, gyro range, gyro ODR, accel ODR); a field value the
    /// driver does not use reads as `InvalidConfig`.
    pub fn read_ranges(&mut self) -> Result<(AccelRange, GyroRange, Odr, Odr), Error<I::BusError>> {
        let mut b = [0u8; 2];
        self.read_registers(reg::GYRO_CONFIG0, &mut b)?;
        let [gyro, accel] = b;
        let invalid = |what, value: u8| Error::InvalidConfig {
            what,
            value: u32::from(value),
        };
        let gyro_range =
            GyroRange::from_code(gyro >> reg::FS_SEL_SHIFT).ok_or(invalid("GYRO_CONFIG0", gyro))?;
        let accel_range = AccelRange::from_code::<Icm42688Chip>(accel >> reg::FS_SEL_SHIFT)
            .ok_or(invalid("ACCEL_CONFIG0", accel))?;
        let gyro_odr = Odr::from_code(gyro & reg::ODR_MASK).ok_or(invalid("GYRO_CONFIG0", gyro))?;
        let accel_odr =
            Odr::from_code(accel & reg::ODR_MASK).ok_or(invalid("ACCEL_CONFIG0", accel))?;
        Ok((accel_range, gyro_range, gyro_odr, accel_odr))
    }

    /// Reads (and thereby clears) INT_STATUS.
    pub fn read_int_status(&mut self) -> Result<u8, Error<I::BusError>> {
        self.read_register(reg::INT_STATUS)
    }

    /// Reads a sample only if the chip says it is new (INT_STATUS DATA_RDY);
    /// otherwise [`Error::NoNewData`] with the status read. Costs one more
    /// register read than [`Imu::read_sample`]; it detects a stopped chip.
    pub fn read_new_sample(&mut self) -> Result<RawSample, Error<I::BusError>> {
        let status = self.read_int_status()?;
        if status & reg::DATA_RDY_INT == 0 {
            return Err(Error::NoNewData { status });
        }
        self.read_sample()
    }
}

/// Whether `config` reads the high-resolution FIFO.
fn high_resolution(config: &Config) -> bool {
    config.fifo.is_some_and(|f| f.high_resolution)
}

/// Refuses a high-resolution FIFO the chip cannot give as configured: its
/// data are at ±16 g and ±2000 °/s whatever the ranges say (§6.1), so other
/// ranges would be reported and not applied; and 20-byte packets fill the
/// 2 KiB FIFO at 102, not 128.
fn check_high_resolution<E>(config: &Config) -> Result<(), Error<E>> {
    let Some(fifo) = config.fifo.filter(|f| f.high_resolution) else {
        return Ok(());
    };
    if config.accel_range != AccelRange::G16 {
        return Err(Error::InvalidConfig {
            what: "accelerometer range with the high-resolution FIFO (fixed at ±16 g, \
                   DS-000347 §6.1): ACCEL_FS_SEL code",
            value: u32::from(config::accel_fs_sel(config.accel_range)),
        });
    }
    if config.gyro_range != GyroRange::Dps2000 {
        return Err(Error::InvalidConfig {
            what: "gyroscope range with the high-resolution FIFO (fixed at ±2000 °/s, \
                   DS-000347 §6.1): GYRO_FS_SEL code",
            value: u32::from(config.gyro_range.code()),
        });
    }
    if fifo.watermark > reg::FIFO_CAPACITY_HIRES_PACKETS {
        return Err(Error::InvalidConfig {
            what: "FIFO watermark with the high-resolution FIFO (packets, 1..=102)",
            value: u32::from(fifo.watermark),
        });
    }
    Ok(())
}

/// A 16-bit register sample at ±16 g and ±2000 °/s on the 20-bit FIFO's
/// scale (`hires`): each code × 16 (2¹⁵ and 2¹⁹ codes span the same full
/// scale), the limit codes to the 20-bit ones (-32768, "no data" or
/// saturated, to the 20-bit marker; 32767 to the saturated code).
fn widen(sample: &RawSample, hires: &ImuScale) -> RawSample {
    let triad = |v: &[i32; 3], codes: &CodeRange| {
        v.map(|x| match x {
            x if x <= i32::from(i16::MIN) => codes.no_data(),
            x if x >= i32::from(i16::MAX) => codes.high,
            x => x << 4,
        })
    };
    RawSample {
        accel: triad(&sample.accel, &hires.accel.codes),
        gyro: triad(&sample.gyro, &hires.gyro.codes),
        temperature: sample.temperature,
    }
}

/// Decodes the 14-byte TEMP_DATA1..GYRO_DATA_Z0 block (big-endian words).
fn decode_sample_block(b: &[u8; 14]) -> RawSample {
    let w = |i: usize| i16::from_be_bytes([b[2 * i], b[2 * i + 1]]);
    let c = |i: usize| i32::from(w(i));
    RawSample {
        temperature: w(0),
        accel: [c(1), c(2), c(3)],
        gyro: [c(4), c(5), c(6)],
    }
}

/// Decodes one 16-byte FIFO packet 3 (§6.1): header, accel, gyro, 8-bit
/// temperature, timestamp. The temperature is brought to the register
/// scale. A sensor with no new sample in the packet (it runs at the lower
/// rate) reads -32768 on every axis (§6.1; the driver then holds its
/// previous value). `Err`: the header, when the packet is not a packet 3.
fn decode_fifo_packet(p: &[u8; reg::FIFO_PACKET_LEN]) -> Result<RawSample, u8> {
    let header = p[0];
    let expected = reg::HEADER_ACCEL | reg::HEADER_GYRO;
    let mask = reg::HEADER_MSG | reg::HEADER_ACCEL | reg::HEADER_GYRO | reg::HEADER_20;
    if header & mask != expected {
        return Err(header);
    }
    let w = |i: usize| i32::from(i16::from_be_bytes([p[1 + 2 * i], p[2 + 2 * i]]));
    // 132.48 / 2.07 = 64: the FIFO's 8-bit temperature on the 16-bit scale.
    let temperature = i16::from(p[13] as i8) * 64;
    Ok(RawSample {
        accel: [w(0), w(1), w(2)],
        gyro: [w(3), w(4), w(5)],
        temperature,
    })
}

/// Decodes one 20-byte FIFO packet 4 (§6.1): header, bits 19:4 of accel
/// x y z and gyro x y z (big-endian words), 16-bit temperature (the
/// register's scale), timestamp, then bits 3:0 of each axis (accel in the
/// high nibble, gyro in the low). Each axis is its 20-bit value, sign from
/// the word; a sensor with no new sample reads -524288 on every axis (the
/// driver then holds its previous value). `Err`: the header, when the
/// packet is not a packet 4.
fn decode_hires_packet(p: &[u8; reg::FIFO_PACKET_HIRES_LEN]) -> Result<RawSample, u8> {
    let header = p[0];
    let expected = reg::HEADER_ACCEL | reg::HEADER_GYRO | reg::HEADER_20;
    let mask = reg::HEADER_MSG | expected;
    if header & mask != expected {
        return Err(header);
    }
    let value = |word_at: usize, low: u8| {
        (i32::from(i16::from_be_bytes([p[word_at], p[word_at + 1]])) << 4) | i32::from(low & 0x0F)
    };
    let accel = |i: usize| value(1 + 2 * i, p[17 + i] >> 4);
    let gyro = |i: usize| value(7 + 2 * i, p[17 + i]);
    Ok(RawSample {
        accel: [accel(0), accel(1), accel(2)],
        gyro: [gyro(0), gyro(1), gyro(2)],
        temperature: i16::from_be_bytes([p[13], p[14]]),
    })
}
