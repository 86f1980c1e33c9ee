//! Fuzz targets for the parsers that take outside bytes, run by AFL++
//! (coverage-guided, through cargo-afl, on the stable toolchain: its
//! instrumentation is rustc's own SanitizerCoverage passes, which stable
//! enables, and AFL++'s runtime is C) — `cargo xtask bench --fuzz` builds
//! and runs them; each target here is a plain function of the input bytes,
//! so the tests run them over their seeds without AFL, and a crash AFL
//! finds replays as a test.
//!
//! A target panics (AFL's crash) on a broken invariant and lets a parser's
//! own panic through; an error with a message is a correct answer to bad bytes.

pub mod record_files;

pub use record_files::{record, triad_csv};
