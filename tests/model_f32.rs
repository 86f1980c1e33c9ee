//! The f32 hot path against the f64 reference, on random valid calibrations
//! and raw inputs across the full i16 range.
//!
//! Error bound (derivation). Let u = 2⁻²⁴ (f32 unit roundoff) and S_i =
//! Σ_j |K_ij|·|x_j| + |k_i| with the exact f64 K, k. The kernel computes
//! ((k̃ + K̃0·x0) + K̃1·x1) + K̃2·x2 with K̃ = fl32(K) = K(1+α), |α| ≤ u, and
//! x exact (an i16 is exact in f32). K̃0·x0 passes through one
//! multiplication and three additions (4 roundings), k̃ through 3 additions,
//! K̃1·x1 through 3 roundings and K̃2·x2 through 2, so (Higham, Accuracy and Stability of Numerical Algorithms,
//! §3.1, lemma 3.1) the result is Σ t_j(1+θ_j) with |θ_j| ≤ γ4 = 4u/(1−4u).
//! With the coefficient rounding: |ŷ − y| ≤ ((1+u)(1+γ4) − 1)·S_i
//! = (γ4 + u + u·γ4)·S_i ≤ 5.0000004·u·S_i. The f64 reference (Gaussian
//! elimination, κ₁ ≤ 21 for valid matrices) is itself within ≈ κ·10·2⁻⁵³
//! ≈ 3e−14 of exact relative to S_i, i.e. 5e−7·u·S_i; C = 5.00001 covers both.
//!
//! With a g-sensitivity the gyro's row adds the accelerometer's three
//! products after its own, ((õ + K̃0·g0 + K̃1·g1 + K̃2·g2) + C̃0·a0 + C̃1·a1) +
//! C̃2·a2 left to right (src/model/g_sensitivity.rs), õ = fl32(k_g + c):
//! K̃0·g0 passes through 7 roundings, so the same argument with γ7 gives
//! (γ7 + u + u·γ7)·S_i ≤ 8.0000008·u·S_i, S_i now summing the accelerometer
//! terms |C_ij|·|a_j| too and |k_g + c| for the offset; C_G = 8.00001.

mod model_support;

use model_support::*;
use triad::model::{Corrector, Triad};

const U: f64 = 1.0 / (1u64 << 24) as f64;
/// The constant of the bound derived in the module doc.
const C: f64 = 5.00001;
/// The constant for the gyro's row with a g-sensitivity (module doc).
const C_G: f64 = 8.00001;

/// The bound's constant and S_i = Σ_j |K_ij|·|x_j| + |k_i| (for the gyro
/// with G: + Σ_j |C_ij|·|a_j|, and |k_i + c_i| for the offset), `a` the raw
/// accelerometer input.
fn magnitude(c: &Corrector, triad: Triad, x: [f64; 3], a: [f64; 3]) -> (f64, [f64; 3]) {
    let f = c.folded(triad);
    let products = |k: &[[f64; 3]; 3], x: [f64; 3], i: usize| {
        (0..3).map(|j| k[i][j].abs() * x[j].abs()).sum::<f64>()
    };
    match (triad, c.folded_g_sensitivity()) {
        (Triad::Gyro, Some(g)) => (
            C_G,
            [0, 1, 2].map(|i| {
                products(&f.k, x, i) + products(&g.k, a, i) + (f.offset[i] + g.offset[i]).abs()
            }),
        ),
        _ => (
            C,
            [0, 1, 2].map(|i| products(&f.k, x, i) + f.offset[i].abs()),
        ),
    }
}

#[test]
fn f32_path_is_within_the_derived_bound_of_the_f64_reference() {
    let mut rng = rng(0xF32);
    let mut worst_ratio: f64 = 0.0;
    let mut checked = 0usize;
    for _ in 0..400 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        let orientation = random_orientation(&mut rng);
        let c =
            Corrector::new(&cal, &scale, orientation).expect("generated calibrations are valid");
        for _ in 0..250 {
            let raw = random_raw(&mut rng);
            let fast = c.correct(&raw);
            let exact = c.reference(&raw);
            assert_eq!(fast.clip, exact.clip);
            for (triad, got, want, x) in [
                (Triad::Accel, fast.accel, exact.accel, raw.accel),
                (Triad::Gyro, fast.gyro, exact.gyro, raw.gyro),
            ] {
                let (constant, s) =
                    magnitude(&c, triad, x.map(f64::from), raw.accel.map(f64::from));
                for i in 0..3 {
                    let err = (f64::from(got[i]) - want[i]).abs();
                    let bound = constant * U * s[i];
                    assert!(
                        err <= bound,
                        "{triad:?}[{i}] err {err:e} > bound {bound:e}, cal {cal:?}, raw {raw:?}"
                    );
                    worst_ratio = worst_ratio.max(err / bound);
                    checked += 1;
                }
            }
            // Temperature: fl(fl(raw·ts) + 25) with ts = fl32(1/132.48): three roundings
            // of terms ≤ 247 + 25 < 300 °C, plus the final one of |T|: ≤ 4u·(|T| + 300).
            let t_err = (f64::from(fast.temperature) - exact.temperature).abs();
            assert!(
                t_err <= 4.0 * U * (exact.temperature.abs() + 300.0),
                "temperature err {t_err:e}"
            );
        }
    }
    println!("f32 vs f64: {checked} outputs, worst error = {worst_ratio:.3} of the bound");
    // The bound is not vacuous: random inputs reach a sizeable part of it.
    assert!(worst_ratio > 0.05, "bound far from attained: {worst_ratio}");
}

#[test]
fn si_kernel_matches_the_si_reference_within_the_same_bound() {
    let mut rng = rng(0x51);
    for _ in 0..200 {
        let scale = widest_scale();
        let cal = random_calibration(&mut rng, &scale);
        let c = Corrector::new_si(
            &cal,
            scale.accel.full_scale,
            scale.gyro.full_scale,
            random_orientation(&mut rng),
        )
        .unwrap();
        for _ in 0..100 {
            let a = random_raw(&mut rng)
                .accel
                .map(|v| (f64::from(v) * scale.accel.si_per_lsb) as f32);
            let g = random_raw(&mut rng)
                .gyro
                .map(|v| (f64::from(v) * scale.gyro.si_per_lsb) as f32);
            let fast = c.correct_si(a, g, 21.5);
            let exact = c.reference_si(a.map(f64::from), g.map(f64::from), 21.5);
            assert_eq!(fast.temperature, 21.5);
            assert_eq!(exact.temperature, 21.5);
            for (triad, got, want, x) in [
                (Triad::Accel, fast.accel, exact.accel, a),
                (Triad::Gyro, fast.gyro, exact.gyro, g),
            ] {
                let (constant, s) = magnitude(&c, triad, x.map(f64::from), a.map(f64::from));
                for i in 0..3 {
                    let err = (f64::from(got[i]) - want[i]).abs();
                    assert!(err <= constant * U * s[i], "{triad:?}[{i}] err {err:e}");
                }
            }
        }
    }
}

#[test]
fn identity_calibration_only_applies_the_sensitivity() {
    let scale = widest_scale();
    let c = Corrector::new(
        &triad::model::Calibration::identity(7),
        &scale,
        Default::default(),
    )
    .unwrap();
    assert_eq!(c.calibration_id(), 7);
    let raw = triad::sensor::RawSample {
        accel: [1000, -2000, 16384],
        gyro: [1, -1, 0],
        temperature: 0,
    };
    let s = c.correct(&raw);
    let sa = scale.accel.si_per_lsb as f32;
    // K = s·I, k = 0: one rounding of s and one product per axis, plus exact zeros.
    assert_eq!(s.accel, [1000.0 * sa, -2000.0 * sa, 16384.0 * sa]);
    assert_eq!(s.temperature, 25.0);
    assert_eq!(s.clip, Default::default());
}

#[test]
fn correction_inverts_the_measurement_model() {
    // Forward: raw = ((I+Σ)·m + b)/s for a chosen m, then correct must return m.
    let scale = widest_scale();
    let mut rng = rng(3);
    let cal = random_calibration(&mut rng, &scale);
    let m = [1.5, -9.80665, 3.25];
    let a = cal.accel.scale_misalignment;
    let measured: Vec<f64> = (0..3)
        .map(|i| (0..3).map(|j| a[i][j] * m[j]).sum::<f64>() + cal.accel.bias[i])
        .collect();
    // The f64 reference on the exact SI measurement (no raw quantisation).
    let si = Corrector::new_si(
        &cal,
        scale.accel.full_scale,
        scale.gyro.full_scale,
        Default::default(),
    )
    .unwrap();
    let back = si.reference_si([measured[0], measured[1], measured[2]], [0.0; 3], 0.0);
    // |m| ≤ 10 and κ ≤ 21: forward and back in f64 is good to ~1e−13.
    for (got, want) in back.accel.iter().zip(m) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn correction_removes_the_g_sensitivity_of_the_true_specific_force() {
    // Forward: m̂_g = (I+Σ_g)·ω + b_g + G·f with f the true specific force;
    // the correction (f64 reference and f32 path, in a rotated mounting)
    // must return R·ω whatever f is, and G must matter.
    let scale = widest_scale();
    let mut rng = rng(0x65);
    let mut cal = random_calibration(&mut rng, &scale);
    let limit = triad::model::validate::MAX_G_SENSITIVITY;
    cal.g_sensitivity = Some([
        [limit, -0.5 * limit, 0.2 * limit],
        [0.3 * limit, -limit, 0.0],
        [0.0, 0.7 * limit, limit],
    ]);
    let orientation = triad::model::Orientation::from_name("ROTATION_ROLL_90_YAW_90").unwrap();
    let si = Corrector::new_si(
        &cal,
        scale.accel.full_scale,
        scale.gyro.full_scale,
        orientation,
    )
    .unwrap();
    let without = Corrector::new_si(
        &triad::model::Calibration {
            g_sensitivity: None,
            ..cal
        },
        scale.accel.full_scale,
        scale.gyro.full_scale,
        orientation,
    )
    .unwrap();
    let forward = |m: &[[f64; 3]; 3], b: &[f64; 3], x: [f64; 3]| {
        [0, 1, 2].map(|i| (0..3).map(|j| m[i][j] * x[j]).sum::<f64>() + b[i])
    };
    let omega = [0.3, -1.2, 0.05];
    for f in [
        [0.0, 0.0, 9.80665],
        [-9.80665, 0.0, 0.0],
        [3.0, -40.0, 25.0],
    ] {
        let accel = forward(&cal.accel.scale_misalignment, &cal.accel.bias, f);
        let g = cal.g_sensitivity.unwrap();
        let gf = forward(&g, &[0.0; 3], f);
        let gyro = forward(&cal.gyro.scale_misalignment, &cal.gyro.bias, omega);
        let gyro = [0, 1, 2].map(|i| gyro[i] + gf[i]);
        let want = orientation.rotate(omega);
        let exact = si.reference_si(accel, gyro, 0.0);
        let fast = si.correct_si(accel.map(|x| x as f32), gyro.map(|x| x as f32), 0.0);
        let ignored = without.reference_si(accel, gyro, 0.0);
        for i in 0..3 {
            assert!(
                (exact.gyro[i] - want[i]).abs() < 1e-12,
                "{f:?}: {:?} vs {want:?}",
                exact.gyro
            );
            // f32: a few u of |ω| + |G·f| + |b|.
            assert!(
                (f64::from(fast.gyro[i]) - want[i]).abs() < 1e-5,
                "{f:?}: {:?}",
                fast.gyro
            );
        }
        let missed = (0..3)
            .map(|i| (ignored.gyro[i] - want[i]).abs())
            .fold(0.0, f64::max);
        assert!(missed > 1e-3, "G·f = {gf:?} should matter: {missed}");
    }
}

/// `triad correct` sees the device's raw counts only as SI values x = fl32(s·raw)
/// and applies K/s; the device applies K to raw. Each is within 5u·S of the
/// exact result (bound above), and rounding x to f32 moves the exact result by
/// ≤ u·Σ|K_ij||raw_j| ≤ u·S, so the two f32 results differ by at most
/// (5 + 5 + 1)·u·S (+ O(u²), covered by 11.0001). This is the bound the
/// end-to-end comparison of firmware output and `triad correct` can rely on.
/// With a g-sensitivity the gyro's is (8 + 8 + 1)·u·S: both inputs are
/// rounded to f32, each by a relative u, so together by ≤ u·S.
#[test]
fn host_si_path_and_device_raw_path_agree_within_11u() {
    let mut rng = rng(0xE2E);
    let mut worst_ratio: f64 = 0.0;
    for _ in 0..200 {
        let scale = random_scale(&mut rng);
        let cal = random_calibration(&mut rng, &scale);
        let orientation = random_orientation(&mut rng);
        let device = Corrector::new(&cal, &scale, orientation).unwrap();
        let host = Corrector::new_si(
            &cal,
            scale.accel.full_scale,
            scale.gyro.full_scale,
            orientation,
        )
        .unwrap();
        for _ in 0..200 {
            let raw = random_raw(&mut rng);
            let si = |v: [i32; 3], s: f64| v.map(|x| (f64::from(x) * s) as f32);
            let d = device.correct(&raw);
            let h = host.correct_si(
                si(raw.accel, scale.accel.si_per_lsb),
                si(raw.gyro, scale.gyro.si_per_lsb),
                0.0,
            );
            for (triad, a, b, x) in [
                (Triad::Accel, d.accel, h.accel, raw.accel),
                (Triad::Gyro, d.gyro, h.gyro, raw.gyro),
            ] {
                let (constant, s) =
                    magnitude(&device, triad, x.map(f64::from), raw.accel.map(f64::from));
                let limit = 2.0 * constant + 1.0001;
                for i in 0..3 {
                    let diff = (f64::from(a[i]) - f64::from(b[i])).abs();
                    assert!(diff <= limit * U * s[i], "{triad:?}[{i}]: {diff:e}");
                    worst_ratio = worst_ratio.max(diff / (limit * U * s[i]));
                }
            }
        }
    }
    println!(
        "device vs host f32: worst difference = {worst_ratio:.3} of the 11u·S (17u·S with G) bound"
    );
}
