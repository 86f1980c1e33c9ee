//! The Cholesky factorisation A = LLᵀ of a symmetric positive-definite
//! matrix and the forward substitution with its factor: the fit whitens by
//! the octave estimates' covariance with them ([`super::gls`]) and solves
//! each support's normal equations ([`super::nnls`]).
//!
//! Matrices are row-major slices with a row `stride` (the leading n × n
//! block of a larger array is factored in place), so the core needs no
//! allocation.

/// The matrix is not positive definite (to the pivot tolerance given).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NotPositiveDefinite;

/// Factors the leading n × n block of `a` in place: its lower triangle
/// becomes L (the upper one is left as it was and never read). A pivot must
/// exceed `min_pivot` times the original diagonal element (0: just
/// positive) and be finite.
// Indices as in the textbook formula: checkable at a glance.
#[allow(clippy::needless_range_loop)]
pub(crate) fn cholesky(
    a: &mut [f64],
    n: usize,
    stride: usize,
    min_pivot: f64,
) -> Result<(), NotPositiveDefinite> {
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * stride + j];
            for k in 0..j {
                s -= a[i * stride + k] * a[j * stride + k];
            }
            if i == j {
                let positive = s > min_pivot * a[i * stride + i].abs() && s.is_finite();
                if !positive {
                    return Err(NotPositiveDefinite);
                }
                a[i * stride + i] = libm::sqrt(s);
            } else {
                a[i * stride + j] = s / a[j * stride + j];
            }
        }
    }
    Ok(())
}

/// Solves L·y = b in place (L the factor [`cholesky`] left in `l`, of
/// order `b.len()`).
pub(crate) fn forward_subst(l: &[f64], stride: usize, b: &mut [f64]) {
    for i in 0..b.len() {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * stride + k] * b[k];
        }
        b[i] = s / l[i * stride + i];
    }
}
