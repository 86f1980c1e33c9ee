//! `triad sim` with a scene's optical gyro sections: an undithered ring
//! laser on a rate table reads nothing below its lock-in rate and the
//! Adler beat above it; an open-loop fibre-optic gyro reads sin(ΔΦ)/S₀.

mod common;

use std::path::{Path, PathBuf};

use common::{dir, simulate_scene};

/// Simulates 10 s of a rate table turning at `rate` about +z with the
/// `[gyro...]` body `gyro`, at 100 Hz, into `d`/`name`.csv.
fn simulate(d: &Path, name: &str, rate: &str, gyro: &str) -> PathBuf {
    let body = format!(
        "rate_hz = 100.0\n[motion]\nkind = \"rate-table\"\naxis = \"+z\"\nrate = \"{rate}\"\n{gyro}\n"
    );
    simulate_scene(d, name, &body, "10", "1")
}

/// The mean of column `gz` of a CSV, °/s.
fn mean_gz_dps(path: &Path) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header.iter().position(|h| *h == "gz").unwrap();
    let values: Vec<f64> = lines
        .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
        .collect();
    (values.iter().sum::<f64>() / values.len() as f64).to_degrees()
}

#[test]
fn an_undithered_ring_laser_locks_below_its_lock_in_rate() {
    // A 10 cm triangle (2.26 arcsec a fringe), lock-in 0.1 °/s, no dither.
    let d = dir("rlg");
    let cavity = "[gyro.ring_laser]\narea = \"43.30127 cm^2\"\npath_length = \"30 cm\"\nlock_in = \"0.1 deg/s\"";
    let locked = simulate(&d, "locked", "0.05 deg/s", cavity);
    assert_eq!(
        mean_gz_dps(&locked),
        0.0,
        "below the lock-in rate: no fringe"
    );
    // At 1 °/s it beats at √(1 − 0.01) °/s, to a fringe over 10 s.
    let beating = simulate(&d, "beating", "1 deg/s", cavity);
    let fringe_dps = 2.2608 / 3600.0 / 10.0;
    let m = mean_gz_dps(&beating);
    assert!((m - 0.99f64.sqrt()).abs() <= fringe_dps, "{m} °/s");
    // Dithered, the same 0.05 °/s is counted (to the dither's walk and a fringe).
    let dithered = format!("{cavity}\ndither_rate = \"100 deg/s\"\ndither_frequency_hz = 400.0");
    let counted = simulate(&d, "dithered", "0.05 deg/s", &dithered);
    let m = mean_gz_dps(&counted);
    assert!((m - 0.05).abs() < 0.002, "{m} °/s");
}

#[test]
fn an_open_loop_fibre_optic_gyro_reads_the_sine_of_its_phase() {
    // 1 km on a 10 cm coil at 1550 nm: S₀ = 1.352 rad per rad/s, π/2 at
    // 66.6 °/s. At 100 °/s the phase is 2.360 rad: the output is
    // sin(2.360)/S₀ = 0.521 rad/s = 29.8 °/s, as 33.1 °/s reads too.
    let d = dir("fog");
    let coil = "[gyro.fibre_optic]\nturns = 3183.1\ncoil_diameter = \"10 cm\"\nwavelength = \"1550 nm\"\nreadout = \"open\"";
    let fast = simulate(&d, "fast", "100 deg/s", coil);
    let s0 = 8.0 * std::f64::consts::PI * 3183.1 * std::f64::consts::PI * 0.01
        / 4.0
        / (1550e-9 * 299_792_458.0);
    let expected = (s0 * 100f64.to_radians()).sin() / s0;
    let m = mean_gz_dps(&fast);
    assert!(
        (m - expected.to_degrees()).abs() < 1e-9,
        "{m} °/s vs {}",
        expected.to_degrees()
    );
    assert!(m < 66.6, "compressed beyond π/2");
    let mirror = (std::f64::consts::PI / s0).to_degrees() - 100.0;
    let slow = simulate(&d, "slow", &format!("{mirror} deg/s"), coil);
    assert!(
        (mean_gz_dps(&slow) - m).abs() < 1e-6,
        "two rates, one output"
    );
}
