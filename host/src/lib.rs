//! The host side of triad: the library behind the `triad` command. Each
//! subcommand is a module here (its arguments, its `run`, and the pure
//! functions it is made of); `src/main.rs` only parses the command line and
//! dispatches.
//!
//! - [`decode`]: the firmware's binary stream → CSV or MCAP;
//! - [`device`]: a board running triad firmware, driven over its serial port;
//! - [`correct`]: a calibration applied to measured samples;
//! - [`calib`]: check, pack, fit and verify calibration files;
//! - [`sim`]: what a sensor measures in a scene ([`scene_file`]);
//! - [`allan`]: Allan deviation, noise terms and grade of rate columns;
//! - [`convert`]: a recording of any format read ([`record`]) → CSV or MCAP;
//! - [`units`]: the unit conversions a command line accepts;
//! - [`cli_docs`]: shell completions and man pages of the command line.
//!
//! What every command shares is in [`plumbing`] (inputs, outputs written
//! whole or not at all, standard streams without panics, progress, Ctrl-C,
//! serial ports, readable numbers, what the binary carries, its version).

#![warn(missing_docs)]

pub mod allan;
pub mod calib;
pub mod cli_docs;
pub mod convert;
pub mod correct;
pub mod decode;
pub mod device;
pub mod plumbing;
pub mod record;
pub mod scene_file;
pub mod sim;
pub mod units;

#[doc(hidden)]
pub mod fixtures;
