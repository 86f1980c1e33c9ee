//! ST LSM6DSOX 6-axis IMU driver, over SPI or I²C.
//!
//! Datasheet DS12814. The driver runs both sensors in high-performance mode
//! at one output data rate with block data update, and either reads the
//! output registers on data ready or drains the tagged FIFO on its watermark.

pub mod config;
mod registers;
mod self_test;

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;
use embedded_hal::spi::SpiDevice;

use self::registers as reg;
use super::error::Error;
use super::fifo::{FifoImu, FifoRead};
use super::interface::{I2cInterface, RegisterInterface, SpiInterface};
use super::{Imu, ImuScale, RawSample};

pub use self::config::{AccelRange, Config, FifoConfig, FifoMode, GyroRange, InterruptPin, Odr};
pub use self::registers::{I2C_ADDRESS_SA0_HIGH, I2C_ADDRESS_SA0_LOW};
pub use self::self_test::self_test_max_duration_ms;

/// The chip's name, as the link and the log report it.
pub const NAME: &str = "lsm6dsox";
/// The identity WHO_AM_I holds (DS12814 §9).
pub const IDENTITY: u8 = reg::WHO_AM_I_VALUE;
/// The fastest SPI clock the chip takes, Hz (DS12814 §4.4.1).
pub const SPI_MAX_HZ: u32 = 10_000_000;
/// The chip's I²C addresses: SA0 low, then high (DS12814 §6.3).
pub const I2C_ADDRESSES: [u8; 2] = [I2C_ADDRESS_SA0_LOW, I2C_ADDRESS_SA0_HIGH];

/// Reads the chip's identity register (WHO_AM_I); changes nothing.
pub fn identify<I: RegisterInterface>(interface: &mut I) -> Result<u8, I::BusError> {
    let mut value = [0];
    interface.read_registers(reg::WHO_AM_I, &mut value)?;
    Ok(value[0])
}

/// Samples read per FIFO bus transaction: 32 × 2 words × 7 B = 448 B of stack.
const FIFO_CHUNK_SAMPLES: usize = 32;
/// Largest watermark in samples: WTM has 9 bits of words, two words per sample.
const MAX_WATERMARK_SAMPLES: u16 = 255;

/// An LSM6DSOX behind a register interface `I`.
#[derive(Debug)]
pub struct Lsm6dsox<I> {
    interface: I,
    config: Config,
}

impl<SPI: SpiDevice> Lsm6dsox<SpiInterface<SPI>> {
    /// A driver for a chip on SPI (mode 0 or 3, up to 10 MHz, DS12814 §6.1).
    pub fn new_spi(spi: SPI) -> Self {
        Self::new(SpiInterface::new(spi))
    }
}

impl<I2C: I2c> Lsm6dsox<I2cInterface<I2C>> {
    /// A driver for a chip on I²C at `address` (0x6A with SA0 low, 0x6B high).
    pub fn new_i2c(i2c: I2C, address: u8) -> Self {
        Self::new(I2cInterface::new(i2c, address))
    }
}

impl<I: RegisterInterface> Lsm6dsox<I> {
    /// A driver over any register interface. The chip is untouched until [`Self::init`].
    pub fn new(interface: I) -> Self {
        Self {
            interface,
            config: Config {
                // The reset ranges, so `scale` is right before `init` too.
                accel_range: AccelRange::G2,
                gyro_range: GyroRange::Dps250,
                ..Config::default()
            },
        }
    }

    /// The configuration last applied.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The register interface.
    pub fn interface_mut(&mut self) -> &mut I {
        &mut self.interface
    }

    /// The bus (e.g. the chip model, whose clock the emulated board advances).
    pub fn bus_mut(&mut self) -> &mut I::Bus {
        self.interface.bus_mut()
    }

    /// The bus, shared.
    pub fn bus(&self) -> &I::Bus {
        self.interface.bus()
    }

    /// Gives the bus back.
    pub fn release(self) -> I::Bus {
        self.interface.release()
    }

    /// Gives the register interface back.
    pub fn into_interface(self) -> I {
        self.interface
    }

    /// Checks the identity, soft-resets, and applies `config`: interrupt pin,
    /// FIFO, ranges and rate (a non-zero rate turns each sensor on).
    pub fn init(
        &mut self,
        delay: &mut impl DelayNs,
        config: &Config,
    ) -> Result<(), Error<I::BusError>> {
        if let Some(fifo) = config.fifo {
            if fifo.watermark == 0 || fifo.watermark > MAX_WATERMARK_SAMPLES {
                return Err(Error::InvalidConfig {
                    what: "FIFO watermark (samples, 1..=255)",
                    value: u32::from(fifo.watermark),
                });
            }
        }
        let found = self.read_register(reg::WHO_AM_I)?;
        if found != reg::WHO_AM_I_VALUE {
            return Err(Error::WrongChip {
                expected: reg::WHO_AM_I_VALUE,
                found,
            });
        }
        self.write(reg::CTRL3_C, reg::IF_INC | reg::SW_RESET)?;
        delay.delay_us(reg::SW_RESET_WAIT_US);
        let status = self.read_register(reg::CTRL3_C)?;
        if status & reg::SW_RESET != 0 {
            return Err(Error::ResetNotDone { status });
        }
        self.write(reg::CTRL3_C, config::ctrl3_c(config.interrupt))?;
        let pulsed = if config.interrupt.latched {
            0
        } else {
            reg::DATAREADY_PULSED
        };
        self.write(reg::COUNTER_BDR_REG1, pulsed)?;
        let odr = config.odr.code();
        match config.fifo {
            Some(fifo) => {
                let [high, low] = (fifo.watermark * reg::WORDS_PER_SAMPLE).to_be_bytes();
                self.write(reg::FIFO_CTRL1, low)?;
                self.write(reg::FIFO_CTRL2, high & 0x01)?;
                self.write(reg::FIFO_CTRL3, (odr << reg::ODR_SHIFT) | odr)?;
                self.write(reg::FIFO_CTRL4, fifo_mode_bits(fifo.mode))?;
                self.write(reg::INT1_CTRL, reg::INT1_FIFO_TH)?;
            }
            None => self.write(reg::INT1_CTRL, reg::INT1_DRDY_G)?,
        }
        self.write(
            reg::CTRL1_XL,
            (odr << reg::ODR_SHIFT) | (config.accel_range.code() << reg::FS_SHIFT),
        )?;
        self.write(
            reg::CTRL2_G,
            (odr << reg::ODR_SHIFT) | config.gyro_range.bits(),
        )?;
        self.config = *config;
        Ok(())
    }

    /// Reads back the ranges and rates the chip holds (CTRL1_XL, CTRL2_G) as
    /// (accel range, gyro range, gyro ODR, accel ODR); a power-down or
    /// low-power-only rate reads as `InvalidConfig`.
    pub fn read_ranges(&mut self) -> Result<(AccelRange, GyroRange, Odr, Odr), Error<I::BusError>> {
        let mut b = [0u8; 2];
        self.interface
            .read_registers(reg::CTRL1_XL, &mut b)
            .map_err(Error::Bus)?;
        let [ctrl1_xl, ctrl2_g] = b;
        let invalid = |what, value: u8| Error::InvalidConfig {
            what,
            value: u32::from(value),
        };
        // FS_XL is 2 bits: every value is a range.
        let accel_range = AccelRange::from_code((ctrl1_xl >> reg::FS_SHIFT) & 0b11)
            .ok_or(invalid("CTRL1_XL", ctrl1_xl))?;
        let gyro_range = GyroRange::from_bits(ctrl2_g);
        let gyro_odr =
            Odr::from_code(ctrl2_g >> reg::ODR_SHIFT).ok_or(invalid("CTRL2_G", ctrl2_g))?;
        let accel_odr =
            Odr::from_code(ctrl1_xl >> reg::ODR_SHIFT).ok_or(invalid("CTRL1_XL", ctrl1_xl))?;
        Ok((accel_range, gyro_range, gyro_odr, accel_odr))
    }

    /// Reads STATUS_REG (XLDA, GDA, TDA).
    pub fn read_status(&mut self) -> Result<u8, Error<I::BusError>> {
        self.read_register(reg::STATUS_REG)
    }

    /// Reads a sample only if STATUS_REG says both accel and gyro are new;
    /// otherwise [`Error::NoNewData`] with the status read.
    pub fn read_new_sample(&mut self) -> Result<RawSample, Error<I::BusError>> {
        let status = self.read_status()?;
        if status & (reg::XLDA | reg::GDA) != reg::XLDA | reg::GDA {
            return Err(Error::NoNewData { status });
        }
        self.read_sample()
    }

    fn write(&mut self, register: u8, value: u8) -> Result<(), Error<I::BusError>> {
        self.interface
            .write_register(register, value)
            .map_err(Error::Bus)
    }

    fn read_register(&mut self, register: u8) -> Result<u8, Error<I::BusError>> {
        let mut b = [0u8];
        self.interface
            .read_registers(register, &mut b)
            .map_err(Error::Bus)?;
        Ok(b[0])
    }
}

/// FIFO_CTRL4 FIFO_MODE for a [`FifoMode`].
fn fifo_mode_bits(mode: FifoMode) -> u8 {
    match mode {
        FifoMode::StopOnFull => reg::FIFO_MODE_FIFO,
        FifoMode::Stream => reg::FIFO_MODE_CONTINUOUS,
    }
}

/// Three little-endian words.
fn triad_le(b: &[u8]) -> [i16; 3] {
    let w = |i: usize| i16::from_le_bytes([b[2 * i], b[2 * i + 1]]);
    [w(0), w(1), w(2)]
}

/// Decodes one gyro + accel pair of FIFO words (either order).
fn decode_fifo_pair(words: &[u8], temperature: i16) -> Result<RawSample, u8> {
    let mut sample = RawSample {
        temperature,
        ..RawSample::default()
    };
    let (mut gyro, mut accel) = (false, false);
    for word in words.chunks_exact(reg::FIFO_WORD_LEN) {
        let tag = word[0];
        match tag >> reg::TAG_SENSOR_SHIFT {
            reg::TAG_GYRO if !gyro => {
                sample.gyro = triad_le(&word[1..]);
                gyro = true;
            }
            reg::TAG_ACCEL if !accel => {
                sample.accel = triad_le(&word[1..]);
                accel = true;
            }
            _ => return Err(tag),
        }
    }
    Ok(sample)
}

impl<I: RegisterInterface> Imu for Lsm6dsox<I> {
    type Error = Error<I::BusError>;

    /// One burst of 14 bytes from OUT_TEMP_L to OUTZ_H_A.
    fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
        let mut b = [0u8; 14];
        self.interface
            .read_registers(reg::OUT_TEMP_L, &mut b)
            .map_err(Error::Bus)?;
        Ok(RawSample {
            temperature: i16::from_le_bytes([b[0], b[1]]),
            gyro: triad_le(&b[2..8]),
            accel: triad_le(&b[8..14]),
        })
    }

    fn scale(&self) -> ImuScale {
        self.config.scale()
    }
}

impl<I: RegisterInterface> FifoImu for Lsm6dsox<I> {
    /// Reads FIFO_STATUS1/2 in one burst; on overrun resets the FIFO (bypass,
    /// then the configured mode again) and reports the discarded samples as a
    /// lower bound of the loss (the chip does not count what it dropped).
    /// Otherwise reads OUT_TEMP (the FIFO carries no temperature here) and the
    /// whole gyro + accel word pairs that fit in `out`, 32 samples per transaction.
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error> {
        let mut status = [0u8; 2];
        self.interface
            .read_registers(reg::FIFO_STATUS1, &mut status)
            .map_err(Error::Bus)?;
        let words = u16::from_le_bytes([status[0], status[1] & reg::DIFF_FIFO_HIGH_MASK]);
        let available = words / reg::WORDS_PER_SAMPLE;
        if words > reg::FIFO_CAPACITY_WORDS {
            // More than the FIFO holds: the count cannot be trusted, nor
            // what reading that many would bring. Start the FIFO afresh;
            // what it held is lost, at least the watermark that raised this.
            self.reset_fifo()?;
            return Ok(FifoRead::impossible_count(self.config.fifo));
        }
        if status[1] & (reg::FIFO_OVR_IA | reg::FIFO_OVR_LATCHED) != 0 {
            self.reset_fifo()?;
            return Ok(FifoRead {
                samples: 0,
                remaining: 0,
                overflowed: true,
                lost: u32::from(available),
                lost_is_lower_bound: true,
            });
        }
        let wanted = usize::from(available).min(out.len());
        if wanted == 0 {
            return Ok(FifoRead {
                remaining: available,
                ..FifoRead::default()
            });
        }
        let mut t = [0u8; 2];
        self.interface
            .read_registers(reg::OUT_TEMP_L, &mut t)
            .map_err(Error::Bus)?;
        let temperature = i16::from_le_bytes(t);
        const PAIR: usize = 2 * reg::FIFO_WORD_LEN;
        let mut buffer = [0u8; FIFO_CHUNK_SAMPLES * PAIR];
        let mut done = 0;
        while done < wanted {
            let samples = (wanted - done).min(FIFO_CHUNK_SAMPLES);
            let bytes = &mut buffer[..samples * PAIR];
            self.interface
                .read_registers(reg::FIFO_DATA_OUT_TAG, bytes)
                .map_err(Error::Bus)?;
            for (pair, slot) in bytes.chunks_exact(PAIR).zip(out[done..].iter_mut()) {
                *slot = decode_fifo_pair(pair, temperature)
                    .map_err(|header| Error::BadFifoPacket { header })?;
            }
            done += samples;
        }
        Ok(FifoRead {
            samples: wanted,
            // `wanted` ≤ `available`, so this fits.
            remaining: available - wanted as u16,
            overflowed: false,
            lost: 0,
            lost_is_lower_bound: false,
        })
    }

    /// Bypass mode empties the FIFO; the configured mode then restarts it.
    fn reset_fifo(&mut self) -> Result<(), Self::Error> {
        self.write(reg::FIFO_CTRL4, reg::FIFO_MODE_BYPASS)?;
        if let Some(fifo) = self.config.fifo {
            self.write(reg::FIFO_CTRL4, fifo_mode_bits(fifo.mode))?;
        }
        Ok(())
    }
}
