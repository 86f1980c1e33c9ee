//! 3×3 helpers the fits need beyond [`triad::model::matrix`]: the upper
//! Cholesky factor and the eigenvalues of a symmetric matrix.
#![allow(clippy::needless_range_loop)] // index form reads as the formula

pub use triad::model::matrix::Mat3;

/// The upper triangular U with positive diagonal and W = UᵀU, or `None` if
/// W is not (numerically) positive definite.
pub fn cholesky_upper(w: &Mat3) -> Option<Mat3> {
    let u00 = sqrt_positive(w[0][0])?;
    let u01 = w[0][1] / u00;
    let u02 = w[0][2] / u00;
    let u11 = sqrt_positive(w[1][1] - u01 * u01)?;
    let u12 = (w[1][2] - u01 * u02) / u11;
    let u22 = sqrt_positive(w[2][2] - u02 * u02 - u12 * u12)?;
    Some([[u00, u01, u02], [0.0, u11, u12], [0.0, 0.0, u22]])
}

fn sqrt_positive(x: f64) -> Option<f64> {
    (x > 0.0 && x.is_finite()).then(|| libm::sqrt(x))
}

/// aᵀ·a.
pub fn gram(a: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[0][i] * a[0][j] + a[1][i] * a[1][j] + a[2][i] * a[2][j];
        }
    }
    out
}

/// The eigenvalues of a symmetric matrix, ascending (the closed form of
/// Smith, "Eigenvalues of a symmetric 3×3 matrix", CACM 4(4), 1961).
pub fn symmetric_eigenvalues(a: &Mat3) -> [f64; 3] {
    let p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    let q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    if p1 == 0.0 {
        let mut d = [a[0][0], a[1][1], a[2][2]];
        d.sort_unstable_by(f64::total_cmp);
        return d;
    }
    let p2 = (a[0][0] - q) * (a[0][0] - q)
        + (a[1][1] - q) * (a[1][1] - q)
        + (a[2][2] - q) * (a[2][2] - q)
        + 2.0 * p1;
    let p = libm::sqrt(p2 / 6.0);
    let mut b = *a;
    for (i, row) in b.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (*x - if i == j { q } else { 0.0 }) / p;
        }
    }
    let r = (triad::model::matrix::determinant(&b) / 2.0).clamp(-1.0, 1.0);
    let phi = libm::acos(r) / 3.0;
    let e_max = q + 2.0 * p * libm::cos(phi);
    let e_min = q + 2.0 * p * libm::cos(phi + 2.0 * core::f64::consts::PI / 3.0);
    let e_mid = 3.0 * q - e_max - e_min;
    [e_min, e_mid, e_max]
}

/// The affine dimension of a point set (0 point, 1 line, 2 plane, 3 space)
/// and the RMS distance of the points from their best-fitting plane
/// (√(λ_min/n) of the centred scatter matrix). A direction counts when its
/// scatter eigenvalue exceeds `relative_tolerance²` times the largest.
pub fn spread(
    points: impl Iterator<Item = [f64; 3]> + Clone,
    relative_tolerance: f64,
) -> (u8, f64) {
    let mut n = 0usize;
    let mut mean = [0.0; 3];
    for p in points.clone() {
        n += 1;
        for (m, x) in mean.iter_mut().zip(p) {
            *m += x;
        }
    }
    if n == 0 {
        return (0, 0.0);
    }
    for m in mean.iter_mut() {
        *m /= n as f64;
    }
    let mut s = [[0.0; 3]; 3];
    for p in points {
        let d = [p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]];
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] += d[i] * d[j];
            }
        }
    }
    let e = symmetric_eigenvalues(&s);
    let largest = e[2].max(0.0);
    let tol = relative_tolerance * relative_tolerance * largest;
    let dimension = if largest == 0.0 {
        0
    } else {
        e.iter().filter(|&&x| x > tol).count() as u8
    };
    (dimension, libm::sqrt(e[0].max(0.0) / n as f64))
}
