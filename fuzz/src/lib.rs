//! Fuzz targets for the parsers that take outside bytes, run by AFL++
//! (coverage-guided, through cargo-afl, on the stable toolchain: its
//! instrumentation is rustc's own SanitizerCoverage passes, which stable
//! enables, and AFL++'s runtime is C) — `cargo xtask bench --fuzz` builds
//! and runs them — and by the long mutation run of the same benchmark
//! (examples/bench_fuzz.rs). Each target here is a plain function of the
//! input bytes that checks the parser's invariants after it ran, one
//! function per invariant ([`invariants`]), so AFL's binaries, the
//! mutation run and the tests over the seeds check the same things, and a
//! crash AFL finds replays as a test.
//!
//! A target returns what the parser accepted, or [`Broken`] (an invariant
//! that did not hold, with the input's story); AFL's binaries turn that
//! into a crash ([`crash_on_broken`]), the mutation run counts it. A
//! parser's own panic goes through either way; an error with a message is
//! a correct answer to bad bytes.

pub mod invariants;
pub mod seeds;
pub mod targets;

pub use invariants::Broken;
pub use targets::record_files::{record, triad_csv};
pub use targets::{
    calibration_blob, calibration_toml, cobs, command_path, scene_blob, stream_decoder,
};

/// For AFL's binaries: a broken invariant is a crash (a panic, which
/// cargo-afl's harness aborts on), with what broke as its message.
pub fn crash_on_broken(verdict: Result<u64, Broken>) {
    if let Err(broken) = verdict {
        panic!("broken invariant: {broken}");
    }
}
