//! `triad sim --truth-calib`: a simulated unit's true calibration, the
//! (I+Σ), b, temperature terms and gyro g-sensitivity the simulator applies to it
//! ([`linear_truth`]), as a calibration file that `triad correct --calib`
//! and `triad calib verify` read, so a fit can be compared with the truth.

use anyhow::anyhow;
use triad::model::{Calibration, Orientation};
use triad_sim::effects::linear_truth::linear_truth;
use triad_sim::scenes::scene::TriadEffects;

use crate::calib::file as calib_file;
use crate::scene_file::sensor_unit::LoadedUnit;

/// The effects a unit may have that the calibration model leaves out.
fn outside_the_model(e: &TriadEffects) -> Vec<&'static str> {
    let named = [
        ("noise", e.white_noise.is_some() || e.gauss_markov.is_some()),
        ("random walk", e.random_walk.is_some()),
        ("bias instability", e.bias_instability.is_some()),
        (
            "optical gyro response",
            e.ring_laser.is_some() || e.fibre_optic.is_some(),
        ),
        (
            "quantisation",
            e.increment_quantisation.is_some() || e.output_lsb.is_some(),
        ),
        ("saturation", e.saturation.is_some()),
    ];
    named
        .iter()
        .filter(|(_, on)| *on)
        .map(|(n, _)| *n)
        .collect()
}

/// The text of `unit`'s true calibration file.
pub fn render(unit: &LoadedUnit) -> anyhow::Result<String> {
    let truth = |e: &TriadEffects| {
        linear_truth(e)
            .map_err(|why| anyhow!("{}: no true calibration: {why}", unit.path.display()))
    };
    let calibration = Calibration {
        id: 0,
        accel: truth(&unit.accel)?,
        gyro: truth(&unit.gyro)?,
        // In the model since issue 22: the simulator's ω_err = G·f_true.
        g_sensitivity: unit.gyro.g_sensitivity,
    };
    let left_out = |name: &str, e: &TriadEffects| {
        let list = outside_the_model(e);
        if list.is_empty() {
            format!("{name}: nothing")
        } else {
            format!("{name}: {}", list.join(", "))
        }
    };
    let header = format!(
        "The true calibration of unit {} (seed {}), written by `triad sim --truth-calib`:\n\
         the (I+Σ), b, temperature terms and g-sensitivity G the simulator applies,\n\
         m̂ = (I+Σ)(T)·m + b(T) (+ G·f for the gyro).\n\
         Left out (not part of the model): {}; {}.",
        unit.path.display(),
        unit.seed,
        left_out("accel", &unit.accel),
        left_out("gyro", &unit.gyro),
    );
    let mut truth = toml::Table::new();
    truth.insert(
        "unit".into(),
        toml::Value::String(unit.path.display().to_string()),
    );
    // TOML integers are i64: a seed above i64::MAX is written as its text.
    let seed = i64::try_from(unit.seed)
        .map(toml::Value::Integer)
        .unwrap_or_else(|_| toml::Value::String(unit.seed.to_string()));
    truth.insert("seed".into(), seed);
    let mut extra = toml::Table::new();
    extra.insert("truth".into(), toml::Value::Table(truth));
    calib_file::render(&calibration, Orientation::RotationNone, &header, extra)
}
