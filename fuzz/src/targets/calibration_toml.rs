//! The calibration TOML (`triad calib` files, [`triad_host::calib::file`]).
//! The input is a file's bytes (as text, invalid UTF-8 replaced as a
//! reader that refused it would not get this far). Invariant: parsed, or
//! refused with a message.

use std::path::Path;

use crate::invariants::{error_has_message, Broken};

/// Parses `bytes` as a calibration file; 1 when it parsed.
pub fn calibration_toml(bytes: &[u8]) -> Result<u64, Broken> {
    let text = String::from_utf8_lossy(bytes);
    match triad_host::calib::file::parse(&text, Path::new("fuzzed.toml")) {
        Ok(_) => Ok(1),
        Err(e) => error_has_message(&format!("{e:#}")).map(|()| 0),
    }
}
