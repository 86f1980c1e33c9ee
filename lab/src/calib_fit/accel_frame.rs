//! The frame of the rig-free fits' results. The accelerometer fit
//! ([`crate::calib_fit::fits::accel_fit`]) sees only |(I+Σ)⁻¹(f̂ − b)| = g, which a rotation
//! of the corrected axes leaves unchanged, so it reports the upper
//! triangular (I+Σ) = A: corrected z along the z sensing axis, corrected x
//! in the xz sensing plane. Any other (I+Σ) T of the same accelerometer is
//! A·Q with Q a rotation (T's RQ decomposition), and the corrected axes are
//! Q times T's. The gyro fit ([`crate::calib_fit::fits::rig_free`]) matches gravity
//! directions in those corrected axes, so its (I+Σ) is G = T_g·Qᵀ where T_g
//! is the gyro's in T's axes: its off-diagonal terms differ from T_g's by
//! the accelerometer's misalignment. [`in_accel_frame`] puts a truth given
//! in body axes (`triad sim --truth-calib`) into the fits' frame, so the
//! two compare entry by entry.

use crate::calib_fit::numerics::small3::Mat3;
use triad::model::matrix;

/// A truth's (I+Σ)'s in the rig-free fits' frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InAccelFrame {
    /// The accelerometer's upper triangular (I+Σ), A (positive diagonal).
    pub accel: Mat3,
    /// The gyroscope's (I+Σ) in A's corrected axes: T_g·Qᵀ.
    pub gyro: Mat3,
    /// The rotation Q from the truth's axes to the corrected ones.
    pub rotation: Mat3,
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `v` less its components along the unit vectors `units`, and the
/// coefficients removed.
fn reject(v: &[f64; 3], units: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut rest = *v;
    let mut coefficients = [0.0; 3];
    for (c, u) in coefficients.iter_mut().zip(units) {
        *c = dot(v, u);
        for k in 0..3 {
            rest[k] -= *c * u[k];
        }
    }
    (rest, coefficients)
}

/// The RQ decomposition T = A·Q (A upper triangular with a positive
/// diagonal, Q orthonormal), by Gram–Schmidt on T's rows from the last:
/// row 3 = A₃₃·q₃, row 2 = A₂₂·q₂ + A₂₃·q₃, row 1 = A₁₁·q₁ + A₁₂·q₂ + A₁₃·q₃.
/// `None` when T is singular (a row in the span of those below it).
pub fn rq(t: &Mat3) -> Option<(Mat3, Mat3)> {
    let mut a = [[0.0; 3]; 3];
    let mut q = [[0.0; 3]; 3];
    for i in (0..3).rev() {
        let below = q;
        let (rest, coefficients) = reject(&t[i], &below[i + 1..]);
        let norm = libm::sqrt(dot(&rest, &rest));
        // NaN fails too: a row that is not finite is no basis vector.
        let independent = norm > 1e-12 * libm::sqrt(dot(&t[i], &t[i]));
        if !independent {
            return None;
        }
        a[i][i] = norm;
        for (k, c) in coefficients.iter().take(2 - i).enumerate() {
            a[i][i + 1 + k] = *c;
        }
        q[i] = rest.map(|x| x / norm);
    }
    Some((a, q))
}

/// The truth `accel` and `gyro` (I+Σ) (body axes) in the rig-free fits'
/// frame; `None` when `accel` is singular.
pub fn in_accel_frame(accel: &Mat3, gyro: &Mat3) -> Option<InAccelFrame> {
    let (a, q) = rq(accel)?;
    let q_t = core::array::from_fn(|i| core::array::from_fn(|j| q[j][i]));
    Some(InAccelFrame {
        accel: a,
        gyro: matrix::mul(gyro, &q_t),
        rotation: q,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= tol))
    }

    /// A consumer accelerometer's (I+Σ): percent scale errors, milliradian
    /// misalignments in every off-diagonal place.
    const T_A: Mat3 = [
        [1.005, 0.004, -0.003],
        [-0.002, 0.997, 0.006],
        [0.005, -0.004, 1.002],
    ];

    #[test]
    fn rq_gives_an_upper_triangular_factor_and_a_rotation() {
        let (a, q) = rq(&T_A).unwrap();
        assert!(a[1][0] == 0.0 && a[2][0] == 0.0 && a[2][1] == 0.0, "{a:?}");
        assert!((0..3).all(|i| a[i][i] > 0.0));
        // A·Q = T to rounding (1e-15 relative, entries ≈ 1).
        assert!(close(&matrix::mul(&a, &q), &T_A, 1e-14));
        let qqt = matrix::mul(
            &q,
            &core::array::from_fn(|i| core::array::from_fn(|j| q[j][i])),
        );
        assert!(close(
            &qqt,
            &[[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            1e-14
        ));
        assert!((matrix::determinant(&q) - 1.0).abs() < 1e-14);
        // An upper triangular T is its own A (Q = I).
        let (a2, q2) = rq(&a).unwrap();
        assert!(
            close(&a2, &a, 1e-15) && close(&q2, &[[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]], 1e-15)
        );
    }

    #[test]
    fn a_gyro_in_the_accelerometers_frame_measures_the_same_rates() {
        let t_g = [
            [0.993, 0.004, 0.002],
            [-0.003, 1.004, -0.005],
            [0.001, 0.006, 0.995],
        ];
        let f = in_accel_frame(&T_A, &t_g).unwrap();
        // A body rate ω is ω_c = Q·ω in the corrected axes; both forms
        // give the same measurement: G·ω_c = T_g·ω.
        let w = [0.3, -1.2, 0.7];
        let via_frame = matrix::mul_vec(&f.gyro, &matrix::mul_vec(&f.rotation, &w));
        let direct = matrix::mul_vec(&t_g, &w);
        assert!((0..3).all(|k| (via_frame[k] - direct[k]).abs() < 1e-14));
        // The off-diagonal terms move by the accelerometer's misalignment
        // (milliradians): the reason for the conversion.
        assert!((f.gyro[0][2] - t_g[0][2]).abs() > 1e-3, "{:?}", f.gyro);
        assert!(in_accel_frame(&[[1., 0., 0.], [2., 0., 0.], [0., 0., 1.]], &t_g).is_none());
    }
}
