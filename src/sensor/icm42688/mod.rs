//! TDK InvenSense ICM-42688-P 6-axis IMU driver, over SPI or I²C.
//!
//! Datasheet DS-000347. The driver keeps the chip in user bank 0, runs both
//! sensors in low-noise mode at one output data rate, and either reads the
//! data registers on data ready or drains the FIFO on its watermark.

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
pub use self::registers::{I2C_ADDRESS_AD0_HIGH, I2C_ADDRESS_AD0_LOW};
pub use self::self_test::self_test_max_duration_ms;

/// The chip's name, as the link and the log report it.
pub const NAME: &str = "icm42688";
/// The identity WHO_AM_I holds (§14).
pub const IDENTITY: u8 = reg::WHO_AM_I_VALUE;
/// The fastest SPI clock the chip takes, Hz (DS-000347 §4.5).
pub const SPI_MAX_HZ: u32 = 24_000_000;
/// The chip's I²C addresses: AP_AD0 low, then high (§9.3).
pub const I2C_ADDRESSES: [u8; 2] = [I2C_ADDRESS_AD0_LOW, I2C_ADDRESS_AD0_HIGH];

/// Reads the chip's identity register (WHO_AM_I, bank 0) without changing
/// anything, unless REG_BANK_SEL (0x76, readable in every bank) names a user
/// bank other than 0 — as after a warm restart of the microcontroller — when
/// it selects bank 0 first and reads again.
pub fn identify<I: RegisterInterface>(interface: &mut I) -> Result<u8, I::BusError> {
    let mut read = |register| {
        let mut value = [0];
        interface
            .read_registers(register, &mut value)
            .map(|()| value[0])
    };
    let found = read(reg::WHO_AM_I)?;
    if found == IDENTITY || !(1..=4).contains(&read(reg::REG_BANK_SEL)?) {
        return Ok(found);
    }
    interface.write_register(reg::REG_BANK_SEL, 0)?;
    let mut value = [0];
    interface.read_registers(reg::WHO_AM_I, &mut value)?;
    Ok(value[0])
}

/// FIFO packets read per bus transaction: 32 × 16 B = 512 B of stack.
const FIFO_CHUNK_PACKETS: usize = 32;

/// An ICM-42688-P behind a register interface `I`.
#[derive(Debug)]
pub struct Icm42688<I> {
    interface: I,
    config: Config,
}

impl<SPI: SpiDevice> Icm42688<SpiInterface<SPI>> {
    /// A driver for a chip on SPI (mode 0 or 3, up to 24 MHz, §4.5).
    pub fn new_spi(spi: SPI) -> Self {
        Self::new(SpiInterface::new(spi))
    }
}

impl<I2C: I2c> Icm42688<I2cInterface<I2C>> {
    /// A driver for a chip on I²C at `address` (0x68 with AP_AD0 low, 0x69 high).
    pub fn new_i2c(i2c: I2C, address: u8) -> Self {
        Self::new(I2cInterface::new(i2c, address))
    }
}

impl<I: RegisterInterface> Icm42688<I> {
    /// A driver over any register interface. The chip is untouched until [`Self::init`].
    pub fn new(interface: I) -> Self {
        Self {
            interface,
            config: Config::default(),
        }
    }

    /// The configuration last applied (the reset configuration before `init`).
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

    /// Checks the identity, soft-resets, and applies `config`: ranges, rate,
    /// INT1 pin and source, FIFO; turns both sensors on in low-noise mode.
    pub fn init(
        &mut self,
        delay: &mut impl DelayNs,
        config: &Config,
    ) -> Result<(), Error<I::BusError>> {
        if let Some(fifo) = config.fifo {
            if fifo.watermark == 0 || fifo.watermark > reg::FIFO_CAPACITY_PACKETS {
                return Err(Error::InvalidConfig {
                    what: "FIFO watermark (packets, 1..=128)",
                    value: u32::from(fifo.watermark),
                });
            }
        }
        // WHO_AM_I lives in bank 0; after a warm restart the chip may be in another.
        self.write(reg::REG_BANK_SEL, 0)?;
        let found = self.read_register(reg::WHO_AM_I)?;
        if found != reg::WHO_AM_I_VALUE {
            return Err(Error::WrongChip {
                expected: reg::WHO_AM_I_VALUE,
                found,
            });
        }
        self.write(reg::DEVICE_CONFIG, reg::SOFT_RESET_CONFIG)?;
        delay.delay_us(reg::SOFT_RESET_WAIT_US);
        let status = self.read_register(reg::INT_STATUS)?;
        if status & reg::RESET_DONE_INT == 0 {
            return Err(Error::ResetNotDone { status });
        }
        // Count the FIFO (and its watermark) in packets, both big-endian.
        self.write(
            reg::INTF_CONFIG0,
            reg::FIFO_COUNT_REC | reg::FIFO_COUNT_ENDIAN | reg::SENSOR_DATA_ENDIAN,
        )?;
        self.write(reg::INT_CONFIG, config::int_config(config.interrupt))?;
        // §14 INT_CONFIG1: INT_ASYNC_RESET must be 0 for INT1 to work.
        self.write(reg::INT_CONFIG1, 0)?;
        self.write(
            reg::GYRO_CONFIG0,
            (config.gyro_range.code() << reg::FS_SEL_SHIFT) | config.odr.code(),
        )?;
        self.write(
            reg::ACCEL_CONFIG0,
            (config.accel_range.code() << reg::FS_SEL_SHIFT) | config.odr.code(),
        )?;
        match config.fifo {
            Some(fifo) => {
                self.write(
                    reg::FIFO_CONFIG1,
                    reg::FIFO_ACCEL_EN | reg::FIFO_GYRO_EN | reg::FIFO_TEMP_EN,
                )?;
                let [high, low] = fifo.watermark.to_be_bytes();
                self.write(reg::FIFO_CONFIG2, low)?;
                self.write(reg::FIFO_CONFIG3, high)?;
                let mode = match fifo.mode {
                    FifoMode::StopOnFull => reg::FIFO_MODE_STOP_ON_FULL,
                    FifoMode::Stream => reg::FIFO_MODE_STREAM,
                };
                self.write(reg::FIFO_CONFIG, mode)?;
                self.write(reg::INT_SOURCE0, reg::FIFO_THS_INT1_EN)?;
            }
            None => self.write(reg::INT_SOURCE0, reg::UI_DRDY_INT1_EN)?,
        }
        self.write(
            reg::PWR_MGMT0,
            reg::GYRO_MODE_LOW_NOISE | reg::ACCEL_MODE_LOW_NOISE,
        )?;
        delay.delay_us(reg::POWER_ON_WAIT_US);
        self.config = *config;
        Ok(())
    }

    /// Reads back the ranges and rate the chip holds (GYRO_CONFIG0, ACCEL_CONFIG0)
    /// as (accel range, gyro range, gyro ODR, accel ODR); a field value the
    /// driver does not use reads as `InvalidConfig`.
    pub fn read_ranges(&mut self) -> Result<(AccelRange, GyroRange, Odr, Odr), Error<I::BusError>> {
        let mut b = [0u8; 2];
        self.interface
            .read_registers(reg::GYRO_CONFIG0, &mut b)
            .map_err(Error::Bus)?;
        let [gyro, accel] = b;
        let invalid = |what, value: u8| Error::InvalidConfig {
            what,
            value: u32::from(value),
        };
        let gyro_range =
            GyroRange::from_code(gyro >> reg::FS_SEL_SHIFT).ok_or(invalid("GYRO_CONFIG0", gyro))?;
        let accel_range = AccelRange::from_code(accel >> reg::FS_SEL_SHIFT)
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

/// Decodes the 14-byte TEMP_DATA1..GYRO_DATA_Z0 block (big-endian words).
fn decode_sample_block(b: &[u8; 14]) -> RawSample {
    let w = |i: usize| i16::from_be_bytes([b[2 * i], b[2 * i + 1]]);
    RawSample {
        temperature: w(0),
        accel: [w(1), w(2), w(3)],
        gyro: [w(4), w(5), w(6)],
    }
}

/// Decodes one 16-byte FIFO packet 3 (§6.1): header, accel, gyro, 8-bit
/// temperature, timestamp. The temperature is brought to the register scale.
fn decode_fifo_packet(p: &[u8]) -> Option<RawSample> {
    let header = *p.first()?;
    let expected = reg::HEADER_ACCEL | reg::HEADER_GYRO;
    let mask = reg::HEADER_MSG | reg::HEADER_ACCEL | reg::HEADER_GYRO | reg::HEADER_20;
    if header & mask != expected || p.len() < reg::FIFO_PACKET_LEN {
        return None;
    }
    let w = |i: usize| i16::from_be_bytes([p[1 + 2 * i], p[2 + 2 * i]]);
    // 132.48 / 2.07 = 64: the FIFO's 8-bit temperature on the 16-bit scale.
    let temperature = i16::from(p[13] as i8) * 64;
    Some(RawSample {
        accel: [w(0), w(1), w(2)],
        gyro: [w(3), w(4), w(5)],
        temperature,
    })
}

impl<I: RegisterInterface> Imu for Icm42688<I> {
    type Error = Error<I::BusError>;

    /// One burst of 14 bytes from TEMP_DATA1 to GYRO_DATA_Z0.
    fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
        let mut b = [0u8; 14];
        self.interface
            .read_registers(reg::TEMP_DATA1, &mut b)
            .map_err(Error::Bus)?;
        Ok(decode_sample_block(&b))
    }

    fn scale(&self) -> ImuScale {
        self.config.scale()
    }
}

impl<I: RegisterInterface> FifoImu for Icm42688<I> {
    /// Reads INT_STATUS and FIFO_COUNT in one burst, then the whole packets
    /// that fit in `out` from FIFO_DATA, 32 packets per transaction. On
    /// FIFO_FULL the lost-packet counter is read and the FIFO flushed.
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error> {
        let mut head = [0u8; 3];
        self.interface
            .read_registers(reg::INT_STATUS, &mut head)
            .map_err(Error::Bus)?;
        let [status, count_high, count_low] = head;
        let count = u16::from_be_bytes([count_high, count_low]);
        if count > reg::FIFO_CAPACITY_PACKETS {
            // More than the FIFO holds: the count cannot be trusted, nor
            // what reading that many would bring. Start the FIFO afresh;
            // what it held is lost, at least the watermark that raised this.
            self.reset_fifo()?;
            return Ok(FifoRead::impossible_count(self.config.fifo));
        }
        if status & reg::FIFO_FULL_INT != 0 {
            let mut lost = [0u8; 2];
            self.interface
                .read_registers(reg::FIFO_LOST_PKT0, &mut lost)
                .map_err(Error::Bus)?;
            self.reset_fifo()?;
            return Ok(FifoRead {
                samples: 0,
                remaining: 0,
                overflowed: true,
                lost: u32::from(u16::from_le_bytes(lost)) + u32::from(count),
                lost_is_lower_bound: false,
            });
        }
        let wanted = usize::from(count).min(out.len());
        let mut buffer = [0u8; FIFO_CHUNK_PACKETS * reg::FIFO_PACKET_LEN];
        let mut done = 0;
        while done < wanted {
            let packets = (wanted - done).min(FIFO_CHUNK_PACKETS);
            let bytes = &mut buffer[..packets * reg::FIFO_PACKET_LEN];
            self.interface
                .read_registers(reg::FIFO_DATA, bytes)
                .map_err(Error::Bus)?;
            for (packet, slot) in bytes
                .chunks_exact(reg::FIFO_PACKET_LEN)
                .zip(out[done..].iter_mut())
            {
                *slot =
                    decode_fifo_packet(packet).ok_or(Error::BadFifoPacket { header: packet[0] })?;
            }
            done += packets;
        }
        Ok(FifoRead {
            samples: wanted,
            // `wanted` ≤ `count`, so this fits.
            remaining: count - wanted as u16,
            overflowed: false,
            lost: 0,
            lost_is_lower_bound: false,
        })
    }

    fn reset_fifo(&mut self) -> Result<(), Self::Error> {
        self.write(reg::SIGNAL_PATH_RESET, reg::FIFO_FLUSH)
    }
}
