//! Published embedded-hal drivers for the ICM-42688-P and the LSM6DSOX (and
//! the LSM6DSOX's relatives) run against triad-sim's chip models: the
//! shared pieces of the tests in `tests/`, one file per published driver.
//!
//! Each test gives the model a known truth, lets the driver start the chip
//! and read it over every bus the driver supports, and compares what the
//! driver reports with the truth. Where a driver disagrees because of its
//! own bug, the test says so with the data-sheet citation and checks the
//! model's side of the disagreement instead (see `PEER_BUGS.md`).

use triad_sim::chips::source::{SampleSource, TrueSample};
use triad_sim::chips::unmodelled::UnmodelledLog;

/// Standard gravity, m/s² (what the data sheets' g is).
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// The same truth at every sample: what the chip model measures.
#[derive(Clone, Copy, Debug)]
pub struct Truth(pub TrueSample);

impl Truth {
    /// Specific force `accel_g` (g), angular rate `gyro_dps` (°/s) and
    /// temperature `celsius`, in the units drivers report.
    pub fn new(accel_g: [f64; 3], gyro_dps: [f64; 3], celsius: f64) -> Self {
        Self(TrueSample {
            specific_force: accel_g.map(|g| g * STANDARD_GRAVITY),
            angular_rate: gyro_dps.map(f64::to_radians),
            temperature: celsius,
        })
    }

    /// A truth inside `accel_fs_g` and `gyro_fs_dps` (distinct on every axis,
    /// both signs, 30–90 % of full scale) at 31.7 °C.
    pub fn within(accel_fs_g: f64, gyro_fs_dps: f64) -> Self {
        Self::new(
            [0.4, -0.3, 0.9].map(|f| f * accel_fs_g),
            [0.45, -0.6, 0.3].map(|f| f * gyro_fs_dps),
            31.7,
        )
    }

    /// Specific force, g.
    pub fn accel_g(&self) -> [f64; 3] {
        self.0.specific_force.map(|a| a / STANDARD_GRAVITY)
    }

    /// Angular rate, °/s.
    pub fn gyro_dps(&self) -> [f64; 3] {
        self.0.angular_rate.map(f64::to_degrees)
    }

    /// Temperature, °C.
    pub fn celsius(&self) -> f64 {
        self.0.temperature
    }
}

impl SampleSource for Truth {
    fn next_sample(&mut self) -> TrueSample {
        self.0
    }
}

/// Drivers compute in f32: a relative error this size is arithmetic, not disagreement.
pub const F32_RELATIVE: f64 = 1e-6;

/// Asserts that `got` is within `lsb_tolerance` codes of `want` at
/// `units_per_lsb`, plus f32 arithmetic ([`F32_RELATIVE`]).
#[track_caller]
pub fn assert_within_lsb(what: &str, got: f64, want: f64, units_per_lsb: f64, lsb_tolerance: f64) {
    let tolerance = lsb_tolerance * units_per_lsb + F32_RELATIVE * want.abs();
    assert!(
        (got - want).abs() <= tolerance,
        "{what}: driver reports {got}, truth {want} (tolerance {tolerance}, {units_per_lsb} per LSB)"
    );
}

/// Asserts that the driver touched nothing the model does not model.
#[track_caller]
pub fn assert_all_modelled(log: &UnmodelledLog) {
    assert!(
        log.is_empty(),
        "the driver touched what the model does not model: {:?}",
        log.accesses().collect::<Vec<_>>()
    );
}
