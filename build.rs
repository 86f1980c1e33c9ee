//! Names the cores with the Arm DSP extension (ARMv7E-M: the Cortex-M4 and
//! M7, targets `thumbv7em-*`) as `cfg(triad_dsp)`: the batch kernel's
//! limit-code test uses its saturating instructions there
//! (src/model/limit_codes.rs). Stable Rust has no `target_feature = "dsp"`
//! to test instead.
//!
//! Of those, the hard-float targets (`thumbv7em-none-eabihf`: the
//! Cortex-M4F and M7F) are also `cfg(triad_fpu)`: the batch kernel's usual
//! pass runs as one loop of FPU instructions there (src/model/fused_pass.rs).

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(triad_dsp)");
    println!("cargo::rustc-check-cfg=cfg(triad_fpu)");
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.starts_with("thumbv7em") {
        println!("cargo::rustc-cfg=triad_dsp");
        if target.ends_with("eabihf") {
            println!("cargo::rustc-cfg=triad_fpu");
        }
    }
}
