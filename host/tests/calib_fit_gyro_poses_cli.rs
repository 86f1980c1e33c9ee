//! `triad calib fit gyro --static` on a record of several static poses with
//! turns between them: the bias and, where the poses' gravity directions
//! span three dimensions, the gyro's g-sensitivity G with its σ's (the
//! simulator's `g_sensitivity` effect gives the truth); G reported as not
//! supported where the poses do not determine it, and never invented for a
//! unit without one.

mod common;

use common::{dir, hand_csv, matrix, s, simulate_g_unit, text, triad};
use triad_lab::calib_fit::hand_record::{Axes, Script};

/// `calib fit gyro --static RECORD --out OUT` with `extra` options.
fn fit_static(
    record: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "calib",
        "fit",
        "gyro",
        "--static",
        s(record),
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    triad(&args)
}

fn read(path: &std::path::Path) -> toml::Table {
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

#[test]
fn poses_of_a_unit_with_g_sensitivity_give_g_within_3_sigma() {
    let d = dir("gyro-poses-g");
    let (m, truth) = simulate_g_unit(&d);
    let cal = d.join("cal.toml");
    // The truth's accelerometer as the base: its corrected axes are the
    // body's, the frame of the truth's G.
    let o = fit_static(&m, &cal, &["--base", s(&truth)]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(
        report.contains("gyro at rest in 16 static poses"),
        "{report}"
    );
    assert!(
        report.contains("g-sensitivity G, °/s per g") && report.contains("in the calibration"),
        "{report}"
    );
    let file = read(&cal);
    let truth = read(&truth);
    let fitted = matrix(&file, "gyro", "g_sensitivity");
    let fit = file["fit"]["gyro"]["g_sensitivity"].as_table().unwrap();
    assert_eq!(fit["degrees_of_freedom"].as_integer(), Some(16 - 4));
    let sigma: [[f64; 3]; 3] = std::array::from_fn(|i| {
        let row = fit["sigma"][i].as_array().unwrap();
        std::array::from_fn(|j| row[j].as_float().unwrap())
    });
    let g_truth = matrix(&truth, "gyro", "g_sensitivity");
    for i in 0..3 {
        for j in 0..3 {
            let z = (fitted[i][j] - g_truth[i][j]) / sigma[i][j];
            assert!(
                z.abs() <= 3.0,
                "G[{i}][{j}]: {} vs {} (σ {}), z {z}",
                fitted[i][j],
                g_truth[i][j],
                sigma[i][j]
            );
        }
    }
    // The bias is the fit's intercept (the reading at zero specific force),
    // within 3σ of the truth's.
    let bias = |t: &toml::Table| -> Vec<f64> {
        t["gyro"]["bias"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().unwrap())
            .collect()
    };
    let sigma_bias: Vec<f64> = file["fit"]["gyro"]["sigma_bias"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_float().unwrap())
        .collect();
    let (b, b_truth) = (bias(&file), bias(&truth));
    for i in 0..3 {
        assert!(
            (b[i] - b_truth[i]).abs() <= 3.0 * sigma_bias[i],
            "b[{i}] {} vs {} (σ {})",
            b[i],
            b_truth[i],
            sigma_bias[i]
        );
    }
    // The file with G verifies: `calib check` prints it.
    let o = triad(&["calib", "check", s(&cal)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("g-sensitivity G in °/s per g"));
}

#[test]
fn poses_of_a_unit_without_g_sensitivity_get_none_invented() {
    let d = dir("gyro-poses-no-g");
    let script = Script {
        rate_hz: 100.0,
        poses: 16,
        static_s: 4.0,
        turn_s: 1.5,
        angle_deg: (60.0, 150.0),
        axes: Axes::Any,
        drift: None,
    };
    let record = hand_csv(&d, "hand", &script, 21);
    let cal = d.join("cal.toml");
    let o = fit_static(&record, &cal, &[]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(
        report.contains("consistent with zero: left out of the calibration"),
        "{report}"
    );
    let file = read(&cal);
    assert!(file["gyro"].get("g_sensitivity").is_none(), "{file}");
    // The bias is then the mean of the poses' means, with poses − 1
    // degrees of freedom.
    assert_eq!(
        file["fit"]["gyro"]["bias_degrees_of_freedom"].as_integer(),
        Some(15)
    );
}

#[test]
fn poses_turned_about_one_axis_do_not_support_g() {
    // Turns about one body axis keep gravity on a cone about it: the poses'
    // directions lie on one circle and do not determine G.
    let d = dir("gyro-poses-circle");
    let script = Script {
        rate_hz: 100.0,
        poses: 12,
        static_s: 4.0,
        turn_s: 1.5,
        angle_deg: (60.0, 150.0),
        axes: Axes::One([1.0, 0.0, 0.0]),
        drift: None,
    };
    let record = hand_csv(&d, "circle", &script, 4);
    let cal = d.join("cal.toml");
    let o = fit_static(&record, &cal, &[]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(
        report.contains("g-sensitivity G: not supported: the poses' gravity directions do not span three dimensions"),
        "{report}"
    );
    let file = read(&cal);
    assert!(file["gyro"].get("g_sensitivity").is_none());
    assert_eq!(
        file["fit"]["gyro"]["g_sensitivity"]["status"].as_str(),
        Some("not supported by the poses")
    );
}

/// A record at 100 Hz: `seconds` of samples, the accelerometer still
/// (gravity on z with a little noise), the gyro `rate(t)` about z (rad/s).
fn one_pose_csv(path: &std::path::Path, seconds: f64, rate: impl Fn(f64) -> f64) {
    let mut csv = String::from("t,ax,ay,az,gx,gy,gz\n");
    for i in 0..(seconds * 100.0) as usize {
        let t = i as f64 / 100.0;
        // A deterministic wobble well below the detector's threshold.
        let e = 1e-3 * ((i * 7919) % 13) as f64;
        csv.push_str(&format!(
            "{t},{e},{},{},{},{},{}\n",
            -e,
            9.81 + e,
            1e-3 + e * 1e-3,
            -2e-3,
            rate(t) + 5e-4
        ));
    }
    std::fs::write(path, csv).unwrap();
}

#[test]
fn fewer_than_two_poses_are_said_with_the_bias_and_with_a_refusal() {
    let d = dir("gyro-one-pose");
    // Still throughout: one pose, so the bias alone, and the report says why.
    let still = d.join("still.csv");
    one_pose_csv(&still, 20.0, |_| 0.0);
    let o = fit_static(&still, &d.join("cal.toml"), &[]);
    let report = text(&o.stdout);
    assert!(o.status.success(), "{report}{}", text(&o.stderr));
    assert!(
        report.contains("gyro static bias:")
            && report.contains("pose detection found 1 static pose(s)")
            && report.contains("G needs two or more"),
        "{report}"
    );
    // Turning about the vertical for the last 5 s: the accelerometer still
    // sees one pose, the gyro a turn; the refusal says both.
    let turned = d.join("turned.csv");
    one_pose_csv(&turned, 20.0, |t| if t >= 15.0 { 0.5 } else { 0.0 });
    let o = fit_static(&turned, &d.join("cal2.toml"), &[]);
    let said = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{said}");
    assert!(
        said.contains("turned.csv") && said.contains("pose detection found 1 static pose(s)"),
        "{said}"
    );
}
