//! `triad calib fit imu`: a unit turned by hand, no rig. The gyro's (I+Σ)
//! and b come back within their σ's of the truth, the file holds both
//! triads and their statistics, and degenerate records are refused with
//! what to do.

mod common;

use std::path::Path;

use common::{dir, hand_csv, hand_unit as unit, matrix, s, simulate_g_unit, text, triad};
use triad_lab::calib_fit::hand_record::{Axes, Script};

fn script(poses: usize, axes: Axes) -> Script {
    Script {
        rate_hz: 100.0,
        poses,
        static_s: 4.0,
        turn_s: 1.5,
        angle_deg: (60.0, 150.0),
        axes,
        drift: None,
    }
}

#[test]
fn a_hand_turned_unit_gives_its_gyro_within_its_sigmas() {
    let d = dir("imu");
    let input = hand_csv(&d, "hand", &script(16, Axes::Any), 11);
    let cal = d.join("cal.toml");
    let o = triad(&[
        "calib",
        "fit",
        "imu",
        "--positions",
        s(&input),
        "--out",
        s(&cal),
    ]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(report.contains("16 static poses"), "{report}");
    assert!(report.contains("15 moves"), "{report}");
    let file: toml::Table = std::fs::read_to_string(&cal).unwrap().parse().unwrap();
    let fit = file["fit"].as_table().unwrap();
    assert!(
        fit.contains_key("accel") && fit.contains_key("gyro"),
        "{fit:?}"
    );
    let dof = fit["gyro"]["degrees_of_freedom"].as_integer().unwrap();
    assert!(dof > 0);
    let m = matrix(&file, "gyro", "scale_misalignment");
    let sigma = matrix(fit, "gyro", "sigma_scale_misalignment");
    let truth = unit().gyro.scale_misalignment;
    for i in 0..3 {
        for j in 0..3 {
            let z = (m[i][j] - truth[i][j]) / sigma[i][j];
            // 4σ: 9 entries with a few degrees of freedom (Student-t tails);
            // the coverage over 60 seeds is the lab's test.
            assert!(
                z.abs() < 4.0,
                "({i},{j}): {} vs {} (σ {}), z {z}",
                m[i][j],
                truth[i][j],
                sigma[i][j]
            );
            assert!(sigma[i][j] > 0.0 && sigma[i][j] < 5e-3, "σ {}", sigma[i][j]);
        }
    }
    let b = file["gyro"]["bias"].as_array().unwrap();
    for (k, truth) in unit().gyro.bias.iter().enumerate() {
        assert!((b[k].as_float().unwrap() - truth).abs() < 2e-3, "bias {k}");
    }
}

#[test]
fn degenerate_records_are_refused_with_what_to_do() {
    let d = dir("imu-refusals");
    let out = d.join("cal.toml");
    // Too few poses for the accelerometer.
    let few = hand_csv(&d, "few", &script(6, Axes::Any), 3);
    let o = triad(&[
        "calib",
        "fit",
        "imu",
        "--positions",
        s(&few),
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    assert!(
        e.contains("accelerometer:") && e.contains("turn the board to more orientations"),
        "{e}"
    );
    // Every turn about one axis: gravity stays in one plane of the sensor,
    // which the accelerometer fit refuses first.
    let one_axis = hand_csv(&d, "one-axis", &script(16, Axes::One([0.0, 0.0, 1.0])), 4);
    let o = fit_imu(&one_axis, &out);
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    assert!(
        e.contains("gravity directions in one plane") && e.contains("tilt the sensor"),
        "{e}"
    );
    // A pose that is not static (a slow turn about the vertical, which the
    // accelerometer cannot see): the gyroscope's fit refuses it.
    let mut drifting = script(16, Axes::Any);
    drifting.drift = Some((5, 0.02));
    let drift = hand_csv(&d, "drift", &drifting, 5);
    let o = fit_imu(&drift, &out);
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    assert!(
        e.contains("gyroscope: pose 6") && e.contains("hold it still at each pose"),
        "{e}"
    );
    assert!(!out.exists(), "nothing written");
}

/// `triad calib fit imu --positions input --out out`.
fn fit_imu(input: &Path, out: &Path) -> std::process::Output {
    triad(&[
        "calib",
        "fit",
        "imu",
        "--positions",
        s(input),
        "--out",
        s(out),
    ])
}

#[test]
fn a_six_face_tumble_gives_both_triads_with_axis_aligned() {
    let d = dir("imu-tumble");
    let input = d.join("tumble.csv");
    let o = triad(&["sim", "-q", "--scene", "tumble-6", "--out", s(&input)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let cal = d.join("cal.toml");
    let fit = |extra: &[&str]| {
        let mut args = vec!["calib", "fit", "imu", "--positions", s(&input)];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", s(&cal)]);
        triad(&args)
    };
    // Six gravity directions cannot give the ellipsoid fit; the refusal
    // says what can.
    let o = fit(&[]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("give --axis-aligned for a cube tumble"));
    let o = fit(&["--axis-aligned"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let file: toml::Table = std::fs::read_to_string(&cal).unwrap().parse().unwrap();
    let m = matrix(&file, "gyro", "scale_misalignment");
    let sigma = matrix(
        file["fit"].as_table().unwrap(),
        "gyro",
        "sigma_scale_misalignment",
    );
    // scenes/tumble-6.toml's gyro: scale factors 4000, −2000, 1000 ppm on
    // the diagonal, its misalignment (mrad) off it, in the faces' (body)
    // frame, which is the fit's frame here.
    let truth = [
        [1.004, 0.001, -0.002],
        [0.002, 0.998, 0.001],
        [-0.001, 0.002, 1.001],
    ];
    for i in 0..3 {
        for j in 0..3 {
            let z = (m[i][j] - truth[i][j]) / sigma[i][j];
            // 4σ: 9 entries, and the gyro's 0.061 °/s LSB above its noise
            // (quantisation is not in the σ's).
            assert!(
                z.abs() < 4.0,
                "({i},{j}): {} vs {} z {z}",
                m[i][j],
                truth[i][j]
            );
        }
    }
}

#[test]
fn a_simulated_unit_with_g_sensitivity_gives_g_within_3_sigma() {
    use triad_lab::calib_fit::accel_frame::in_accel_frame;
    let d = dir("imu-g");
    let (m, truth) = simulate_g_unit(&d);
    let cal = d.join("cal.toml");
    let o = fit_imu(&m, &cal);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(
        report.contains("g-sensitivity G, °/s per g") && report.contains("in the calibration"),
        "{report}"
    );
    assert!(
        report.contains("poses' consistency: each pose's gyro mean within"),
        "{report}"
    );
    let file: toml::Table = std::fs::read_to_string(&cal).unwrap().parse().unwrap();
    let truth: toml::Table = std::fs::read_to_string(&truth).unwrap().parse().unwrap();
    let fitted = matrix(&file, "gyro", "g_sensitivity");
    let fit = file["fit"]["gyro"]["g_sensitivity"].as_table().unwrap();
    let sigma: [[f64; 3]; 3] = std::array::from_fn(|i| {
        let row = fit["sigma"][i].as_array().unwrap();
        std::array::from_fn(|j| row[j].as_float().unwrap())
    });
    // The truth's G maps body-axis forces; the fit's, the accelerometer's
    // corrected axes (as its gyro (I+Σ)): G·Qᵀ.
    let frame = in_accel_frame(
        &matrix(&truth, "accel", "scale_misalignment"),
        &matrix(&truth, "gyro", "g_sensitivity"),
    )
    .unwrap();
    for i in 0..3 {
        for j in 0..3 {
            let z = (fitted[i][j] - frame.gyro[i][j]) / sigma[i][j];
            assert!(
                z.abs() <= 3.0,
                "G[{i}][{j}]: {} vs {} (σ {}), z {z}",
                fitted[i][j],
                frame.gyro[i][j],
                sigma[i][j]
            );
        }
    }
    // The file with G verifies and packs: `calib check` prints it.
    let o = triad(&["calib", "check", s(&cal)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("g-sensitivity G in °/s per g"),
        "{}",
        text(&o.stdout)
    );
}
