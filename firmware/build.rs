//! Checks that the features name one board, at most one sensor chip and at
//! most one bus, and embeds the calibration blob chosen at build time
//! (TRIAD_CALIBRATION, default calibrations/default.bin). The board crate puts
//! its memory map on the linker path.

use std::{env, fs, path::PathBuf};

/// The calibration embedded when `TRIAD_CALIBRATION` is not set: packed from
/// calibrations/default.toml by `triad calib pack` (a test keeps them equal).
const DEFAULT_CALIBRATION: &str = "../calibrations/default.bin";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    one_of("board", &["qemu", "nucleo-f401re"]).unwrap_or_else(|| {
        panic!("the firmware needs a board: --features board-qemu or board-nucleo-f401re")
    });
    one_of("sensor", &["icm42688", "lsm6dsox"]);
    one_of("bus", &["spi", "i2c"]);

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
}

/// Which of the features `<group>-<name>` is on: `None` for none; two at once
/// stop the build with a message naming both.
fn one_of(group: &str, names: &[&'static str]) -> Option<&'static str> {
    let on: Vec<&'static str> = names
        .iter()
        .copied()
        .filter(|name| {
            let var = format!("CARGO_FEATURE_{group}_{name}")
                .to_uppercase()
                .replace('-', "_");
            env::var_os(var).is_some()
        })
        .collect();
    match on.as_slice() {
        [] => None,
        [one] => Some(one),
        several => panic!(
            "the firmware takes one {group}, but features {} are on together",
            several
                .iter()
                .map(|name| format!("{group}-{name}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}
