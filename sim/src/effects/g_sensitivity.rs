//! Gyro g-sensitivity: a rate error proportional to the specific force,
//! ω_err = G·f with G in (rad/s)/(m/s²) (IEEE Std 952 §3, "acceleration
//! sensitive drift"; data sheets quote (°/s)/g or (°/h)/g).

/// The rate error G·f for the specific force `f`.
pub fn rate_error(g: &[[f64; 3]; 3], f: &[f64; 3]) -> [f64; 3] {
    [
        g[0][0] * f[0] + g[0][1] * f[1] + g[0][2] * f[2],
        g[1][0] * f[0] + g[1][1] * f[1] + g[1][2] * f[2],
        g[2][0] * f[0] + g[2][1] * f[1] + g[2][2] * f[2],
    ]
}
