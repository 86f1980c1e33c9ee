//! Constant and turn-on biases.
//!
//! The constant bias is the same in every run; the turn-on (run-to-run) bias
//! is drawn once per run from N(0, σ²) on the effect's own stream and then
//! held (Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
//! Navigation Systems", 2nd ed., §4.4.1: fixed and run-to-run components).

use super::rng::Rng;

/// Draws one turn-on value per axis: σ_i·z_i from each axis's stream.
pub fn draw_turn_on(sigma: &[f64; 3], rngs: &mut [Rng; 3]) -> [f64; 3] {
    [
        sigma[0] * rngs[0].gaussian(),
        sigma[1] * rngs[1].gaussian(),
        sigma[2] * rngs[2].gaussian(),
    ]
}
