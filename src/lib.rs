//! triad: calibrated MEMS inertial sensors.
//!
//! The portable core: no_std, no allocation. The same code runs in the
//! firmware, in the host tests and in the `triad` command, so a number seen on
//! the host is the number the device computes.
//!
//! Data flow (one direction): [`sensor`] reads a [`sensor::RawSample`],
//! [`model`] corrects it into a [`model::Sample`], [`stream`] frames it for
//! the serial link. [`sim`] produces what a sensor would measure, for tests
//! and for the emulated board.
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod crc32c;
pub mod device;
pub mod model;
pub mod sensor;
pub mod stream;
pub mod units;
