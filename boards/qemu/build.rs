//! Puts this board's memory.x on the linker path as board_memory.x (the root
//! memory.x includes it), passes on the emulated chip TRIAD_EMULATED_CHIP
//! names (one of `triad::sensor::CHIP_NAMES`, default the first) and, with
//! `sim-scene`, copies the scene blob named by
//! TRIAD_SCENE (written by `triad sim --pack`) to OUT_DIR/scene.bin.

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("board_memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");

    println!("cargo:rerun-if-env-changed=TRIAD_EMULATED_CHIP");
    let chips = triad::sensor::CHIP_NAMES;
    let chip = env::var("TRIAD_EMULATED_CHIP").unwrap_or_else(|_| chips[0].to_owned());
    if !chips.contains(&chip.as_str()) {
        panic!(
            "TRIAD_EMULATED_CHIP={chip:?} is not a chip triad drives: one of {}",
            chips.join(", ")
        );
    }
    println!("cargo:rustc-env=TRIAD_EMULATED_CHIP={chip}");

    println!("cargo:rerun-if-env-changed=TRIAD_SCENE");
    if env::var_os("CARGO_FEATURE_SIM_SCENE").is_none() {
        return;
    }
    let scene = env::var_os("TRIAD_SCENE").map(PathBuf::from).unwrap_or_else(|| {
        panic!("the sim-scene feature needs TRIAD_SCENE: the blob of `triad sim --scene NAME --pack FILE`")
    });
    let blob = fs::read(&scene)
        .unwrap_or_else(|e| panic!("TRIAD_SCENE: cannot read {}: {e}", scene.display()));
    fs::write(out.join("scene.bin"), blob).expect("write scene.bin");
    println!("cargo:rerun-if-changed={}", scene.display());
}
