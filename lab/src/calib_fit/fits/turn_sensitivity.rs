//! How an integrated turn moves when the gyro's (I+Σ) changes, or the
//! specific forces that set its g-sensitivity's bias during the move: the
//! rig-free fits' Jacobian in one pass over the move, instead of
//! re-integrating it per parameter (central differences took 18
//! integrations of every move per Levenberg–Marquardt step).
//!
//! First-order perturbation of the attitude: with q̇ = ½·q ⊗ (0, ω) (body
//! rate) and q(0) = 1, a change δω(t) of the rate turns the end attitude by
//! q(T) ⊗ exp(δθ/2), δθ = R_Tᵀ·∫ R_t·δω(t) dt (R_t the rotation of q(t)).
//! The rate is ω = K·(ω̂ − b(t)), K = (I+Σ)⁻¹, so a change of entry (a, c) of
//! (I+Σ) changes K by −K·e_a·e_cᵀ·K and the rate by −K_{:,a}·ω_c(t):
//! δθ = −R_Tᵀ·A_c·K_{:,a} with A_c = ∫ ω_c(t)·R_t dt. With a g-sensitivity
//! the bias is c + G·f(s), f interpolated between the poses' forces F₀ and
//! F₁ ([`crate::calib_fit::fits::rig_free`]), and a change of F₀ or F₁ gives
//! δθ = −R_Tᵀ·(M₀·δF₀ + M₁·δF₁), M_e = ∫ R_t·K·G·∂f/∂F_e dt.
//!
//! The integrals are trapezoid sums at the record's samples: the
//! derivative of the continuous turn, not of the discrete RK4 steps, which
//! differ by O((ω·dt)²) relatively (the test beside the fit compares them
//! with central differences).

use crate::calib_fit::fits::rig_free::{cross, MoveSample};
use crate::calib_fit::numerics::small3::Mat3;
use triad::model::matrix;

/// What one pass over a move gathers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TurnSensitivity {
    /// A_c = ∫ ω_c(t)·R_t dt, c = 0..3 (the corrected rate's axis c).
    pub rate_moments: [Mat3; 3],
    /// M₀ and M₁ (module doc) when the bias has a g-sensitivity.
    pub force: Option<[Mat3; 2]>,
}

/// Gathers a [`TurnSensitivity`] from a move's samples.
pub(crate) struct Accumulator {
    /// K·G and the poses' forces F₀, F₁ when the bias has a g-sensitivity.
    g: Option<(Mat3, [[f64; 3]; 2])>,
    out: TurnSensitivity,
}

impl Accumulator {
    /// `kg` = K·G and the move's end forces, when the bias has a G.
    pub fn new(kg: Option<(Mat3, [[f64; 3]; 2])>) -> Accumulator {
        Accumulator {
            out: TurnSensitivity {
                rate_moments: [[[0.0; 3]; 3]; 3],
                force: kg.map(|_| [[[0.0; 3]; 3]; 2]),
            },
            g: kg,
        }
    }

    /// Adds one sample of the move.
    pub fn add(&mut self, sample: &MoveSample) {
        let r = crate::calib_fit::numerics::quaternion::to_matrix(&sample.q);
        for (moment, &w) in self.out.rate_moments.iter_mut().zip(&sample.rate) {
            add_scaled(moment, &r, sample.weight * w);
        }
        if let (Some((kg, forces)), Some(m)) = (&self.g, &mut self.out.force) {
            let n = matrix::mul(&r, kg);
            let [d0, d1] = force_derivatives(forces, sample.s);
            add_scaled(&mut m[0], &matrix::mul(&n, &d0), sample.weight);
            add_scaled(&mut m[1], &matrix::mul(&n, &d1), sample.weight);
        }
    }

    /// What the samples gave.
    pub fn finish(self) -> TurnSensitivity {
        self.out
    }
}

fn add_scaled(sum: &mut Mat3, m: &Mat3, w: f64) {
    for (row, m_row) in sum.iter_mut().zip(m) {
        for (x, y) in row.iter_mut().zip(m_row) {
            *x += w * y;
        }
    }
}

/// ∂f/∂F₀ and ∂f/∂F₁ at fraction `s`, f = m·v/|v| with v = F₀ + s(F₁ − F₀)
/// and m = |F₀| + s(|F₁| − |F₀|) ([`crate::calib_fit::fits::rig_free::force_along`]).
fn force_derivatives([f0, f1]: &[[f64; 3]; 2], s: f64) -> [Mat3; 2] {
    let norm = |v: &[f64; 3]| libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    let v = [0, 1, 2].map(|i| f0[i] + s * (f1[i] - f0[i]));
    let (n, n0, n1) = (norm(&v), norm(f0), norm(f1));
    if n == 0.0 || n0 == 0.0 || n1 == 0.0 {
        return [[[0.0; 3]; 3]; 2];
    }
    let u = v.map(|x| x / n);
    let ratio = (n0 + s * (n1 - n0)) / n;
    // ∂f/∂F_e = w_e·(ratio·(I − u·uᵀ) + u·F̂_eᵀ), w₀ = 1 − s, w₁ = s.
    let part = |w: f64, f: &[f64; 3], nf: f64| -> Mat3 {
        core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let projector = if i == j { 1.0 } else { 0.0 } - u[i] * u[j];
                w * (ratio * projector + u[i] * f[j] / nf)
            })
        })
    };
    [part(1.0 - s, f0, n0), part(s, f1, n1)]
}

/// ∂(residual c)/∂(I+Σ)_{a,b} for the residual e_cᵀ·(R_Tᵀ·u − u'), at the
/// move's end attitude `q_end`, `k` = (I+Σ)⁻¹, `predicted` = R_Tᵀ·u and
/// `across` the two directions e_c: −(R_T·(e_c × predicted))ᵀ·A_b·K_{:,a},
/// in the order of (I+Σ)'s entries row by row.
pub(crate) fn scale_gradient(
    sensitivity: &TurnSensitivity,
    q_end: &crate::calib_fit::numerics::quaternion::Quat,
    k: &Mat3,
    predicted: &[f64; 3],
    across: &[[f64; 3]; 2],
) -> [[f64; 9]; 2] {
    across.map(|e| {
        let v = crate::calib_fit::numerics::quaternion::rotate(q_end, &cross(&e, predicted));
        // vᵀ·A_b, for each b.
        let va: [[f64; 3]; 3] = sensitivity
            .rate_moments
            .map(|a| core::array::from_fn(|n| (0..3).map(|m| v[m] * a[m][n]).sum::<f64>()));
        core::array::from_fn(|p| {
            let (a, b) = (p / 3, p % 3);
            -(0..3).map(|n| va[b][n] * k[n][a]).sum::<f64>()
        })
    })
}

/// The end attitude's change δθ (in the end body frame) for changes `d0`
/// and `d1` of the poses' forces: −R_Tᵀ·(M₀·δF₀ + M₁·δF₁); zero without G.
pub(crate) fn force_turn(
    sensitivity: &TurnSensitivity,
    q_end: &crate::calib_fit::numerics::quaternion::Quat,
    d0: &[f64; 3],
    d1: &[f64; 3],
) -> [f64; 3] {
    let Some([m0, m1]) = &sensitivity.force else {
        return [0.0; 3];
    };
    let (a, b) = (matrix::mul_vec(m0, d0), matrix::mul_vec(m1, d1));
    let sum = [0, 1, 2].map(|i| -(a[i] + b[i]));
    crate::calib_fit::numerics::quaternion::rotate_inverse(q_end, &sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib_fit::fits::rig_free::force_along;

    #[test]
    fn the_force_derivatives_match_central_differences() {
        let forces = [[0.3, -9.6, 1.2], [7.1, 0.4, -6.5]];
        let h = 1e-6;
        for s in [0.0, 0.3, 0.8, 1.0] {
            let d = force_derivatives(&forces, s);
            for e in 0..2 {
                for j in 0..3 {
                    let shifted = |x: f64| {
                        let mut f = forces;
                        f[e][j] += x;
                        force_along(&f, s)
                    };
                    let (p, m) = (shifted(h), shifted(-h));
                    for i in 0..3 {
                        let numeric = (p[i] - m[i]) / (2.0 * h);
                        assert!(
                            (numeric - d[e][i][j]).abs() < 1e-8,
                            "s {s} F{e} ({i},{j}): {numeric} vs {}",
                            d[e][i][j]
                        );
                    }
                }
            }
        }
    }
}
