//! The one driver shell every chip shares: the register interface, the
//! configuration applied, the buses, and [`Imu`]/[`FifoImu`] over the
//! chip's own steps ([`Chip`]). A chip module adds only what differs (its
//! register map, scales, start-up sequence and FIFO packet format).

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;
use embedded_hal::spi::SpiDevice;

use super::chip::Chip;
use super::config::Config;
use super::error::Error;
use super::fifo::{FifoImu, FifoRead};
use super::interface::{I2cInterface, RegisterInterface, SpiInterface};
use super::{Imu, ImuScale, RawSample};

/// What a sensor reads before its first sample: the "no data" code
/// ([`super::CodeRange::no_data`]) on every axis, the marker both chips use
/// (ICM-42688-P §6.1, §14; the corrector flags a triad at this code as
/// clipped, so no frame passes it off as a measurement).
fn not_yet_sampled(scale: &ImuScale) -> RawSample {
    RawSample {
        accel: [scale.accel.codes.no_data(); 3],
        gyro: [scale.gyro.codes.no_data(); 3],
        temperature: 0,
    }
}

/// FIFO records read per bus transaction (at most 32 × 16 B = 512 B of stack).
const FIFO_CHUNK_RECORDS: usize = 32;

/// Chip `C` behind a register interface `I` (e.g.
/// [`super::icm42688::Icm42688`]`<I>` is `Driver<Icm42688Chip, I>`).
#[derive(Debug)]
pub struct Driver<C: Chip, I> {
    pub(super) interface: I,
    pub(super) config: Config<C>,
    /// The last sample delivered from the FIFO (or, for a chip whose data
    /// registers cannot say which sensor is new, from them): a sensor with
    /// no new sample (it runs at the lower rate) keeps its value from here;
    /// [`Self::no_data`] until it has one.
    pub(super) held: RawSample,
    /// The configuration's "no data" sample ([`not_yet_sampled`]).
    no_data: RawSample,
    /// The chip's own FIFO bookkeeping between drains ([`Chip::FifoState`]).
    pub(super) fifo_state: C::FifoState,
}

impl<C: Chip, SPI: SpiDevice> Driver<C, SpiInterface<SPI>> {
    /// A driver for a chip on SPI (mode 0 or 3, up to [`Chip::SPI_MAX_HZ`]).
    pub fn new_spi(spi: SPI) -> Self {
        Self::new(SpiInterface::new(spi))
    }
}

impl<C: Chip, I2C: I2c> Driver<C, I2cInterface<I2C>> {
    /// A driver for a chip on I²C at `address` (one of [`Chip::I2C_ADDRESSES`]).
    pub fn new_i2c(i2c: I2C, address: u8) -> Self {
        Self::new(I2cInterface::new(i2c, address))
    }
}

impl<C: Chip, I: RegisterInterface> Driver<C, I> {
    /// A driver over any register interface. The chip is untouched until
    /// [`Self::init`].
    pub fn new(interface: I) -> Self {
        let no_data = not_yet_sampled(&C::RESET_CONFIG.scale());
        Self {
            interface,
            config: C::RESET_CONFIG,
            held: no_data,
            no_data,
            fifo_state: C::FifoState::default(),
        }
    }

    /// The configuration last applied ([`Chip::RESET_CONFIG`] before
    /// `init`, so `scale` is right before `init` too).
    pub fn config(&self) -> &Config<C> {
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

    /// Checks the identity, soft-resets, and applies `config` (the chip's
    /// start-up: [`Chip::start`]). A FIFO watermark out of range is refused
    /// before any bus access.
    pub fn init(
        &mut self,
        delay: &mut impl DelayNs,
        config: &Config<C>,
    ) -> Result<(), Error<I::BusError>> {
        if let Some(fifo) = config.fifo {
            if fifo.watermark == 0 || fifo.watermark > C::MAX_WATERMARK {
                return Err(Error::InvalidConfig {
                    what: C::WATERMARK_WHAT,
                    value: u32::from(fifo.watermark),
                });
            }
        }
        C::start(self, delay, config)?;
        self.config = *config;
        self.no_data = not_yet_sampled(&config.scale());
        self.held = self.no_data;
        self.fifo_state = C::FifoState::default();
        Ok(())
    }

    /// Reads the identity register `who_am_i`: [`Error::WrongChip`] unless
    /// it holds [`Chip::IDENTITY`].
    pub(super) fn expect_identity(&mut self, who_am_i: u8) -> Result<(), Error<I::BusError>> {
        let found = self.read_register(who_am_i)?;
        if found != C::IDENTITY {
            return Err(Error::WrongChip {
                expected: C::IDENTITY,
                found,
            });
        }
        Ok(())
    }

    /// Writes one register.
    pub(super) fn write(&mut self, register: u8, value: u8) -> Result<(), Error<I::BusError>> {
        self.interface
            .write_register(register, value)
            .map_err(Error::Bus)
    }

    /// Reads one register.
    pub(super) fn read_register(&mut self, register: u8) -> Result<u8, Error<I::BusError>> {
        let mut b = [0u8];
        self.read_registers(register, &mut b)?;
        Ok(b[0])
    }

    /// Fills `out` from the FIFO data port `register`: whole records of
    /// `RECORD` bytes, 32 per transaction, each decoded by `decode` (whose
    /// error is the header or tag byte of a record it does not take). With
    /// the sensors at different rates, a triad the record has no new sample
    /// of (the "no data" code on every axis) then takes its previous value
    /// ([`Self::hold_slower`]); at one rate the records go out as decoded.
    pub(super) fn read_fifo_records<const RECORD: usize>(
        &mut self,
        register: u8,
        out: &mut [RawSample],
        mut decode: impl FnMut(&[u8; RECORD]) -> Result<RawSample, u8>,
    ) -> Result<(), Error<I::BusError>> {
        let mut buffer = [[0u8; RECORD]; FIFO_CHUNK_RECORDS];
        for chunk in out.chunks_mut(FIFO_CHUNK_RECORDS) {
            let records = &mut buffer[..chunk.len()];
            self.read_registers(register, records.as_flattened_mut())?;
            for (record, slot) in records.iter().zip(chunk) {
                *slot = decode(record).map_err(|header| Error::BadFifoPacket { header })?;
            }
        }
        if self.config.accel_odr != self.config.gyro_odr {
            self.hold_slower(out);
        }
        Ok(())
    }

    /// Each triad of `samples` at the "no data" code on every axis (no new sample: the
    /// sensor runs at the lower rate) takes the previous sample's value,
    /// the first one [`Self::held`]'s; the last sample is held next.
    fn hold_slower(&mut self, samples: &mut [RawSample]) {
        let mut previous = self.held;
        for sample in samples {
            if sample.accel == self.no_data.accel {
                sample.accel = previous.accel;
            }
            if sample.gyro == self.no_data.gyro {
                sample.gyro = previous.gyro;
            }
            previous = *sample;
        }
        self.held = previous;
    }

    /// Reads `buffer.len()` bytes from `register` in one transaction.
    pub(super) fn read_registers(
        &mut self,
        register: u8,
        buffer: &mut [u8],
    ) -> Result<(), Error<I::BusError>> {
        self.interface
            .read_registers(register, buffer)
            .map_err(Error::Bus)
    }
}

impl<C: Chip, I: RegisterInterface> Imu for Driver<C, I> {
    type Error = Error<I::BusError>;

    fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
        C::read_sample(self)
    }

    fn scale(&self) -> ImuScale {
        self.config.scale()
    }
}

impl<C: Chip, I: RegisterInterface> FifoImu for Driver<C, I> {
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, Self::Error> {
        C::read_fifo(self, out)
    }

    fn reset_fifo(&mut self) -> Result<(), Self::Error> {
        C::reset_fifo(self)
    }
}
