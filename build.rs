//! Names the cores with the Arm DSP extension (ARMv7E-M: the Cortex-M4 and
//! M7, targets `thumbv7em-*`) as `cfg(triad_dsp)`: the batch kernel's
//! limit-code test uses its saturating instructions there
//! (src/model/limit_codes.rs). Stable Rust has no `target_feature = "dsp"`
//! to test instead.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(triad_dsp)");
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.starts_with("thumbv7em") {
        println!("cargo::rustc-cfg=triad_dsp");
    }
}
