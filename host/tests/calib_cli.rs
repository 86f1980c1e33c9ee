//! `triad calib check` and `triad calib pack` on the example files in
//! calibrations/: exit codes, one-line reasons, and the packed blob.

mod common;

use std::path::PathBuf;

use common::{calibration, text, triad};
use triad::model::{blob, Orientation, Triad};

#[test]
fn check_accepts_the_examples_and_prints_conditioning_and_coefficients() {
    for name in ["default.toml", "lab-example.toml"] {
        let path = calibration(name);
        let out = triad(&["calib", "check", path.to_str().unwrap()]);
        let stdout = text(&out.stdout);
        assert!(out.status.success(), "{name}: {}", text(&out.stderr));
        assert!(stdout.contains(": OK"), "{stdout}");
        assert_eq!(
            stdout.matches("condition number κ₁ = ").count(),
            2,
            "{stdout}"
        );
        assert_eq!(stdout.matches("    K = [").count(), 4, "{stdout}");
        assert!(
            stdout.contains("fixed point (Q16.16) error bound"),
            "{stdout}"
        );
    }
    let out = triad(&[
        "calib",
        "check",
        calibration("lab-example.toml").to_str().unwrap(),
    ]);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("calibration id: 0x0135290"), "{stdout}"); // id = 20261122
    assert!(
        stdout.contains("orientation: ROTATION_YAW_90 (2)"),
        "{stdout}"
    );
}

#[test]
fn check_rejects_each_bad_file_with_one_line_naming_the_problem() {
    let cases = [
        ("nan-entry.toml", "accel scale_misalignment[1][2] = NaN: not a finite number"),
        ("inf-bias.toml", "gyro bias[1] = -inf: not a finite number"),
        ("singular.toml", "accel scale_misalignment: singular"),
        ("nearly-singular.toml", "gyro scale_misalignment: condition number"),
        (
            "scale-out-of-range.toml",
            "accel scale_misalignment[1][1] = 1.7: diagonal (scale factor) outside the sane range 0.5..1.5",
        ),
        ("misalignment.toml", "accel scale_misalignment[0][2] = 0.3: off-diagonal"),
        ("bias-beyond-full-scale.toml", "accel bias[2] = 200: beyond the sensor's full scale"),
        ("temperature-absurd.toml", "accel temperature.scale_misalignment_per_c[0][0] = 0.05"),
        ("missing-bias.toml", "missing field `bias` (in `gyro`)"),
        ("short-row.toml", "2:40: invalid length 2, expected an array of length 3 (in `accel.scale_misalignment`)"),
        ("long-bias.toml", "6:8: invalid length 4, expected an array of length 3 (in `gyro.bias`)"),
        ("fourth-row.toml", "2:22: invalid length 4, expected an array of length 3 (in `accel.scale_misalignment`)"),
        ("misspelt-key.toml", "unknown field `temprature`"),
        ("bad-orientation.toml", "orientation: `ROTATION_YAW_45` is not one of the 24"),
    ];
    let dir = calibration("bad");
    for (name, reason) in cases {
        let path = dir.join(name);
        let out = triad(&["calib", "check", path.to_str().unwrap()]);
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "{name} accepted");
        assert!(out.stdout.is_empty(), "{name}: {}", text(&out.stdout));
        assert_eq!(stderr.lines().count(), 1, "{name}: not one line: {stderr}");
        assert!(
            stderr.contains(path.to_str().unwrap()),
            "{name}: file not named: {stderr}"
        );
        assert!(
            stderr.contains(reason),
            "{name}: expected `{reason}` in: {stderr}"
        );
    }
    // Every file in bad/ is covered above.
    let files = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(files, cases.len());
}

#[test]
fn ranges_given_on_the_command_line_bound_the_bias() {
    // default.toml's accel bias 0.1 m/s² is within ±16 g but a gyro bias of
    // 0.002 rad/s is beyond a ±0.1 °/s range (0.00175 rad/s).
    let path = calibration("default.toml");
    let p = path.to_str().unwrap();
    assert!(triad(&[
        "calib",
        "check",
        p,
        "--accel-range-g",
        "2",
        "--gyro-range-dps",
        "125"
    ])
    .status
    .success());
    let out = triad(&["calib", "check", p, "--gyro-range-dps", "0.1"]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("gyro bias[1] = -0.002: beyond the sensor's full scale"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn pack_writes_the_blob_and_the_checked_in_default_matches_its_toml() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let out_path = dir.join("calib_cli_default.bin");
    let out = triad(&[
        "calib",
        "pack",
        calibration("default.toml").to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let packed = std::fs::read(&out_path).unwrap();
    assert_eq!(packed.len(), blob::BLOB_LEN);
    let cal = blob::decode(&packed).unwrap();
    // The values of default.toml, and its id is the CRC-32C of the parameters.
    assert_eq!(cal.accel.scale_misalignment[0], [1.002, 0.001, -0.0005]);
    assert_eq!(cal.accel.bias, [0.05, -0.02, 0.10]);
    assert_eq!(cal.gyro.bias, [0.001, -0.002, 0.0005]);
    assert_eq!(cal.g_sensitivity.map(|g| g[1][1]), Some(2.1e-4));
    assert_eq!(cal.id, blob::parameter_id(&cal));
    assert!(text(&out.stderr).contains(&format!("{:#010x}", cal.id)));
    // The firmware embeds calibrations/default.bin: it must be this file's pack.
    let checked_in = std::fs::read(calibration("default.bin")).unwrap();
    assert!(checked_in == packed, "calibrations/default.bin is stale: run `triad calib pack calibrations/default.toml -o calibrations/default.bin`");

    // A bad file is not packed.
    let bad_path = dir.join("calib_cli_bad.bin");
    let _ = std::fs::remove_file(&bad_path);
    let out = triad(&[
        "calib",
        "pack",
        calibration("bad/singular.toml").to_str().unwrap(),
        "-o",
        bad_path.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(!bad_path.exists());
}

#[test]
fn lab_example_loads_with_temperature_terms_and_orientation() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let out_path = dir.join("calib_cli_lab.bin");
    let out = triad(&[
        "calib",
        "pack",
        calibration("lab-example.toml").to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let cal = blob::decode(&std::fs::read(&out_path).unwrap()).unwrap();
    assert_eq!(cal.id, 20261122);
    let t = cal
        .triad(Triad::Accel)
        .temperature
        .expect("accel temperature terms");
    assert_eq!(t.reference_c, 25.0);
    assert_eq!(t.bias_coefficients[2], [1.1e-2, 4.0e-5, 2.5e-7]);
    assert!(cal.gyro.temperature.is_some());
    assert_eq!(
        Orientation::from_name("ROTATION_YAW_90"),
        Some(Orientation::Yaw90)
    );
}
