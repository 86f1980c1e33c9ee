//! Levenberg–Marquardt for the nonlinear fits, with Marquardt's diagonal
//! scaling: each step solves [J; √λ·diag(‖J_k‖)]·δ ≈ [−r; 0] by QR
//! ([`GivensLs`]), so JᵀJ is never formed. A step is taken when it lowers
//! Σr²; λ shrinks tenfold after a success and grows tenfold after a failure.
//! It stops when a taken step changes every parameter by ≤ 1e-13 of its
//! size (or of 1), or when no step, however short, lowers the cost (λ > 1e10).

use crate::calib_fit::numerics::error::NumericsError;
use crate::calib_fit::numerics::qr::GivensLs;

/// A least-squares problem in N parameters.
pub trait Problem<const N: usize> {
    /// Σ r² at `p`.
    fn cost(&self, p: &[f64; N]) -> f64;
    /// Calls `row(∂r/∂p, r)` for every residual r at `p`.
    fn rows(&self, p: &[f64; N], row: &mut dyn FnMut([f64; N], f64));
}

/// Minimises `problem` from `p` in at most `max_iterations`; returns the
/// solution and the iterations run.
pub fn minimise<const N: usize>(
    problem: &impl Problem<N>,
    mut p: [f64; N],
    max_iterations: u32,
) -> Result<([f64; N], u32), NumericsError> {
    let mut lambda = 1e-3;
    let mut current = problem.cost(&p);
    for iteration in 1..=max_iterations {
        let mut column_sq = [0.0; N];
        let mut ls = GivensLs::<N>::new();
        problem.rows(&p, &mut |grad, r| {
            for (c, x) in column_sq.iter_mut().zip(grad) {
                *c += x * x;
            }
            ls.add_row(grad, -r);
        });
        for (k, c) in column_sq.iter().enumerate() {
            let mut row = [0.0; N];
            row[k] = libm::sqrt(lambda * c);
            ls.add_row(row, 0.0);
        }
        let step = ls.solve()?;
        let mut trial = p;
        for (x, d) in trial.iter_mut().zip(step) {
            *x += d;
        }
        let trial_cost = problem.cost(&trial);
        let small = step
            .iter()
            .zip(p.iter())
            .all(|(d, x)| d.abs() <= 1e-13 * x.abs().max(1.0));
        if trial_cost <= current {
            p = trial;
            current = trial_cost;
            lambda = (lambda / 10.0).max(1e-15);
            if small {
                return Ok((p, iteration));
            }
        } else {
            lambda *= 10.0;
            // No step, however short, lowers the cost: a minimum to rounding.
            if lambda > 1e10 || small {
                return Ok((p, iteration));
            }
        }
    }
    Err(NumericsError::NoConvergence {
        iterations: max_iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a·exp(b·x) through exact points.
    struct Exponential;

    const XS: [f64; 5] = [0.0, 0.5, 1.0, 1.5, 2.0];

    impl Problem<2> for Exponential {
        fn cost(&self, p: &[f64; 2]) -> f64 {
            let mut s = 0.0;
            self.rows(p, &mut |_, r| s += r * r);
            s
        }
        fn rows(&self, p: &[f64; 2], row: &mut dyn FnMut([f64; 2], f64)) {
            for x in XS {
                let e = libm::exp(p[1] * x);
                let y = 2.0 * libm::exp(-0.7 * x);
                row([e, p[0] * x * e], p[0] * e - y);
            }
        }
    }

    #[test]
    fn it_finds_an_exponential_from_a_poor_start() {
        let (p, iterations) = minimise(&Exponential, [1.0, 0.5], 100).unwrap();
        assert!(
            (p[0] - 2.0).abs() < 1e-10 && (p[1] + 0.7).abs() < 1e-10,
            "{p:?}"
        );
        assert!(iterations < 100);
        assert_eq!(
            minimise(&Exponential, [1.0, 0.5], 1),
            Err(NumericsError::NoConvergence { iterations: 1 })
        );
    }
}
