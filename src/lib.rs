//! triad: calibrated MEMS inertial sensors — the core a firmware embeds.
//!
//! no_std, no allocation, host-testable. The same code runs in triad's own
//! firmware, in the host tests and in the `triad` command, so a number seen on
//! the host is the number the device computes.
//!
//! Data flow: [`sensor`] reads a [`sensor::RawSample`] from a chip over any
//! embedded-hal 1.0 SPI or I²C bus; [`model`] corrects it with a lab
//! calibration, m = (I+Σ)⁻¹(m̂ − b), into a [`model::Sample`]; [`protocol`]
//! frames it for the serial link (closed by the project's one CRC,
//! [`mod@protocol::crc32c`]) and reads the host's commands. [`device`]
//! holds what a firmware decides (which calibration starts, the data-ready
//! step) as plain functions; [`units`] the unit conversions at the edges.
//!
//! A user's own firmware needs two calls:
//!
//! ```ignore
//! let mut imu = triad::sensor::icm42688::Icm42688::new_spi(spi_device);
//! imu.init(&mut delay, &triad::sensor::icm42688::Config::default())?;
//! let cal = triad::model::blob::decode(CALIBRATION_BLOB)?;
//! let corrector = triad::model::Corrector::new(&cal, &imu.scale(), Orientation::RotationNone)?;
//! let sample = corrector.correct(&imu.read_sample()?); // m/s², rad/s, °C
//! ```
//!
//! (examples/user-firmware is that, built for a Cortex-M4F in CI.)
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod device;
pub mod model;
pub mod protocol;
pub mod sensor;
pub mod units;
