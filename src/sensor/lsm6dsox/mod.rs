//! ST LSM6DSOX 6-axis IMU driver, over SPI or I²C.
//!
//! Datasheet DS12814. The driver runs both sensors in high-performance mode
//! at one output data rate with block data update, and either reads the
//! output registers on data ready or drains the tagged FIFO on its watermark.

pub mod config;
mod registers;
mod self_test;
mod tagged_fifo;

use embedded_hal::delay::DelayNs;

use self::registers as reg;
use self::tagged_fifo::{Rates, TaggedFifo};
use super::chip::{Chip, DataRate};
use super::driver::Driver;
use super::error::Error;
use super::fifo::FifoRead;
use super::interface::RegisterInterface;
use super::{Imu, RawSample};
use crate::units::STANDARD_GRAVITY;

pub use self::config::{AccelRange, Config, FifoConfig, FifoMode, GyroRange, InterruptPin, Odr};
pub use self::registers::{I2C_ADDRESS_SA0_HIGH, I2C_ADDRESS_SA0_LOW};

/// The LSM6DSOX: what differs from the other chips ([`Chip`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lsm6dsoxChip;

/// An LSM6DSOX behind a register interface `I`.
pub type Lsm6dsox<I> = Driver<Lsm6dsoxChip, I>;

impl Chip for Lsm6dsoxChip {
    const NAME: &'static str = "lsm6dsox";
    /// WHO_AM_I (DS12814 §9).
    const IDENTITY: u8 = reg::WHO_AM_I_VALUE;
    /// DS12814 §4.4.1.
    const SPI_MAX_HZ: u32 = 10_000_000;
    /// SA0 low, then high (DS12814 §6.3).
    const I2C_ADDRESSES: &'static [u8] = &[I2C_ADDRESS_SA0_LOW, I2C_ADDRESS_SA0_HIGH];
    /// WTM has 9 bits of words, two words per sample.
    const MAX_WATERMARK: u16 = 255;
    const WATERMARK_WHAT: &'static str = "FIFO watermark (samples, 1..=255)";
    const TEMP_LSB_PER_C: f64 = reg::TEMP_LSB_PER_C;
    const TEMP_OFFSET_C: f64 = reg::TEMP_OFFSET_C;

    type GyroRange = GyroRange;
    type Odr = Odr;
    type FifoState = TaggedFifo;

    /// CTRL1_XL FS_XL (§9).
    fn accel_code(range: AccelRange) -> u8 {
        config::accel_fs_xl(range)
    }

    /// §4.1 Table 2.
    fn accel_si_per_lsb(range: AccelRange) -> f64 {
        config::accel_mg_per_lsb(range) * 1e-3 * STANDARD_GRAVITY
    }

    /// ±16 g, ±2000 °/s, 833 Hz, data-ready interrupt, FIFO off.
    const DEFAULT_CONFIG: Config = Config {
        accel_range: AccelRange::G16,
        gyro_range: GyroRange::Dps2000,
        accel_odr: Odr::Hz833,
        gyro_odr: Odr::Hz833,
        interrupt: InterruptPin::DEFAULT,
        fifo: None,
    };
    /// The reset ranges (±2 g, ±250 °/s).
    const RESET_CONFIG: Config = Config {
        accel_range: AccelRange::G2,
        gyro_range: GyroRange::Dps250,
        ..Self::DEFAULT_CONFIG
    };

    /// Reads WHO_AM_I; changes nothing.
    fn identify<I: RegisterInterface>(interface: &mut I) -> Result<u8, I::BusError> {
        let mut value = [0];
        interface.read_registers(reg::WHO_AM_I, &mut value)?;
        Ok(value[0])
    }

    /// Interrupt pin, FIFO, ranges and rate (a non-zero rate turns each sensor on).
    fn start<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
        delay: &mut impl DelayNs,
        config: &Config,
    ) -> Result<(), Error<I::BusError>> {
        if config.fifo.is_some_and(|f| f.high_resolution) {
            return Err(Error::InvalidConfig {
                what: "high-resolution FIFO (the LSM6DSOX's FIFO words are 16-bit): FIFO watermark",
                value: config.fifo.map_or(0, |f| u32::from(f.watermark)),
            });
        }
        driver.expect_identity(reg::WHO_AM_I)?;
        driver.write(reg::CTRL3_C, reg::IF_INC | reg::SW_RESET)?;
        delay.delay_us(reg::SW_RESET_WAIT_US);
        let status = driver.read_register(reg::CTRL3_C)?;
        if status & reg::SW_RESET != 0 {
            return Err(Error::ResetNotDone { status });
        }
        driver.write(reg::CTRL3_C, config::ctrl3_c(config.interrupt))?;
        let pulsed = if config.interrupt.latched {
            0
        } else {
            reg::DATAREADY_PULSED
        };
        driver.write(reg::COUNTER_BDR_REG1, pulsed)?;
        let (accel_odr, gyro_odr) = (config.accel_odr.code(), config.gyro_odr.code());
        match config.fifo {
            Some(fifo) => {
                let [high, low] = watermark_words(config, fifo.watermark).to_be_bytes();
                driver.write(reg::FIFO_CTRL1, low)?;
                driver.write(reg::FIFO_CTRL2, high & 0x01)?;
                // BDR_GY in bits 7:4, BDR_XL in 3:0: each sensor batched at its ODR.
                driver.write(reg::FIFO_CTRL3, (gyro_odr << reg::ODR_SHIFT) | accel_odr)?;
                driver.write(reg::FIFO_CTRL4, fifo_mode_bits(fifo.mode))?;
                driver.write(reg::INT1_CTRL, reg::INT1_FIFO_TH)?;
            }
            // Data ready of the faster sensor: one interrupt per sample delivered.
            None if config.accel_odr.hz() > config.gyro_odr.hz() => {
                driver.write(reg::INT1_CTRL, reg::INT1_DRDY_XL)?
            }
            None => driver.write(reg::INT1_CTRL, reg::INT1_DRDY_G)?,
        }
        driver.write(
            reg::CTRL1_XL,
            (accel_odr << reg::ODR_SHIFT)
                | (config::accel_fs_xl(config.accel_range) << reg::FS_SHIFT),
        )?;
        driver.write(
            reg::CTRL2_G,
            (gyro_odr << reg::ODR_SHIFT) | config.gyro_range.bits(),
        )?;
        Ok(())
    }

    /// One burst of 14 bytes from OUT_TEMP_L to OUTZ_H_A.
    ///
    /// With the two sensors at different rates, STATUS_REG first: a triad
    /// whose XLDA or GDA is clear keeps its previous value, -32768 on
    /// every axis before its first sample (the output registers' reset
    /// value, 0, would pass for a measurement; docs/PROTOCOL.md §22).
    fn read_sample<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
    ) -> Result<RawSample, Error<I::BusError>> {
        let two_rates = driver.config.accel_odr != driver.config.gyro_odr;
        let status = match two_rates {
            true => driver.read_register(reg::STATUS_REG)?,
            false => reg::XLDA | reg::GDA,
        };
        let mut b = [0u8; 14];
        driver.read_registers(reg::OUT_TEMP_L, &mut b)?;
        let sample = RawSample {
            temperature: i16::from_le_bytes([b[0], b[1]]),
            gyro: triad_le(&b[2..8]),
            accel: triad_le(&b[8..14]),
        };
        if !two_rates {
            return Ok(sample);
        }
        let held = &mut driver.held;
        held.temperature = sample.temperature;
        if status & reg::XLDA != 0 {
            held.accel = sample.accel;
        }
        if status & reg::GDA != 0 {
            held.gyro = sample.gyro;
        }
        Ok(*held)
    }

    /// Reads FIFO_STATUS1/2 in one burst; on overrun resets the FIFO (bypass,
    /// then the configured mode again) and reports the discarded samples as a
    /// lower bound of the loss (the chip does not count what it dropped).
    /// Otherwise reads OUT_TEMP (the FIFO carries no temperature here) and the
    /// whole gyro + accel word pairs that fit in `out`, 32 samples per transaction.
    fn read_fifo<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
        out: &mut [RawSample],
    ) -> Result<FifoRead, Error<I::BusError>> {
        let mut status = [0u8; 2];
        driver.read_registers(reg::FIFO_STATUS1, &mut status)?;
        let words = u16::from_le_bytes([status[0], status[1] & reg::DIFF_FIFO_HIGH_MASK]);
        let rates = rates(driver.config());
        let available = match rates {
            Some(rates) => driver.fifo_state.slots_waiting(words, rates),
            None => words / reg::WORDS_PER_SAMPLE,
        };
        if words > reg::FIFO_CAPACITY_WORDS {
            // More than the FIFO holds: the count cannot be trusted, nor
            // what reading that many would bring. Start the FIFO afresh;
            // what it held is lost, at least the watermark that raised this.
            Self::reset_fifo(driver)?;
            return Ok(FifoRead::impossible_count(driver.config().fifo));
        }
        if status[1] & (reg::FIFO_OVR_IA | reg::FIFO_OVR_LATCHED) != 0 {
            Self::reset_fifo(driver)?;
            return Ok(FifoRead::overflowed(u32::from(available), true));
        }
        if let Some(rates) = rates {
            return Self::read_fifo_slots(driver, out, words, rates);
        }
        let wanted = usize::from(available).min(out.len());
        if wanted == 0 {
            return Ok(FifoRead::drained(0, available));
        }
        let temperature = Self::read_temperature(driver)?;
        driver.read_fifo_records(reg::FIFO_DATA_OUT_TAG, &mut out[..wanted], |pair| {
            decode_fifo_pair(pair, temperature)
        })?;
        // `wanted` ≤ `available`, so this fits.
        Ok(FifoRead::drained(wanted, available - wanted as u16))
    }

    /// Bypass mode empties the FIFO; the configured mode then restarts it.
    fn reset_fifo<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
    ) -> Result<(), Error<I::BusError>> {
        driver.fifo_state = TaggedFifo::default();
        driver.write(reg::FIFO_CTRL4, reg::FIFO_MODE_BYPASS)?;
        if let Some(fifo) = driver.config.fifo {
            driver.write(reg::FIFO_CTRL4, fifo_mode_bits(fifo.mode))?;
        }
        Ok(())
    }
}

impl Lsm6dsoxChip {
    /// OUT_TEMP (the FIFO carries no temperature here: one reading per drain).
    fn read_temperature<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
    ) -> Result<i16, Error<I::BusError>> {
        let mut t = [0u8; 2];
        driver.read_registers(reg::OUT_TEMP_L, &mut t)?;
        Ok(i16::from_le_bytes(t))
    }

    /// The FIFO at two rates ([`tagged_fifo`]): reads the `words` counted,
    /// word by word in bursts, one sample per time slot, never more words
    /// at once than `out` has room for samples (a word closes at most one
    /// slot); a slot cut by a full `out` stays open for the next drain.
    fn read_fifo_slots<I: RegisterInterface>(
        driver: &mut Lsm6dsox<I>,
        out: &mut [RawSample],
        words: u16,
        rates: Rates,
    ) -> Result<FifoRead, Error<I::BusError>> {
        let temperature = Self::read_temperature(driver)?;
        let mut buffer = [[0u8; reg::FIFO_WORD_LEN]; FIFO_BURST_WORDS];
        let (mut delivered, mut left) = (0usize, usize::from(words));
        while left > 0 && delivered < out.len() {
            let burst = &mut buffer[..left.min(FIFO_BURST_WORDS).min(out.len() - delivered)];
            driver.read_registers(reg::FIFO_DATA_OUT_TAG, burst.as_flattened_mut())?;
            left -= burst.len();
            for word in burst.iter() {
                let closed = driver
                    .fifo_state
                    .push(word, rates, &mut driver.held)
                    .map_err(|header| Error::BadFifoPacket { header })?;
                if let Some(sample) = closed {
                    out[delivered] = RawSample {
                        temperature,
                        ..sample
                    };
                    delivered += 1;
                }
            }
        }
        if left == 0 && delivered < out.len() {
            if let Some(sample) = driver.fifo_state.flush(&mut driver.held) {
                out[delivered] = RawSample {
                    temperature,
                    ..sample
                };
                delivered += 1;
            }
        }
        // `left` ≤ `words`, a u16.
        let waiting = driver.fifo_state.slots_waiting(left as u16, rates);
        Ok(FifoRead::drained(delivered, waiting))
    }
}

/// FIFO words read per bus transaction at two rates (32 × 7 B of stack).
const FIFO_BURST_WORDS: usize = 32;

/// The rates of `config` when they differ (the FIFO then holds the slower
/// sensor's word in every `ratio`-th slot only).
fn rates(config: &Config) -> Option<Rates> {
    let (accel, gyro) = (config.accel_odr.hz(), config.gyro_odr.hz());
    if config.accel_odr == config.gyro_odr {
        return None;
    }
    let (fast, slow) = if gyro > accel {
        (gyro, accel)
    } else {
        (accel, gyro)
    };
    Some(Rates {
        gyro_faster: gyro > accel,
        ratio: libm::round(fast / slow) as u16,
    })
}

/// FIFO_CTRL1/2's watermark, words, for `watermark` samples: two words per
/// sample at one rate; at two rates one per slot plus the slower sensor's
/// in every `ratio`-th.
fn watermark_words(config: &Config, watermark: u16) -> u16 {
    match rates(config) {
        None => watermark * reg::WORDS_PER_SAMPLE,
        Some(r) => watermark + watermark.div_ceil(r.ratio),
    }
}

impl<I: RegisterInterface> Lsm6dsox<I> {
    /// Reads back the ranges and rates the chip holds (CTRL1_XL, CTRL2_G) as
    /// (accel range, gyro range, gyro ODR, accel ODR); a power-down or
    /// low-power-only rate reads as `InvalidConfig`.
    pub fn read_ranges(&mut self) -> Result<(AccelRange, GyroRange, Odr, Odr), Error<I::BusError>> {
        let mut b = [0u8; 2];
        self.read_registers(reg::CTRL1_XL, &mut b)?;
        let [ctrl1_xl, ctrl2_g] = b;
        let invalid = |what, value: u8| Error::InvalidConfig {
            what,
            value: u32::from(value),
        };
        // FS_XL is 2 bits: every value is a range.
        let accel_range = AccelRange::from_code::<Lsm6dsoxChip>((ctrl1_xl >> reg::FS_SHIFT) & 0b11)
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
}

/// FIFO_CTRL4 FIFO_MODE for a [`FifoMode`].
fn fifo_mode_bits(mode: FifoMode) -> u8 {
    match mode {
        FifoMode::StopOnFull => reg::FIFO_MODE_FIFO,
        FifoMode::Stream => reg::FIFO_MODE_CONTINUOUS,
    }
}

/// Three little-endian words.
fn words_le(b: &[u8]) -> [i16; 3] {
    let w = |i: usize| i16::from_le_bytes([b[2 * i], b[2 * i + 1]]);
    [w(0), w(1), w(2)]
}

/// Three little-endian words as a triad's counts.
fn triad_le(b: &[u8]) -> [i32; 3] {
    words_le(b).map(i32::from)
}

/// Decodes one gyro + accel pair of FIFO words (either order).
fn decode_fifo_pair(
    words: &[u8; 2 * reg::FIFO_WORD_LEN],
    temperature: i16,
) -> Result<RawSample, u8> {
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
