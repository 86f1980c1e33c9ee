//! Firmware build: checks that the features name one board, at most one
//! sensor chip and at most one bus; puts the selected board's memory.x on the
//! linker path and embeds the calibration blob chosen at build time. Host
//! builds skip all three.

use std::{
    env, fs,
    path::{Path, PathBuf},
};

/// The calibration embedded when `TRIAD_CALIBRATION` is not set: packed from
/// calibrations/default.toml by `triad calib pack` (a test keeps them equal).
const DEFAULT_CALIBRATION: &str = "calibrations/default.bin";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    if env::var_os("CARGO_FEATURE_BENCH_CORE").is_some() {
        // The benchmark firmware: the Cortex-M0 core is QEMU's microbit, the
        // Cortex-M4F core the emulated board's STM32F405.
        let target = env::var("TARGET").unwrap_or_default();
        let core = if target.starts_with("thumbv6m") {
            "microbit"
        } else {
            "qemu"
        };
        link_memory_map(&manifest.join("boards").join(core).join("memory.x"), &out);
        return;
    }
    if env::var_os("CARGO_FEATURE_FIRMWARE").is_none() {
        return;
    }

    let board = one_of("board", &["qemu", "nucleo-f401re"]).unwrap_or_else(|| {
        panic!("the firmware needs a board: --features board-qemu or board-nucleo-f401re")
    });
    // The chip and the bus (src/main.rs and boards/<board>/board.rs read the
    // features; absent ones mean the ICM-42688-P on SPI): checked here only.
    one_of("sensor", &["icm42688", "lsm6dsox"]);
    one_of("bus", &["spi", "i2c"]);
    link_memory_map(&manifest.join("boards").join(board).join("memory.x"), &out);

    embed_scene(board, &out);

    println!("cargo:rerun-if-env-changed=TRIAD_CALIBRATION");
    let calibration = env::var_os("TRIAD_CALIBRATION")
        .map(PathBuf::from)
        .unwrap_or_else(|| manifest.join(DEFAULT_CALIBRATION));
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

/// Puts `memory` on the linker path as memory.x (cortex-m-rt's link.x includes it).
fn link_memory_map(memory: &Path, out: &Path) {
    fs::copy(memory, out.join("memory.x")).expect("copy the board's memory.x");
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rustc-link-search={}", out.display());
}

/// With the `sim-scene` feature (emulated board only): the scene blob named by
/// TRIAD_SCENE (written by `triad sim --pack`) becomes OUT_DIR/scene.bin.
fn embed_scene(board: &str, out: &Path) {
    println!("cargo:rerun-if-env-changed=TRIAD_SCENE");
    if env::var_os("CARGO_FEATURE_SIM_SCENE").is_none() {
        return;
    }
    if board != "qemu" {
        panic!(
            "the sim-scene feature feeds the emulated board's chip model: use it with board-qemu"
        );
    }
    let scene = env::var_os("TRIAD_SCENE").map(PathBuf::from).unwrap_or_else(|| {
        panic!("the sim-scene feature needs TRIAD_SCENE: the blob of `triad sim --scene NAME --pack FILE`")
    });
    let blob = fs::read(&scene)
        .unwrap_or_else(|e| panic!("TRIAD_SCENE: cannot read {}: {e}", scene.display()));
    fs::write(out.join("scene.bin"), blob).expect("write scene.bin");
    println!("cargo:rerun-if-changed={}", scene.display());
}
