//! The few rotation-matrix operations the motion models need (3×3, f64).
//! R maps body coordinates to the local-level frame (x east, y north, z up).

pub use triad::model::matrix::{mul, mul_transpose_vec, mul_vec, transpose_mul, Mat3, IDENTITY};

/// The rotation matrix of the unit quaternion `[w, x, y, z]`: R·v = q·v·q*
/// (body to reference). `q` is used as given: normalise it first.
pub fn from_quaternion(q: &[f64; 4]) -> Mat3 {
    let [w, x, y, z] = *q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Rotation about the frame's z axis by `angle` (radians).
pub fn rot_z(angle: f64) -> Mat3 {
    let (s, c) = (libm::sin(angle), libm::cos(angle));
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// Body-to-level rotation from z-y-x Euler angles: R = Rz(yaw)·Ry(pitch)·Rx(roll).
pub fn from_euler(roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    let (sr, cr) = (libm::sin(roll), libm::cos(roll));
    let (sp, cp) = (libm::sin(pitch), libm::cos(pitch));
    let (sy, cy) = (libm::sin(yaw), libm::cos(yaw));
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Rotation by `angle` about the unit `axis` (Rodrigues' formula).
pub fn exp(axis: &[f64; 3], angle: f64) -> Mat3 {
    let (s, c) = (libm::sin(angle), libm::cos(angle));
    let v = 1.0 - c;
    let [x, y, z] = *axis;
    [
        [c + v * x * x, v * x * y - s * z, v * x * z + s * y],
        [v * y * x + s * z, c + v * y * y, v * y * z - s * x],
        [v * z * x - s * y, v * z * y + s * x, c + v * z * z],
    ]
}

/// The axis and angle (0..=π) of a rotation matrix (the inverse of [`exp`]).
/// The angle-π case takes the axis from the symmetric part.
pub fn log(m: &Mat3) -> ([f64; 3], f64) {
    let cos_angle = ((m[0][0] + m[1][1] + m[2][2] - 1.0) * 0.5).clamp(-1.0, 1.0);
    let angle = libm::acos(cos_angle);
    if angle < 1e-12 {
        return ([0.0, 0.0, 1.0], 0.0);
    }
    let s = libm::sin(angle);
    if s > 1e-6 {
        let k = [
            (m[2][1] - m[1][2]) / (2.0 * s),
            (m[0][2] - m[2][0]) / (2.0 * s),
            (m[1][0] - m[0][1]) / (2.0 * s),
        ];
        return (normalise(k), angle);
    }
    // Angle ≈ π: M = 2kkᵀ − I. Use the largest diagonal term for accuracy.
    let mut j = 0;
    for i in 1..3 {
        if m[i][i] > m[j][j] {
            j = i;
        }
    }
    let kj = libm::sqrt(((m[j][j] + 1.0) * 0.5).max(0.0));
    let mut k = [0.0; 3];
    for (i, ki) in k.iter_mut().enumerate() {
        *ki = if i == j {
            kj
        } else {
            (m[j][i] + m[i][j]) / (4.0 * kj)
        };
    }
    (normalise(k), angle)
}

/// v/|v| (v unchanged if zero).
pub fn normalise(v: [f64; 3]) -> [f64; 3] {
    let n = libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        v
    }
}
