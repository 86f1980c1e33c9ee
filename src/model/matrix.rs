//! 3×3 f64 linear algebra for loading a calibration (never in the hot path):
//! determinant, inverse, 1-norm condition number, and an independent
//! Gaussian-elimination solve for the f64 reference.

/// A 3×3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The identity.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The determinant (cofactor expansion along the first row).
pub fn determinant(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// The inverse by the adjugate, or `None` if the determinant is zero or the
/// result is not finite.
pub fn inverse(m: &Mat3) -> Option<Mat3> {
    let det = determinant(m);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // adj(m)[i][j] = cofactor(m)[j][i]
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let adj = [
        [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
        [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
        [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
    ];
    let mut inv = [[0.0; 3]; 3];
    for (inv_row, adj_row) in inv.iter_mut().zip(adj.iter()) {
        for (x, a) in inv_row.iter_mut().zip(adj_row.iter()) {
            *x = a / det;
        }
    }
    if inv.iter().flatten().all(|x| x.is_finite()) {
        Some(inv)
    } else {
        None
    }
}

/// The 1-norm ‖m‖₁: the largest column sum of absolute values.
pub fn norm_1(m: &Mat3) -> f64 {
    (0..3).fold(0.0f64, |best, col| {
        best.max(m[0][col].abs() + m[1][col].abs() + m[2][col].abs())
    })
}

/// κ₁(m) = ‖m‖₁·‖m⁻¹‖₁, or `None` when `m` is singular (a zero pivot) or
/// its inverse overflows. The inverse comes from [`solve`] column by column,
/// which never forms the determinant, so entries far from 1 (1e±300) give
/// a huge κ rather than a spurious over- or underflow to "singular".
pub fn condition_number(m: &Mat3) -> Option<f64> {
    let mut inv = [[0.0; 3]; 3];
    for (col, e) in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        .iter()
        .enumerate()
    {
        let x = solve(m, e)?;
        for (row, v) in inv.iter_mut().zip(x) {
            row[col] = v;
        }
    }
    let kappa = norm_1(m) * norm_1(&inv);
    (kappa.is_finite()).then_some(kappa)
}

/// a·b.
pub fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    out
}

/// a·v.
pub fn mul_vec(a: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (o, row) in out.iter_mut().zip(a.iter()) {
        *o = row[0] * v[0] + row[1] * v[1] + row[2] * v[2];
    }
    out
}

/// aᵀ·v.
pub fn mul_transpose_vec(a: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    [
        a[0][0] * v[0] + a[1][0] * v[1] + a[2][0] * v[2],
        a[0][1] * v[0] + a[1][1] * v[1] + a[2][1] * v[2],
        a[0][2] * v[0] + a[1][2] * v[1] + a[2][2] * v[2],
    ]
}

/// aᵀ·b.
pub fn transpose_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j];
        }
    }
    out
}

/// Solves m·x = v by Gaussian elimination with partial pivoting; `None` if a
/// pivot is zero. Deliberately a different algorithm from [`inverse`], so the
/// f64 reference checks the folded coefficients rather than repeating them.
#[allow(clippy::needless_range_loop)] // index form reads as the textbook algorithm
pub fn solve(m: &Mat3, v: &[f64; 3]) -> Option<[f64; 3]> {
    let mut a = *m;
    let mut b = *v;
    for col in 0..3 {
        // Partial pivoting: bring the largest |entry| of this column up.
        let mut pivot = col;
        for row in col + 1..3 {
            if a[row][col].abs() > a[pivot][col].abs() {
                pivot = row;
            }
        }
        if a[pivot][col] == 0.0 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let factor = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= factor * a[col][k];
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let mut sum = b[row];
        for k in row + 1..3 {
            sum -= a[row][k] * x[k];
        }
        x[row] = sum / a[row][row];
    }
    Some(x)
}
