//! Optical gyros: ring laser and fibre optic.

pub mod fibre_optic;
pub mod ring_laser;
