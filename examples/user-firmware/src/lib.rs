//! What a user's own firmware takes from triad: the ICM-42688-P driver on
//! whatever SPI bus their HAL provides (any embedded-hal 1.0 `SpiDevice`) and
//! the `Corrector` that applies a lab calibration, m = (I+Σ)⁻¹(m̂ − b).
//!
//! Built for thumbv7em-none-eabihf by `cargo xtask test`; its dependency tree
//! is the core, embedded-hal and libm (no RTIC, no PAC, no simulator).
//!
//! ```ignore
//! // In the user's firmware, with their HAL's SPI device and delay:
//! let mut imu = CalibratedImu::start(spi, &mut delay, CALIBRATION_BLOB)?;
//! loop {
//!     wait_for_data_ready();
//!     let sample = imu.read()?; // m/s², rad/s, °C, clip flags
//! }
//! ```
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use triad::model::{
    blob, BlobError, Calibration, CalibrationError, Corrector, Orientation, Sample,
};
use triad::sensor::icm42688::{Config, Icm42688};
use triad::sensor::interface::SpiInterface;
use triad::sensor::{Error, Imu};

/// An ICM-42688-P on `SPI` whose every reading comes out calibrated.
pub struct CalibratedImu<SPI: SpiDevice> {
    driver: Icm42688<SpiInterface<SPI>>,
    corrector: Corrector,
}

/// Why the IMU did not start.
#[derive(Debug)]
pub enum StartError<E> {
    /// The chip did not answer or configure (bus error, wrong identity).
    Sensor(Error<E>),
    /// The calibration blob is not one (`triad calib pack` writes them).
    Blob(BlobError),
    /// The calibration is not valid for this chip's ranges.
    Calibration(CalibrationError),
}

impl<SPI: SpiDevice> CalibratedImu<SPI> {
    /// Configures the chip (±16 g, ±2000 °/s, 1 kHz, data ready on INT1) and
    /// checks `calibration_blob` against its ranges; the chip mounted in the
    /// board's axes. An empty blob means "uncalibrated": the identity.
    pub fn start(
        spi: SPI,
        delay: &mut impl DelayNs,
        calibration_blob: &[u8],
    ) -> Result<Self, StartError<SPI::Error>> {
        let mut driver = Icm42688::new_spi(spi);
        driver
            .init(delay, &Config::default())
            .map_err(StartError::Sensor)?;
        let calibration = if calibration_blob.is_empty() {
            Calibration::identity(0)
        } else {
            blob::decode(calibration_blob).map_err(StartError::Blob)?
        };
        let corrector = Corrector::new(&calibration, &driver.scale(), Orientation::RotationNone)
            .map_err(StartError::Calibration)?;
        Ok(Self { driver, corrector })
    }

    /// Reads one sample and corrects it: accelerometer in m/s², gyroscope in
    /// rad/s, die temperature in °C, and which triads clipped.
    pub fn read(&mut self) -> Result<Sample, Error<SPI::Error>> {
        let raw = self.driver.read_sample()?;
        Ok(self.corrector.correct(&raw))
    }

    /// The calibration's identifier (the CRC the stream carries).
    pub fn calibration_id(&self) -> u32 {
        self.corrector.calibration_id()
    }
}
