//! triad-sim: what a sensor triad measures in a scene, and the software chips
//! that serve it over a bus. no_std, so it also runs inside the emulated
//! board; the host simulates in f64 with the same code.
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod chips;
pub mod effects;
pub mod grade;
pub mod motion;
pub mod optics;
pub mod scenes;
