//! Scale-factor errors and misalignment: m = (I + Σ)·x.
//!
//! Σ's diagonal holds the scale-factor errors, its off-diagonal terms the
//! misalignments (cross-coupling), as in the calibration model of DESIGN.md.
//! The product is computed as x + Σ·x so a small Σ loses no precision to the
//! rounding of 1 + σ.

/// Applies (I + Σ) to `x`.
pub fn apply(sigma: &[[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    let mut y = x;
    for (yi, row) in y.iter_mut().zip(sigma) {
        *yi += row[0] * x[0] + row[1] * x[1] + row[2] * x[2];
    }
    y
}

/// Applies per-axis scale-factor errors: x_i·(1 + s_i), as x_i + s_i·x_i.
pub fn apply_diagonal(scale: &[f64; 3], x: [f64; 3]) -> [f64; 3] {
    [
        x[0] + scale[0] * x[0],
        x[1] + scale[1] * x[1],
        x[2] + scale[2] * x[2],
    ]
}
