//! The starting point of the accelerometer fit: an algebraic (linear
//! least-squares) ellipsoid through the static means.
//!
//! With p = f̂/g, fit pᵀA·p + 2·lᵀp = 1 (9 unknowns: the symmetric A and l;
//! the right-hand side 1 fixes the scale and excludes ellipsoids through the
//! origin, which a sensor with |b| ≪ g never gives). Completing the square,
//! (p − c)ᵀA(p − c) = k with c = −A⁻¹l and k = 1 + cᵀAc, so W = A/k is the
//! metric of the ellipsoid |T(f̂ − b)| = g with TᵀT = W, b = g·c, and T is
//! the upper Cholesky factor of W (the convention of
//! [`accel_fit`](crate::calib_fit::fits::accel_fit)). The algebraic fit minimises no physical
//! error, so it only starts the Gauss–Newton/LM iteration; it needs no
//! initial guess, which is what makes the start robust.

use crate::calib_fit::numerics::error::{check_condition, NumericsError};
use crate::calib_fit::numerics::qr::GivensLs;
use crate::calib_fit::numerics::small3::{cholesky_upper, Mat3};
use triad::model::matrix;

/// Why the algebraic ellipsoid was not found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EllipsoidError {
    /// The linear fit is ill-conditioned (the same geometry leaves the
    /// ellipsoid undetermined).
    Numerics(NumericsError),
    /// The quadric fitted is not an ellipsoid around the origin.
    NotAnEllipsoid,
}

impl From<NumericsError> for EllipsoidError {
    fn from(e: NumericsError) -> Self {
        EllipsoidError::Numerics(e)
    }
}

/// (T, b) of the algebraic ellipsoid through `means` (m/s²) for gravity `g`;
/// also the scaled condition number of the linear fit.
pub fn algebraic_fit(means: &[[f64; 3]], g: f64) -> Result<(Mat3, [f64; 3], f64), EllipsoidError> {
    let mut ls = GivensLs::<9>::new();
    for m in means {
        let [x, y, z] = [m[0] / g, m[1] / g, m[2] / g];
        ls.add_row(
            [
                x * x,
                y * y,
                z * z,
                2.0 * x * y,
                2.0 * x * z,
                2.0 * y * z,
                2.0 * x,
                2.0 * y,
                2.0 * z,
            ],
            1.0,
        );
    }
    // The same geometry that leaves the ellipsoid undetermined leaves this
    // linear design ill-conditioned: refuse here, before a start built on
    // rounding noise sends the iteration astray.
    let condition = ls.scaled_condition();
    let limit = crate::calib_fit::fits::accel_fit::MAX_CONDITION;
    check_condition(condition, limit)?;
    let a = ls
        .solve()
        .map_err(|_| NumericsError::IllConditioned { condition, limit })?;
    let quadric: Mat3 = [[a[0], a[3], a[4]], [a[3], a[1], a[5]], [a[4], a[5], a[2]]];
    let linear = [a[6], a[7], a[8]];
    let c = matrix::solve(&quadric, &linear).ok_or(EllipsoidError::NotAnEllipsoid)?;
    let c = [-c[0], -c[1], -c[2]];
    let ac = matrix::mul_vec(&quadric, &c);
    let k = 1.0 + c[0] * ac[0] + c[1] * ac[1] + c[2] * ac[2];
    if !(k > 0.0 && k.is_finite()) {
        return Err(EllipsoidError::NotAnEllipsoid);
    }
    let w = quadric.map(|row| row.map(|x| x / k));
    let t = cholesky_upper(&w).ok_or(EllipsoidError::NotAnEllipsoid)?;
    Ok((t, [g * c[0], g * c[1], g * c[2]], condition))
}
