//! triad-bench: the benchmark harness shared by the benchmark firmware (`src/bin/bench.rs`,
//! run on emulated cores by `cargo xtask bench`) and the host, which computes
//! the same variants on the same inputs to check that every fast row is also
//! a right row (the digests must match bit for bit).
//!
//! Each [`Variant`] corrects [`BATCH`] raw samples held in RAM into outputs
//! in RAM, like the reference harness of the benchmark issue (1000 6-axis
//! i16 samples → SI values); the firmware times [`BATCHES`] such batches.
//! Batches, not one block of 1000, because the Cortex-M0 core (nRF51 on
//! QEMU's `microbit`) has 16 KiB of RAM.
//!
//! Besides the variants, [`command_handling`] times what each command of
//! the link costs the firmware's `link` task, over a [`ram_flash`] that
//! counts its operations.

#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod command_handling;
pub mod digest;
pub mod inputs;
pub mod kernels;
pub mod pipeline;
pub mod ram_flash;
pub mod sensor_reads;

pub use digest::Digest;
pub use kernels::{Bench, Variant};

/// Samples per timed batch.
pub const BATCH: usize = 100;
/// Batches per variant: BATCH × BATCHES samples are timed in all.
pub const BATCHES: usize = 10;
