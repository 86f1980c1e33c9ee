//! The benchmark firmware's memory map, by target: the Cortex-M0 core is
//! QEMU's microbit (memory/microbit.x), the Cortex-M4F core the emulated
//! board's STM32F405 (its board crate's memory.x). Put on the linker path as
//! board_memory.x, which the root memory.x includes. Host builds skip it.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if env::var_os("CARGO_FEATURE_FIRMWARE").is_none() {
        return;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("thumbv6m") {
        "memory/microbit.x"
    } else {
        "../boards/qemu/memory.x"
    };
    fs::copy(memory, out.join("board_memory.x")).expect("copy the core's memory map");
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo:rustc-link-search={}", out.display());
}
