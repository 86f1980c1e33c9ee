//! A unit's turn-on errors drawn once and then held: what makes many
//! records of one simulated unit share their scale factors, misalignments
//! and biases while each has its own noise.
//!
//! A scene draws its turn-on errors on every run from the run's seed (a new
//! sensor each time). [`fix_turn_on`] draws them from a unit's seed instead,
//! on the very streams the simulator would use (so a unit of seed S has the
//! turn-on bias and scale a scene run with seed S draws), adds a turn-on
//! misalignment, and folds them into the constant bias and (I + Σ): the
//! effects it returns have no turn-on effect left, and a simulator of them
//! draws only noise from its seed.

use super::bias::draw_turn_on;
use super::rng::{EffectId, Rng};
use crate::scenes::scene::TriadEffects;
use triad::model::matrix::{mul, Mat3};
use triad::model::Triad;

fn streams(seed: u64, triad: Triad, effect: EffectId) -> [Rng; 3] {
    core::array::from_fn(|axis| Rng::for_stream(seed, triad, axis as u8, effect))
}

/// The turn-on misalignment: each off-diagonal term of row i drawn as
/// σ·z from axis i's stream (x: Σxy then Σxz; y: Σyx, Σyz; z: Σzx, Σzy).
pub fn draw_misalignment(sigma: f64, triad: Triad, seed: u64) -> Mat3 {
    let mut rngs = streams(seed, triad, EffectId::TurnOnMisalignment);
    let mut m = [[0.0; 3]; 3];
    for (i, (row, rng)) in m.iter_mut().zip(rngs.iter_mut()).enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            if j != i {
                *x = sigma * rng.gaussian();
            }
        }
    }
    m
}

/// `effects` with the turn-on bias, scale and (σ `misalignment`, radians)
/// misalignment drawn from `seed` and folded in: b' = b + b₀ and
/// (I + Σ') = (I + Σ)·(I + S₀ + M₀), S₀ the turn-on scale (diagonal), M₀
/// the misalignment (off-diagonal). The simulator applies the turn-on scale
/// before (I + Σ), so with no misalignment the measurements are unchanged.
pub fn fix_turn_on(
    effects: &TriadEffects,
    triad: Triad,
    misalignment: Option<f64>,
    seed: u64,
) -> TriadEffects {
    let mut fixed = *effects;
    if let Some(sigma) = effects.turn_on_bias {
        let b0 = draw_turn_on(&sigma, &mut streams(seed, triad, EffectId::TurnOnBias));
        let b = effects.constant_bias.unwrap_or([0.0; 3]);
        fixed.constant_bias = Some(core::array::from_fn(|i| b[i] + b0[i]));
        fixed.turn_on_bias = None;
    }
    let mut turn_on = misalignment.map_or([[0.0; 3]; 3], |s| draw_misalignment(s, triad, seed));
    if let Some(sigma) = effects.turn_on_scale {
        let s0 = draw_turn_on(&sigma, &mut streams(seed, triad, EffectId::TurnOnScale));
        for (i, row) in turn_on.iter_mut().enumerate() {
            row[i] = s0[i];
        }
        fixed.turn_on_scale = None;
    }
    if effects.turn_on_scale.is_some() || misalignment.is_some() {
        let sigma = effects.scale_misalignment.unwrap_or([[0.0; 3]; 3]);
        // (I+Σ)(I+T) − I = Σ + T + Σ·T, without forming 1 + small terms.
        let product = mul(&sigma, &turn_on);
        fixed.scale_misalignment = Some(core::array::from_fn(|i| {
            core::array::from_fn(|j| sigma[i][j] + turn_on[i][j] + product[i][j])
        }));
    }
    fixed
}
