//! triad-lab: what the lab does with recorded data, in f64, no_std (with
//! `alloc`: a fit gathers what a record holds; the caller owns the sample
//! buffers), so the same code runs in the `triad` command and in tests.
//!
//! - [`allan`]: Allan variance of rate data, its confidence intervals, the
//!   IEEE Std 952 noise terms and the grade they meet.
//! - [`calib_fit`]: (I+Σ) and b from static positions and rate-table runs.
//! - [`time_base`]: sample times repaired from stamps as loggers write them.
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

// The whole fits gather what a record holds (its poses, moves, what was
// left out): they allocate; the sample buffers stay the caller's.
extern crate alloc;

pub mod allan;
pub mod calib_fit;
pub mod f_dist;
pub mod student_t;
pub mod time_base;
