//! The calibration a triad's effects amount to: the (I+Σ), b and
//! temperature terms of the core's model (m̂ = (I+Σ)(T)·m + b(T)) that the
//! simulator applies, so that a simulated unit's truth can be written as a
//! calibration file and compared with what a fit finds.

use crate::scenes::scene::TriadEffects;
use triad::model::calibration::IDENTITY;
use triad::model::{TemperatureTerms, TriadCalibration};

/// Why a triad's effects have no one calibration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoTruth {
    /// A turn-on effect is still drawn per run (fix it with
    /// [`super::turn_on::fix_turn_on`] first).
    TurnOnDrawnPerRun,
}

impl core::fmt::Display for NoTruth {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            NoTruth::TurnOnDrawnPerRun => write!(
                f,
                "a turn-on bias or scale is drawn anew on every run, so no one calibration is true"
            ),
        }
    }
}

/// The linear model of `effects`: the simulator measures
/// (I+Σ)·diag(1 + s·ΔT)·m + b + c·ΔT, which is (I+Σ)(T) = (I+Σ) + ΔT·D with
/// D = (I+Σ)·diag(s), and b(T) = b + c·ΔT (c2 = c3 = 0), about the effects'
/// reference temperature. Noise, g-sensitivity, optics, quantisation and
/// saturation are not part of the model and are left out.
pub fn linear_truth(effects: &TriadEffects) -> Result<TriadCalibration, NoTruth> {
    if effects.turn_on_bias.is_some() || effects.turn_on_scale.is_some() {
        return Err(NoTruth::TurnOnDrawnPerRun);
    }
    let sigma = effects.scale_misalignment.unwrap_or([[0.0; 3]; 3]);
    let m: [[f64; 3]; 3] =
        core::array::from_fn(|i| core::array::from_fn(|j| IDENTITY[i][j] + sigma[i][j]));
    let temperature = effects.temperature.map(|td| TemperatureTerms {
        reference_c: td.reference,
        bias_coefficients: core::array::from_fn(|i| [td.bias_per_degree[i], 0.0, 0.0]),
        scale_misalignment_per_c: core::array::from_fn(|i| {
            core::array::from_fn(|j| m[i][j] * td.scale_per_degree[j])
        }),
    });
    Ok(TriadCalibration {
        scale_misalignment: m,
        bias: effects.constant_bias.unwrap_or([0.0; 3]),
        temperature,
    })
}
