//! Unit quaternions for attitude integration, f64, `[w, x, y, z]`.
//!
//! A quaternion q maps body coordinates to reference coordinates,
//! v_ref = q·v_body·q*, and evolves with the body rate ω (body axes) as
//! q̇ = ½·q ⊗ (0, ω).

/// `[w, x, y, z]`.
pub type Quat = [f64; 4];

/// The identity rotation.
pub const IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// The Hamilton product a ⊗ b.
pub fn mul(a: &Quat, b: &Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// exp of the rotation vector φ (rad): a turn of |φ| about φ/|φ|.
pub fn from_rotation_vector(phi: &[f64; 3]) -> Quat {
    let angle = libm::sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    if angle == 0.0 {
        return IDENTITY;
    }
    let s = libm::sin(angle / 2.0) / angle;
    [libm::cos(angle / 2.0), phi[0] * s, phi[1] * s, phi[2] * s]
}

/// The rotation vector of q (axis times angle, angle in 0..π).
pub fn to_rotation_vector(q: &Quat) -> [f64; 3] {
    // q and −q are the same rotation: take w ≥ 0 for the short way round.
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let v = [sign * q[1], sign * q[2], sign * q[3]];
    let s = libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if s == 0.0 {
        return [0.0; 3];
    }
    let angle = 2.0 * libm::atan2(s, sign * q[0]);
    v.map(|x| x * angle / s)
}

/// q·v·q*: body coordinates `v` in the reference frame.
pub fn rotate(q: &Quat, v: &[f64; 3]) -> [f64; 3] {
    let p = mul(&mul(q, &[0.0, v[0], v[1], v[2]]), &conjugate(q));
    [p[1], p[2], p[3]]
}

/// q*·v·q: reference coordinates `v` in the body frame.
pub fn rotate_inverse(q: &Quat, v: &[f64; 3]) -> [f64; 3] {
    rotate(&conjugate(q), v)
}

/// The rotation matrix R of q: R·v = q·v·q* (body to reference).
pub fn to_matrix(q: &Quat) -> [[f64; 3]; 3] {
    triad_sim::motion::rotation::from_quaternion(q)
}

/// q*.
pub fn conjugate(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// q / |q|.
pub fn normalised(q: &Quat) -> Quat {
    let n = libm::sqrt(q.iter().map(|x| x * x).sum::<f64>());
    q.map(|x| x / n)
}

/// ½·q ⊗ (0, ω).
fn derivative(q: &Quat, w: &[f64; 3]) -> Quat {
    mul(q, &[0.0, w[0], w[1], w[2]]).map(|x| 0.5 * x)
}

fn plus(q: &Quat, k: &Quat, h: f64) -> Quat {
    [0, 1, 2, 3].map(|i| q[i] + h * k[i])
}

/// One classical Runge–Kutta step of q̇ = ½·q ⊗ (0, ω) over `dt` seconds,
/// the rate going from `w0` to `w1` linearly (two consecutive samples; the
/// midpoint rate is their mean), normalised after the step.
pub fn rk4_step(q: &Quat, w0: &[f64; 3], w1: &[f64; 3], dt: f64) -> Quat {
    let wm = [0, 1, 2].map(|i| 0.5 * (w0[i] + w1[i]));
    let k1 = derivative(q, w0);
    let k2 = derivative(&plus(q, &k1, dt / 2.0), &wm);
    let k3 = derivative(&plus(q, &k2, dt / 2.0), &wm);
    let k4 = derivative(&plus(q, &k3, dt), w1);
    let step = [0, 1, 2, 3].map(|i| q[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    normalised(&step)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn a_quarter_turn_about_z_takes_x_to_y() {
        let q = from_rotation_vector(&[0.0, 0.0, core::f64::consts::FRAC_PI_2]);
        assert!(close(
            &rotate(&q, &[1.0, 0.0, 0.0]),
            &[0.0, 1.0, 0.0],
            1e-15
        ));
        assert!(close(
            &rotate_inverse(&q, &[0.0, 1.0, 0.0]),
            &[1.0, 0.0, 0.0],
            1e-15
        ));
        let phi = to_rotation_vector(&q);
        assert!(close(
            &phi,
            &[0.0, 0.0, core::f64::consts::FRAC_PI_2],
            1e-15
        ));
        assert!(close(&to_rotation_vector(&q.map(|x| -x)), &phi, 1e-15));
        assert_eq!(to_rotation_vector(&IDENTITY), [0.0; 3]);
    }

    #[test]
    fn the_matrix_rotates_as_the_quaternion_does() {
        let q = normalised(&[0.3, -0.5, 0.7, 0.2]);
        let v = [0.4, -1.1, 2.3];
        let r = to_matrix(&q);
        let by_matrix = [0, 1, 2].map(|i| (0..3).map(|j| r[i][j] * v[j]).sum::<f64>());
        assert!(close(&by_matrix, &rotate(&q, &v), 1e-15), "{by_matrix:?}");
    }

    #[test]
    fn rk4_at_a_constant_rate_is_the_exact_turn() {
        let w = [0.3, -1.2, 0.7];
        let mut q = IDENTITY;
        for _ in 0..100 {
            q = rk4_step(&q, &w, &w, 0.01);
        }
        let exact = from_rotation_vector(&w);
        assert!(close(&q, &exact, 1e-10), "{q:?} vs {exact:?}");
    }
}
