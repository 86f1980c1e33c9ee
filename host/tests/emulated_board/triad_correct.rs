//! `triad correct` on the raw samples a firmware read, in SI units as a
//! user's measured CSV holds them, against the values the firmware streamed.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use triad::sensor::{ImuScale, RawSample};

/// |Δ| allowed between the firmware (K = f32((I+Σ)⁻¹·s), input raw exact) and
/// `triad correct` (K' = f32((I+Σ)⁻¹), input f32(raw·s)) for output axis i.
///
/// Each path rounds: its coefficients (≤ 2⁻²⁴ relative each), the SI input in
/// `triad correct` (≤ 2⁻²⁴ relative), three products and three additions
/// (≤ 2⁻²⁴ relative of the running magnitude each). Summed over both paths
/// that is under 8·2⁻²⁴·(Σ_j |K_ij·m̂_j| + |k_i|) in SI units, where
/// `magnitude` bounds the bracket. A gyro row with a g-sensitivity adds the
/// accelerometer's three products and inputs (tests/model_f32.rs: 8u per
/// path and u for both inputs' rounding): 17·2⁻²⁴, with |C·a| in the
/// bracket (≤ 2e-4·Σ|a|, inside its `+ 1` for the accelerations here).
fn correct_bound(magnitude: f64, g_sensitivity: bool) -> f64 {
    let roundings = if g_sensitivity { 17.0 } else { 8.0 };
    roundings * f64::powi(2.0, -24) * magnitude
}

/// Runs `triad correct --calib CALIBRATION` on `raws` (read at `times_s`,
/// scaled by `scale`) and checks each row's six values against the
/// firmware's `streamed` (accel then gyro) within [`correct_bound`] plus
/// half of `quantum` (the accelerometer's and gyroscope's: the step the
/// firmware rounded its values to, 0 for f32 values); returns the worst |Δ|
/// as a fraction of its bound.
///
/// The bound's magnitude is 1.1·Σ_j |m̂_j| + 1, which holds for a calibration
/// whose (I+Σ)⁻¹ has absolute row sums below 1.1 and whose |(I+Σ)⁻¹·b| is
/// below 1 SI unit (the callers' calibrations: small corrections).
pub fn agrees_with_firmware(
    calibration: &Path,
    raws: &[RawSample],
    times_s: &[f64],
    scale: &ImuScale,
    streamed: &[[f32; 6]],
    quantum: [f64; 2],
) -> f64 {
    assert_eq!(
        raws.len(),
        streamed.len(),
        "one streamed sample per raw one"
    );
    let mut csv = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    let mut v_in = Vec::with_capacity(raws.len());
    for (raw, t) in raws.iter().zip(times_s) {
        let a = raw.accel.map(|x| f64::from(x) * scale.accel.si_per_lsb);
        let g = raw.gyro.map(|x| f64::from(x) * scale.gyro.si_per_lsb);
        v_in.push([a[0], a[1], a[2], g[0], g[1], g[2]]);
        let temp = scale.temperature_c(raw.temperature);
        csv.push_str(&format!(
            "{t},{:?},{:?},{:?},{:?},{:?},{:?},{temp:?}\n",
            a[0], a[1], a[2], g[0], g[1], g[2]
        ));
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_triad"))
        .args(["correct", "--calib"])
        .arg(calibration)
        .arg("-")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Written from a thread: `triad correct` streams its output, so writing
    // all input before reading would deadlock once both pipes are full.
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(csv.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut rows = text.lines();
    assert_eq!(rows.next(), Some("t,ax,ay,az,gx,gy,gz,temp"));
    let rows: Vec<&str> = rows.collect();
    assert_eq!(rows.len(), streamed.len(), "one row per sample");
    let g_sensitivity = triad_host::calib::file::load(calibration)
        .unwrap()
        .calibration
        .g_sensitivity
        .is_some();
    let mut worst = 0.0f64;
    for (n, (row, firmware)) in rows.iter().zip(streamed).enumerate() {
        let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        let input_sum = |x: &[f64]| 1.1 * x.iter().map(|v| v.abs()).sum::<f64>() + 1.0;
        let (accel_in, gyro_in) = (input_sum(&v_in[n][0..3]), input_sum(&v_in[n][3..6]));
        let magnitudes = [accel_in, accel_in, accel_in, gyro_in, gyro_in, gyro_in];
        for (axis, ((host, &fw), magnitude)) in
            v[1..7].iter().zip(firmware).zip(magnitudes).enumerate()
        {
            let fw = f64::from(fw);
            let bound =
                correct_bound(magnitude, g_sensitivity && axis >= 3) + 0.5 * quantum[axis / 3];
            let diff = (host - fw).abs();
            worst = worst.max(diff / bound);
            assert!(
                diff <= bound,
                "sample {n} axis {axis}: triad correct {host} vs firmware {fw}, |Δ| {diff:e} > {bound:e}"
            );
        }
    }
    worst
}
