//! The host side of triad: the library behind the `triad` command. Each
//! subcommand is a module here (its arguments, its `run`, and the pure
//! functions it is made of); `src/main.rs` only parses the command line and
//! dispatches.
//!
//! - [`decode`]: the firmware's binary stream → CSV ([`stream_csv`]);
//! - [`device`]: a board running triad firmware, driven over its serial port;
//! - [`correct`]: a calibration applied to measured samples;
//! - [`calib`]: check, pack and fit calibration files ([`calib_file`]);
//! - [`sim`]: what a sensor measures in a scene ([`scene_file`]);
//! - [`allan`]: Allan deviation, noise terms and grade of rate columns;
//! - [`convert`]: a recording of any format read ([`record`]) → CSV or MCAP;
//! - [`cli_docs`]: shell completions and man pages of the command line.
//!
//! What every command shares: [`input`] (a CSV file or stdin), [`outfile`]
//! (outputs written whole or not at all), [`distinct`] (no output over an
//! input), [`stdio`] (stdout and stderr without panics), [`progress`],
//! [`interrupt`] (Ctrl-C), [`serial`] (ports) and [`number`] (readable numbers in messages).
//! [`shipped`] is what the binary carries (scenes, the default calibration);
//! [`version`] what `triad --version` says.

#![warn(missing_docs)]

pub mod allan;
pub mod calib;
pub mod calib_file;
pub mod cli_docs;
pub mod convert;
pub mod correct;
pub mod decode;
pub mod device;
pub mod distinct;
pub mod input;
pub mod interrupt;
pub mod number;
pub mod outfile;
pub mod progress;
pub mod record;
pub mod row_writer;
pub mod scene_file;
pub mod serial;
pub mod shipped;
pub mod sim;
pub mod stdio;
pub mod stream_csv;
pub mod stream_out;
pub mod truth_calibration;
pub mod units;
pub mod version;

#[doc(hidden)]
pub mod fixtures;
