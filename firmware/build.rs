//! Makes the one board the features name (an optional dependency
//! `triad-board-<name>`, see Cargo.toml) the crate's `board` module, embeds
//! the calibration blob chosen at build time
//! (TRIAD_CALIBRATION, default calibrations/default.bin), and writes the
//! sampling settings chosen at build time: TRIAD_SAMPLE_RATE_HZ (the chip's
//! output data rate, default the driver's), TRIAD_FIFO_WATERMARK (samples
//! per interrupt, 1..=32, default 1: no FIFO) and TRIAD_FIFO_HIGH_RESOLUTION
//! (1: the chip's high-resolution FIFO format, the ICM-42688-P's 20-bit
//! packets; 0 or unset: off). The board crate puts its memory map on the
//! linker path.

use std::{env, fs, path::PathBuf};

/// The calibration embedded when `TRIAD_CALIBRATION` is not set: packed from
/// calibrations/default.toml by `triad calib pack` (a test keeps them equal).
const DEFAULT_CALIBRATION: &str = "../calibrations/default.bin";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let Some(board) = one_board() else {
        panic!("the firmware needs a board: --features triad-board-<name> (see Cargo.toml)");
    };
    fs::write(
        out.join("board.rs"),
        format!(
            "/// The board chosen by feature.\nuse {} as board;\n",
            board.replace('-', "_")
        ),
    )
    .expect("write board.rs");

    println!("cargo:rerun-if-env-changed=TRIAD_CALIBRATION");
    let calibration = env::var_os("TRIAD_CALIBRATION")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_CALIBRATION));
    let blob = fs::read(&calibration).unwrap_or_else(|e| {
        panic!(
            "TRIAD_CALIBRATION: cannot read {}: {e}",
            calibration.display()
        )
    });
    fs::write(out.join("calibration.bin"), blob).expect("write calibration.bin");
    println!("cargo:rerun-if-changed={}", calibration.display());

    let rate = number("TRIAD_SAMPLE_RATE_HZ", 1..=32_000);
    let watermark = number("TRIAD_FIFO_WATERMARK", 1..=32).unwrap_or(1);
    let high_resolution = number("TRIAD_FIFO_HIGH_RESOLUTION", 0..=1) == Some(1);
    if high_resolution && watermark == 1 {
        panic!(
            "TRIAD_FIFO_HIGH_RESOLUTION=1 needs the FIFO: set TRIAD_FIFO_WATERMARK to 2..=32 \
             (it is {watermark})"
        );
    }
    let rate = rate.map_or("None".to_string(), |hz| format!("Some({hz})"));
    let slower = match (
        number("TRIAD_ACCEL_RATE_HZ", 1..=32_000),
        number("TRIAD_GYRO_RATE_HZ", 1..=32_000),
    ) {
        (None, None) => "None".to_string(),
        (Some(hz), None) => format!("Some((triad::model::Triad::Accel, {hz}))"),
        (None, Some(hz)) => format!("Some((triad::model::Triad::Gyro, {hz}))"),
        (Some(_), Some(_)) => panic!(
            "TRIAD_ACCEL_RATE_HZ and TRIAD_GYRO_RATE_HZ are both set: name the slower sensor only \
             (the other runs at TRIAD_SAMPLE_RATE_HZ)"
        ),
    };
    fs::write(
        out.join("settings.rs"),
        format!(
            "/// From TRIAD_SAMPLE_RATE_HZ, TRIAD_ACCEL_RATE_HZ / TRIAD_GYRO_RATE_HZ, TRIAD_FIFO_WATERMARK and TRIAD_FIFO_HIGH_RESOLUTION at build.\n\
             pub const SETTINGS: triad::sensor::Settings = triad::sensor::Settings {{ rate_hz: {rate}, slower: {slower}, watermark: {watermark}, high_resolution: {high_resolution} }};\n"
        ),
    )
    .expect("write settings.rs");
}

/// The whole number in the environment variable `name`, within `range`;
/// `None` when unset; anything else stops the build naming the value.
fn number(name: &str, range: std::ops::RangeInclusive<u32>) -> Option<u32> {
    println!("cargo:rerun-if-env-changed={name}");
    let text = env::var(name).ok()?;
    match text.trim().parse::<u32>() {
        Ok(n) if range.contains(&n) => Some(n),
        _ => panic!(
            "{name}={text:?}: not a whole number in {}..={}",
            range.start(),
            range.end()
        ),
    }
}

/// Which board crate's feature (`triad-board-<name>`, an optional
/// dependency's) is on. Cargo.toml lists the boards; this reads whatever is
/// enabled, so adding a board does not touch this file: `None` for none;
/// two at once stop the build naming both.
fn one_board() -> Option<String> {
    let prefix = "CARGO_FEATURE_TRIAD_BOARD_";
    let mut on: Vec<String> = env::vars()
        .filter_map(|(var, _)| var.strip_prefix(prefix).map(str::to_lowercase))
        .map(|name| format!("triad-board-{}", name.replace('_', "-")))
        .collect();
    on.sort();
    match on.len() {
        0 => None,
        1 => on.pop(),
        _ => panic!(
            "the firmware takes one board, but features {} are on together",
            on.join(", ")
        ),
    }
}
