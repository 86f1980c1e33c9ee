//! Non-negative least squares for the five-term model, exact by enumeration:
//! every support set (31 of them) is solved by unconstrained least squares
//! (Cholesky of the column-scaled normal matrix) and the feasible solution
//! of least residual is kept — the NNLS optimum is the unconstrained optimum
//! on its own support.
//!
//! The rows are already weighted (independent points: each row times √w) or
//! whitened (correlated points: the rows of L⁻¹A, V = LLᵀ), so the residual
//! is a plain sum of squares.

use super::cholesky::{cholesky, forward_subst};
use super::noise_terms::TERMS;

/// A TERMS × TERMS matrix.
pub(crate) type Matrix = [[f64; TERMS]; TERMS];

/// The least-squares solution on the best support.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Solution {
    /// The squared coefficients (zero off the support).
    pub coef: [f64; TERMS],
    /// The covariance of the coefficients on the support (zero elsewhere),
    /// unscaled: (AᵀA)⁻¹.
    pub covariance: Matrix,
    /// Bit k set when term k is in the support.
    pub support: u32,
    /// The residual sum of squares.
    pub chi2: f64,
}

/// The normal matrix and right-hand side of the terms `idx[..n]`.
#[allow(clippy::needless_range_loop)]
fn normal_equations(
    rows: &[[f64; TERMS]],
    data: &[f64],
    n: usize,
    idx: &[usize; TERMS],
) -> (Matrix, [f64; TERMS]) {
    let mut g = [[0.0; TERMS]; TERMS];
    let mut r = [0.0; TERMS];
    for (row, &d) in rows.iter().zip(data) {
        for i in 0..n {
            let a = row[idx[i]];
            r[i] += a * d;
            for j in 0..n {
                g[i][j] += a * row[idx[j]];
            }
        }
    }
    (g, r)
}

/// Solves (LLᵀ)·x = b on the leading n terms (L from [`cholesky`]).
fn cholesky_solve(l: &Matrix, n: usize, b: &[f64; TERMS]) -> [f64; TERMS] {
    let l = l.as_flattened();
    let mut y = *b;
    forward_subst(l, TERMS, &mut y[..n]);
    let mut x = [0.0; TERMS];
    for i in (0..n).rev() {
        let mut s = y[i];
        for k in i + 1..n {
            s -= l[k * TERMS + i] * x[k];
        }
        x[i] = s / l[i * TERMS + i];
    }
    x
}

/// The support's term indices.
fn members(support: u32) -> ([usize; TERMS], usize) {
    let mut idx = [0; TERMS];
    let mut n = 0;
    for (k, slot) in (0..TERMS).filter(|k| support & (1 << k) != 0).zip(0..) {
        idx[slot] = k;
        n += 1;
    }
    (idx, n)
}

/// Unconstrained least squares on one support: the coefficients (full
/// length, zero off the support) and their covariance; None when the normal
/// matrix is singular.
#[allow(clippy::needless_range_loop)]
pub(crate) fn solve_support(
    rows: &[[f64; TERMS]],
    data: &[f64],
    support: u32,
) -> Option<([f64; TERMS], Matrix)> {
    let (idx, n) = members(support);
    if n == 0 || n > rows.len() {
        return None;
    }
    let (g, r) = normal_equations(rows, data, n, &idx);
    // Column scaling: the bases differ by many decades over the τ range.
    let mut scale = [1.0; TERMS];
    for i in 0..n {
        if g[i][i].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        scale[i] = 1.0 / libm::sqrt(g[i][i]);
    }
    let mut gs = [[0.0; TERMS]; TERMS];
    let mut rs = [0.0; TERMS];
    for i in 0..n {
        rs[i] = r[i] * scale[i];
        for j in 0..n {
            gs[i][j] = g[i][j] * scale[i] * scale[j];
        }
    }
    let mut l = gs;
    cholesky(l.as_flattened_mut(), n, TERMS, 1e-13).ok()?;
    let xs = cholesky_solve(&l, n, &rs);
    let mut coef = [0.0; TERMS];
    let mut cov = [[0.0; TERMS]; TERMS];
    for i in 0..n {
        coef[idx[i]] = xs[i] * scale[i];
        let mut e = [0.0; TERMS];
        e[i] = 1.0;
        let col = cholesky_solve(&l, n, &e);
        for j in 0..n {
            cov[idx[j]][idx[i]] = col[j] * scale[i] * scale[j];
        }
    }
    Some((coef, cov))
}

/// The residual sum of squares of `coef`.
pub(crate) fn residual(rows: &[[f64; TERMS]], data: &[f64], coef: &[f64; TERMS]) -> f64 {
    rows.iter()
        .zip(data)
        .map(|(row, &d)| {
            let model: f64 = row.iter().zip(coef).map(|(a, c)| a * c).sum();
            (d - model) * (d - model)
        })
        .sum()
}

/// The NNLS solution over every support.
pub(crate) fn solve(rows: &[[f64; TERMS]], data: &[f64]) -> Solution {
    let zero = [0.0; TERMS];
    let mut best = Solution {
        coef: zero,
        covariance: [zero; TERMS],
        support: 0,
        chi2: residual(rows, data, &zero),
    };
    for support in 1u32..(1 << TERMS) {
        if let Some((coef, covariance)) = solve_support(rows, data, support) {
            if coef.iter().all(|&c| c >= 0.0 && c.is_finite()) {
                let chi2 = residual(rows, data, &coef);
                if chi2 < best.chi2 {
                    best = Solution {
                        coef,
                        covariance,
                        support,
                        chi2,
                    };
                }
            }
        }
    }
    best
}
