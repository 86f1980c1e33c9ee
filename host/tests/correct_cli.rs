//! `triad correct` against the library: the same f32 kernel bit for bit, the
//! f64 reference with `--exact`, and malformed CSV named by line and column.

mod common;

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

use common::{calibration, text, TRIAD};
use triad::model::{blob, Calibration, Corrector, Orientation};
use triad::units::{deg_to_rad, STANDARD_GRAVITY};

/// Runs `triad correct` with `csv` on stdin.
fn correct(calib: &str, csv: &str, extra: &[&str]) -> Output {
    let mut child = Command::new(TRIAD)
        .args([
            "correct",
            "--calib",
            calibration(calib).to_str().unwrap(),
            "-",
        ])
        .args(extra)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A refused calibration ends `triad correct` before it reads its input,
    // so the write may meet a closed pipe: that is the behaviour under test,
    // not a failure of the harness. The exit status and output say the rest.
    let _ = child.stdin.take().unwrap().write_all(csv.as_bytes());
    child.wait_with_output().unwrap()
}

/// The calibration in `name` as the library sees it (through `calib pack`).
fn library_calibration(name: &str) -> Calibration {
    let out_path =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("correct_cli_{name}.bin"));
    let out = Command::new(TRIAD)
        .args([
            "calib",
            "pack",
            calibration(name).to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    blob::decode(&std::fs::read(out_path).unwrap()).unwrap()
}

/// A small CSV with temperatures: a tumble of a static sensor plus rotation.
fn input_csv() -> String {
    let mut s = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..60 {
        let x = f64::from(i) * 0.1;
        let t = 20.0 + f64::from(i) * 0.25;
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            f64::from(i) * 1e-3,
            9.80665 * x.sin() * 0.3,
            -9.80665 * x.cos() * 0.2,
            9.80665 * x.cos(),
            0.5 * x.sin(),
            -0.25,
            1e-3 * f64::from(i),
            t
        ));
    }
    s
}

fn corrector(name: &str, orientation: Orientation) -> Corrector {
    Corrector::new_si(
        &library_calibration(name),
        16.0 * STANDARD_GRAVITY,
        deg_to_rad(2000.0),
        orientation,
    )
    .unwrap()
}

#[test]
fn f32_output_is_bit_exact_with_the_library_kernel() {
    let csv = input_csv();
    let out = correct("lab-example.toml", &csv, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let mut lines = stdout.lines();
    assert_eq!(lines.next(), Some("t,ax,ay,az,gx,gy,gz,temp"));
    let mut c = corrector("lab-example.toml", Orientation::Yaw90);
    let mut rows = 0;
    for (input, output) in csv.lines().skip(1).zip(lines) {
        let i: Vec<&str> = input.split(',').collect();
        let o: Vec<&str> = output.split(',').collect();
        assert_eq!(
            (o[0], o[7]),
            (i[0], i[7]),
            "t and temp pass through verbatim"
        );
        let v: Vec<f32> = i[1..7].iter().map(|x| x.parse().unwrap()).collect();
        let temp: f64 = i[7].parse().unwrap();
        c.refold(temp).unwrap();
        let m = c.correct_si([v[0], v[1], v[2]], [v[3], v[4], v[5]], temp as f32);
        let got: Vec<f32> = o[1..7].iter().map(|x| x.parse().unwrap()).collect();
        let want = [m.accel, m.gyro].concat();
        assert_eq!(
            got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            "line {input}"
        );
        rows += 1;
    }
    assert_eq!(rows, 60);
}

#[test]
fn exact_output_is_the_f64_reference() {
    let csv = "t,ax,ay,az,gx,gy,gz\n0.5,0.1,-0.2,9.81,0.01,0.02,-0.03\n1.5,-3,4.5,1e-3,1,-1,0.25\n";
    let out = correct("default.toml", csv, &["--exact"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let c = corrector("default.toml", Orientation::RotationNone);
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0], "t,ax,ay,az,gx,gy,gz");
    for (input, output) in csv.lines().skip(1).zip(&lines[1..]) {
        let v: Vec<f64> = input
            .split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        let m = c.reference_si([v[0], v[1], v[2]], [v[3], v[4], v[5]], 0.0);
        let got: Vec<f64> = output
            .split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(
            got,
            [m.accel, m.gyro].concat(),
            "f64 values round-trip exactly through the text"
        );
    }
    // And the correction did something: bias 0.05 removed from ax.
    assert!(lines[1].starts_with("0.5,0.0"), "{}", lines[1]);
}

#[test]
fn malformed_csv_is_named_by_line_and_column() {
    let header = "t,ax,ay,az,gx,gy,gz\n";
    let cases = [
        (
            format!("{header}0,1,2,3,4,5,6\n1,1,x,3,4,5,6\n"),
            "stdin line 3, column 3 (ay): `x` is not a number",
        ),
        (
            format!("{header}0,1,2,3,4,5\n"),
            "stdin line 2: expected 7 columns as in the header, found 6",
        ),
        (
            format!("{header}0,1,2,3,4,5,nan\n"),
            "stdin line 2, column 7 (gz): `nan` is not a finite number",
        ),
        (
            format!("{header}0,1,2,3,4,1e39,6\n"),
            "stdin line 2, column 6 (gy): `1e39` is beyond the f32 range",
        ),
        (
            "t,ax,ay,az,gx,gy\n".to_string(),
            "stdin line 1: missing column(s) `gz` in the header `t,ax,ay,az,gx,gy`",
        ),
        (String::new(), "stdin: empty input"),
        (
            "t,ax,ay,az,gx,gy,gz,temp\n0,1,2,3,4,5,6,warm\n".to_string(),
            "stdin line 2, column 8 (temp): `warm` is not a number",
        ),
    ];
    for (csv, message) in cases {
        let out = correct("default.toml", &csv, &[]);
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "accepted: {csv}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(message), "expected `{message}` in {stderr}");
    }
}

#[test]
fn blank_lines_and_crlf_are_accepted() {
    let out = correct(
        "default.toml",
        "t,ax,ay,az,gx,gy,gz\r\n\r\n0,0,0,0,0,0,0\r\n\n",
        &[],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout).lines().count(), 2);
}

#[test]
fn a_bad_calibration_is_refused_before_any_output() {
    let out = correct(
        "bad/singular.toml",
        "t,ax,ay,az,gx,gy,gz\n0,0,0,0,0,0,0\n",
        &[],
    );
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    assert!(text(&out.stderr).contains("singular"));
}
