//! The core math of `triad_lab::calib_fit`: QR least squares on systems with
//! known solutions, Levenberg–Marquardt on exact synthetic data, the gyro
//! linear fit, static-segment detection, and each refusal.
#![allow(clippy::needless_range_loop)] // index form reads as the matrix formulas

use triad::model::matrix;
use triad_lab::calib_fit::fits::accel_cube::AccelCubeError;
use triad_lab::calib_fit::fits::accel_fit::{
    AccelFitError, NotNearGravity, MIN_ACCEL_ORIENTATIONS,
};
use triad_lab::calib_fit::fits::gyro_fit::GyroFitError;
use triad_lab::calib_fit::fits::gyro_fit::{self, RateSegment};
use triad_lab::calib_fit::fits::{accel_cube, accel_fit};
use triad_lab::calib_fit::numerics::qr::{GivensLs, LsError};
use triad_lab::calib_fit::numerics::small3::{cholesky_upper, gram, symmetric_eigenvalues};
use triad_lab::calib_fit::numerics::NumericsError;
use triad_lab::calib_fit::static_segments::{DetectError, Detector, Segment};

const G: f64 = 9.80665;

/// A deterministic pseudo-random sequence in [−1, 1) (xorshift64*).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        x as f64 / (1u64 << 52) as f64 - 1.0
    }
}

#[test]
fn qr_solves_a_consistent_overdetermined_system_to_rounding() {
    // A·x = y exactly for x = [1.5, −2, 0.25, 3]; 10 rows of O(1) entries:
    // the solution is exact up to a few ulps times κ (κ < 100 here).
    let x_true = [1.5, -2.0, 0.25, 3.0];
    let mut ls = GivensLs::<4>::new();
    let mut rng = Rng(7);
    for _ in 0..10 {
        let a = [rng.next(), rng.next(), rng.next(), 1.0];
        let y: f64 = a.iter().zip(x_true).map(|(a, x)| a * x).sum();
        ls.add_row(a, y);
    }
    let x = ls.solve().unwrap();
    for (xi, ti) in x.iter().zip(x_true) {
        assert!((xi - ti).abs() < 1e-13, "{x:?}");
    }
    assert!(ls.residual_sum_of_squares() < 1e-26);
    assert!(ls.scaled_condition() < 100.0);
}

#[test]
fn qr_gives_the_textbook_straight_line_fit_and_its_covariance() {
    // y = a + b·x at x = 0..4, y = [1, 3, 2, 5, 4]: the normal equations
    // give b = Sxy/Sxx = 8/10 = 0.8, a = ȳ − b·x̄ = 3 − 1.6 = 1.4; RSS =
    // Syy − b·Sxy = 10 − 6.4 = 3.6; (AᵀA)⁻¹ = [[Σx², −Σx], [−Σx, n]]/(n·Sxx)
    // = [[30, −10], [−10, 5]]/50. Exact in binary to ~1e-15.
    let mut ls = GivensLs::<2>::new();
    for (x, y) in [(0.0, 1.0), (1.0, 3.0), (2.0, 2.0), (3.0, 5.0), (4.0, 4.0)] {
        ls.add_row([1.0, x], y);
    }
    let [a, b] = ls.solve().unwrap();
    assert!(
        (a - 1.4).abs() < 1e-14 && (b - 0.8).abs() < 1e-14,
        "{a} {b}"
    );
    assert!((ls.residual_sum_of_squares() - 3.6).abs() < 1e-13);
    let c = ls.inverse_normal_matrix().unwrap();
    let want = [[0.6, -0.2], [-0.2, 0.1]];
    for i in 0..2 {
        for j in 0..2 {
            assert!((c[i][j] - want[i][j]).abs() < 1e-14, "{c:?}");
        }
    }
}

#[test]
fn qr_reports_rank_deficiency_and_too_few_rows() {
    let mut ls = GivensLs::<3>::new();
    for x in [1.0, 2.0, 3.0, 4.0] {
        // Column 2 = 2 × column 1: the third unknown is not determined.
        ls.add_row([1.0, x, 2.0 * x], x);
    }
    assert_eq!(ls.solve(), Err(LsError::RankDeficient { unknown: 2 }));
    assert!(ls.scaled_condition().is_infinite());
    let mut few = GivensLs::<3>::new();
    few.add_row([1.0, 0.0, 0.0], 1.0);
    assert_eq!(
        few.solve(),
        Err(LsError::TooFewRows {
            rows: 1,
            unknowns: 3
        })
    );
}

#[test]
fn small3_cholesky_and_eigenvalues_match_known_values() {
    let u = [[2.0, 0.5, -0.25], [0.0, 1.5, 0.125], [0.0, 0.0, 0.75]];
    let w = gram(&u);
    let back = cholesky_upper(&w).unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((back[i][j] - u[i][j]).abs() < 1e-15, "{back:?}");
        }
    }
    assert!(cholesky_upper(&[[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).is_none());
    // [[2,1,0],[1,2,0],[0,0,5]]: eigenvalues 1, 3, 5.
    let e = symmetric_eigenvalues(&[[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]);
    for (got, want) in e.iter().zip([1.0, 3.0, 5.0]) {
        assert!((got - want).abs() < 1e-14, "{e:?}");
    }
}

/// A plausible MEMS (I+Σ) (scale ≤ 0.5 %, misalignment ≤ 3 mrad) and bias.
const M_TRUE: [[f64; 3]; 3] = [
    [1.005, 0.002, -0.001],
    [0.001, 0.997, 0.003],
    [-0.002, 0.001, 1.002],
];
const B_TRUE: [f64; 3] = [0.196, -0.147, 0.294];

/// The truth in the fit's convention: T = upper Cholesky factor of
/// M⁻ᵀM⁻¹ (the rotation-invariant part), (I+Σ) = T⁻¹.
fn truth_t() -> [[f64; 3]; 3] {
    cholesky_upper(&gram(&matrix::inverse(&M_TRUE).unwrap())).unwrap()
}

/// n directions spread over the sphere (a Fibonacci lattice).
fn directions(n: usize) -> Vec<[f64; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            [r * a.cos(), r * a.sin(), z]
        })
        .collect()
}

fn measure(f: &[f64; 3]) -> [f64; 3] {
    let m = matrix::mul_vec(&M_TRUE, f);
    [m[0] + B_TRUE[0], m[1] + B_TRUE[1], m[2] + B_TRUE[2]]
}

#[test]
fn accel_fit_recovers_exact_synthetic_parameters_to_1e9() {
    // Noiseless means: the minimum is at the truth with zero residual, and
    // LM converges quadratically there; only rounding remains (κ ≈ 10 times
    // ε·|f̂|/g ≈ 1e-15), so 1e-9 has a wide margin and still catches any
    // modelling error (a wrong convention or Jacobian moves T by ≳ 1e-4).
    let means: Vec<[f64; 3]> = directions(30)
        .iter()
        .map(|u| measure(&[G * u[0], G * u[1], G * u[2]]))
        .collect();
    let fit = accel_fit::fit(&means, G).unwrap();
    let t = truth_t();
    for (k, &(i, j)) in accel_fit::T_ENTRIES.iter().enumerate() {
        assert!(
            (fit.params[k] - t[i][j]).abs() < 1e-9,
            "T[{i}][{j}] {} vs {}",
            fit.params[k],
            t[i][j]
        );
    }
    for k in 0..3 {
        assert!((fit.bias[k] - B_TRUE[k]).abs() < 1e-9, "b {:?}", fit.bias);
    }
    let m = matrix::inverse(&t).unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((fit.scale_misalignment[i][j] - m[i][j]).abs() < 1e-9);
        }
    }
    assert!(fit.residual_max < 1e-9, "{}", fit.residual_max);
    assert_eq!(fit.orientations, 30);
    assert!(fit.condition < 100.0, "{}", fit.condition);
}

#[test]
fn accel_fit_starts_from_a_far_initial_state_without_help() {
    // A large error (10 % scale, 0.05 misalignment, 1 m/s² bias): the
    // algebraic start is exact for noiseless data, so LM only polishes.
    let m_big = [[1.1, 0.05, -0.03], [0.0, 0.92, 0.04], [0.0, 0.0, 1.07]];
    let b_big = [1.0, -0.8, 0.6];
    let means: Vec<[f64; 3]> = directions(12)
        .iter()
        .map(|u| {
            let m = matrix::mul_vec(&m_big, &[G * u[0], G * u[1], G * u[2]]);
            [m[0] + b_big[0], m[1] + b_big[1], m[2] + b_big[2]]
        })
        .collect();
    let fit = accel_fit::fit(&means, G).unwrap();
    for i in 0..3 {
        assert!((fit.bias[i] - b_big[i]).abs() < 1e-9);
        for j in 0..3 {
            // m_big is upper triangular: it is its own convention form.
            assert!((fit.scale_misalignment[i][j] - m_big[i][j]).abs() < 1e-9);
        }
    }
}

#[test]
fn accel_fit_refuses_six_cube_faces_with_the_count() {
    // ±x, ±y, ±z four times over (a 24-position tumble): 6 directions.
    let mut means = Vec::new();
    for _ in 0..4 {
        for (k, s) in [
            (2, 1.0),
            (2, -1.0),
            (0, 1.0),
            (0, -1.0),
            (1, 1.0),
            (1, -1.0),
        ] {
            let mut f = [0.0; 3];
            f[k] = s * G;
            means.push(measure(&f));
        }
    }
    assert_eq!(
        accel_fit::fit(&means, G),
        Err(AccelFitError::TooFewOrientations {
            segments: 24,
            found: 6,
            needed: MIN_ACCEL_ORIENTATIONS
        })
    );
}

#[test]
fn accel_fit_refuses_orientations_in_one_plane() {
    // Twelve orientations turning about x: gravity stays in the y–z plane.
    let means: Vec<[f64; 3]> = (0..12)
        .map(|i| {
            let a = i as f64 * std::f64::consts::PI / 6.0;
            measure(&[0.0, G * a.cos(), G * a.sin()])
        })
        .collect();
    match accel_fit::fit(&means, G) {
        Err(AccelFitError::OrientationsInOnePlane {
            orientations,
            out_of_plane_rms,
            ..
        }) => {
            assert_eq!(orientations, 12);
            // The measured directions leave the plane only through Σ (≤ 3 mrad).
            assert!(out_of_plane_rms < 0.01, "{out_of_plane_rms}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn accel_fit_refuses_bad_gravity_and_non_finite_means() {
    let means = directions(12);
    assert_eq!(
        accel_fit::fit(&means, 0.0),
        Err(AccelFitError::InvalidGravity { value: 0.0 })
    );
    // Directions on the unit sphere are 1 m/s², as if the record were in g.
    match accel_fit::fit(&means, G) {
        Err(AccelFitError::NotNearGravity(NotNearGravity {
            segment: 0,
            magnitude,
            gravity,
        })) => assert!((magnitude - 1.0).abs() < 1e-12 && gravity == G),
        other => panic!("{other:?}"),
    }
    let mut bad: Vec<[f64; 3]> = means.iter().map(|u| u.map(|x| x * G)).collect();
    bad[3][1] = f64::NAN;
    assert!(matches!(
        accel_fit::fit(&bad, G),
        Err(AccelFitError::Numerics(NumericsError::NonFinite {
            segment: 3,
            ..
        }))
    ));
}

fn rate_segments(rates: &[[f64; 3]]) -> Vec<RateSegment> {
    rates
        .iter()
        .map(|w| {
            let m = matrix::mul_vec(&M_TRUE, w);
            RateSegment {
                true_rate: *w,
                measured: [m[0] + 0.01, m[1] - 0.005, m[2] + 0.002],
            }
        })
        .collect()
}

#[test]
fn gyro_fit_recovers_exact_synthetic_parameters() {
    // Linear LS on exact data: rounding only (κ ≈ 3, values ≤ 1.6 rad/s).
    let r = 30f64.to_radians();
    let rates = [
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
        [r, 0.0, 0.0],
        [-r, 0.0, 0.0],
        [0.0, r, 0.0],
        [0.0, -r, 0.0],
    ];
    let fit = gyro_fit::fit(&rate_segments(&rates)).unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((fit.scale_misalignment[i][j] - M_TRUE[i][j]).abs() < 1e-12);
        }
    }
    for (b, want) in fit.bias.iter().zip([0.01, -0.005, 0.002]) {
        assert!((b - want).abs() < 1e-12);
    }
    assert!(fit.residual_max < 1e-12);
}

#[test]
fn gyro_fit_refuses_rates_about_one_axis_in_one_plane_or_too_few() {
    let r = 0.5;
    let one_axis = [
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
        [0.0, 0.0, 2.0 * r],
        [0.0, 0.0, -2.0 * r],
    ];
    assert_eq!(
        gyro_fit::fit(&rate_segments(&one_axis)),
        Err(GyroFitError::RatesDegenerate { dimension: 1 })
    );
    let plane = [[0.0, 0.0, r], [0.0, 0.0, -r], [r, 0.0, 0.0], [-r, 0.0, 0.0]];
    assert_eq!(
        gyro_fit::fit(&rate_segments(&plane)),
        Err(GyroFitError::RatesDegenerate { dimension: 2 })
    );
    assert_eq!(
        gyro_fit::fit(&rate_segments(&plane[..3])),
        Err(GyroFitError::TooFewRates {
            found: 3,
            needed: 4
        })
    );
}

#[test]
fn static_segments_are_found_between_turns_and_trimmed() {
    // 100 Hz: 10 s at rest, a 4 s turn of gravity from z to x, 10 s at rest,
    // with ±0.007 m/s² uniform noise (σ ≈ 0.004). Blocks of 50 samples: the
    // first run covers blocks 0..20 (not trimmed at the record's start, one
    // block trimmed before the turn), the second starts one block after it.
    let mut rng = Rng(3);
    let mut samples = Vec::new();
    for k in 0..2400 {
        let t = k as f64 / 100.0;
        let a = ((t - 10.0) / 4.0).clamp(0.0, 1.0) * std::f64::consts::FRAC_PI_2;
        let f = [G * a.sin(), 0.0, G * a.cos()];
        samples.push(f.map(|x| x + 0.007 * rng.next()));
    }
    let detector = Detector {
        block: 50,
        min_blocks: 4,
    };
    let mut out = [Segment { start: 0, end: 0 }; 8];
    let n = detector.detect(&samples, &mut out).unwrap();
    assert_eq!(n, 2, "{:?}", &out[..n]);
    assert_eq!(out[0], Segment { start: 0, end: 950 });
    assert_eq!(
        out[1],
        Segment {
            start: 1450,
            end: 2400
        }
    );
    // A buffer too small is an error, not a truncation.
    let mut small = [Segment { start: 0, end: 0 }; 1];
    assert_eq!(
        detector.detect(&samples, &mut small),
        Err(DetectError::TooManySegments { capacity: 1 })
    );
}

#[test]
fn static_segments_split_at_an_orientation_change_between_two_blocks() {
    // Two orientations back to back with no turn, the change exactly on a
    // block boundary (sample 1000 = 20 blocks of 50): no block is noisy,
    // but the jump of the block mean splits the run; both blocks at the
    // split are static, so neither is trimmed.
    let mut rng = Rng(5);
    let samples: Vec<[f64; 3]> = (0..2000)
        .map(|k| {
            let f = if k < 1000 {
                [0.0, 0.0, G]
            } else {
                [G, 0.0, 0.0]
            };
            f.map(|x| x + 0.007 * rng.next())
        })
        .collect();
    let detector = Detector {
        block: 50,
        min_blocks: 4,
    };
    let mut out = [Segment { start: 0, end: 0 }; 4];
    let n = detector.detect(&samples, &mut out).unwrap();
    assert_eq!(
        &out[..n],
        &[
            Segment {
                start: 0,
                end: 1000
            },
            Segment {
                start: 1000,
                end: 2000
            }
        ]
    );
}

#[test]
fn accel_fit_refuses_directions_off_no_coordinate_plane_by_conditioning() {
    // The six faces and six 45° tilts about x and y only: no direction has
    // all of x, y and z, so the x–y coupling of T is not determined. The
    // count (12) and the plane test pass; the conditioning of JᵀJ refuses.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let dirs = [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, h, h],
        [0.0, -h, h],
        [0.0, h, -h],
        [0.0, -h, -h],
        [h, 0.0, h],
        [-h, 0.0, h],
    ];
    let means: Vec<[f64; 3]> = dirs.iter().map(|u| measure(&u.map(|x| G * x))).collect();
    match accel_fit::fit(&means, G) {
        Err(AccelFitError::Numerics(NumericsError::IllConditioned { condition, limit })) => {
            assert!(condition > limit, "{condition}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn accel_cube_fit_recovers_the_full_matrix_from_six_faces() {
    // Exact axis-aligned means: the linear fit returns the full (I+Σ) (no
    // rotation convention: the faces define the axes) to rounding.
    let mut means = Vec::new();
    for (k, s) in [
        (2, 1.0),
        (2, -1.0),
        (0, 1.0),
        (0, -1.0),
        (1, 1.0),
        (1, -1.0),
    ] {
        let mut f = [0.0; 3];
        f[k] = s * G;
        means.push(measure(&f));
    }
    let fit = accel_cube::fit(&means, G).unwrap();
    for i in 0..3 {
        assert!((fit.bias[i] - B_TRUE[i]).abs() < 1e-12);
        for j in 0..3 {
            assert!((fit.scale_misalignment[i][j] - M_TRUE[i][j]).abs() < 1e-12);
        }
    }
    // Four faces in one plane (±z, ±x) leave y undetermined.
    let plane = [means[0], means[1], means[2], means[3]];
    assert_eq!(
        accel_cube::fit(&plane, G),
        Err(AccelCubeError::TooFewFaces {
            found: 4,
            segments: 4
        })
    );
    // A position tilted 30° off every axis is not axis-aligned.
    let mut tilted = means.clone();
    let (s30, c30) = (0.5, 0.75f64.sqrt());
    tilted[2] = measure(&[G * c30, G * s30 * 0.5f64.sqrt(), G * s30 * 0.5f64.sqrt()]);
    match accel_cube::fit(&tilted, G) {
        Err(AccelCubeError::NotAxisAligned {
            segment: 2,
            angle_deg,
            ..
        }) => assert!((angle_deg - 30.0).abs() < 1.0, "{angle_deg}"),
        other => panic!("{other:?}"),
    }
}
