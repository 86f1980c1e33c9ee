//! `triad sim` end to end: every shipped scene runs, the files have the
//! documented columns and length, the same seed gives the same bytes, a scene
//! without effects gives the truth, and bad scenes fail with a file position.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::tmp;

fn triad() -> Command {
    Command::new(env!("CARGO_BIN_EXE_triad"))
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scenes")
}

fn rate_of(scene: &Path) -> f64 {
    let text = std::fs::read_to_string(scene).unwrap();
    let v: toml::Value = toml::from_str(&text).unwrap();
    v["rate_hz"].as_float().unwrap()
}

#[test]
fn every_shipped_scene_runs_and_writes_the_documented_columns() {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            names.push(path.file_stem().unwrap().to_string_lossy().into_owned());
        }
    }
    names.sort();
    for required in [
        "static-bench",
        "rate-table",
        "tumble-6",
        "vibration",
        "thermal-ramp",
    ] {
        assert!(
            names.iter().any(|n| n == required),
            "scene {required} is shipped"
        );
    }
    for name in &names {
        let out = tmp(&format!("{name}.csv"));
        let truth = tmp(&format!("{name}-truth.csv"));
        let status = triad()
            .args([
                "sim",
                "--scene",
                name,
                "--seconds",
                "1.5",
                "--seed",
                "3",
                "--out",
            ])
            .arg(&out)
            .arg("--truth")
            .arg(&truth)
            .status()
            .unwrap();
        assert!(status.success(), "scene {name}");
        let rate = rate_of(&scenes_dir().join(format!("{name}.toml")));
        for file in [&out, &truth] {
            let text = std::fs::read_to_string(file).unwrap();
            let mut lines = text.lines();
            assert_eq!(lines.next(), Some("t,ax,ay,az,gx,gy,gz,temp"));
            let rows: Vec<Vec<f64>> = lines
                .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
                .collect();
            assert_eq!(
                rows.len() as f64,
                (1.5 * rate).round(),
                "scene {name}: rows"
            );
            assert!(rows
                .iter()
                .all(|r| r.len() == 8 && r.iter().all(|x| x.is_finite())));
            // t = k/rate.
            assert_eq!(rows[1][0], 1.0 / rate);
        }
    }
}

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let run = |seed: &str, name: &str| {
        let out = tmp(name);
        let ok = triad()
            .args([
                "sim",
                "--scene",
                "static-bench",
                "--seconds",
                "2",
                "--seed",
                seed,
                "--out",
            ])
            .arg(&out)
            .status()
            .unwrap()
            .success();
        assert!(ok);
        std::fs::read(out).unwrap()
    };
    let a = run("7", "seed7a.csv");
    let b = run("7", "seed7b.csv");
    let c = run("8", "seed8.csv");
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn scene_without_effects_measures_the_truth() {
    let (out, truth) = (tmp("t-out.csv"), tmp("t-truth.csv"));
    let ok = triad()
        .args([
            "sim",
            "--scene",
            "truth-only",
            "--seconds",
            "3",
            "--rate",
            "50",
            "--out",
        ])
        .arg(&out)
        .arg("--truth")
        .arg(&truth)
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let a = std::fs::read_to_string(out).unwrap();
    assert_eq!(a, std::fs::read_to_string(truth).unwrap());
    assert_eq!(
        a.lines().count(),
        1 + 150,
        "--rate overrides the scene's rate"
    );
}

fn fails_with(scene_text: &str, name: &str, expected: &[&str]) {
    let path = tmp(name);
    std::fs::write(&path, scene_text).unwrap();
    let output = triad()
        .args(["sim", "--seconds", "1", "--out"])
        .arg(tmp("never.csv"))
        .arg("--scene")
        .arg(&path)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let err = String::from_utf8_lossy(&output.stderr);
    for e in expected {
        assert!(err.contains(e), "stderr {err:?} should contain {e:?}");
    }
}

#[test]
fn unknown_effect_is_an_error_at_its_line_and_column() {
    fails_with(
        "rate_hz = 100.0\n[motion]\nkind = \"static\"\n[gyro]\nwhite_nose = \"0.1 deg/sqrt(h)\"\n",
        "unknown.toml",
        &["unknown.toml:5:1", "unknown field `white_nose`"],
    );
}

#[test]
fn negative_density_is_an_error_at_its_line_and_column() {
    fails_with(
        "rate_hz = 100.0\n[motion]\nkind = \"static\"\n[accel]\nwhite_noise = \"-40 ug/sqrt(Hz)\"\n",
        "negative.toml",
        &["negative.toml:5:15", "must not be negative", "-40 ug/sqrt(Hz)"],
    );
}

#[test]
fn missing_field_is_an_error_with_a_position() {
    fails_with(
        "[motion]\nkind = \"static\"\n",
        "missing.toml",
        &["missing.toml:1:1", "missing field `rate_hz`"],
    );
    fails_with(
        "rate_hz = 10.0\n[motion]\nkind = \"tumble\"\npositions = 6\n",
        "missing-dwell.toml",
        &["missing-dwell.toml:3:8", "needs `dwell_s`"],
    );
}

#[test]
fn wrong_unit_dimension_is_an_error() {
    fails_with(
        "rate_hz = 100.0\n[motion]\nkind = \"static\"\n[gyro]\nwhite_noise = \"0.1 deg/h\"\n",
        "dimension.toml",
        &["dimension.toml:5:15", "white_noise", "deg/sqrt(h)"],
    );
}

#[test]
fn unknown_scene_name_lists_the_shipped_scenes() {
    let output = triad()
        .args(["sim", "--scene", "no-such-scene", "--seconds", "1", "--out"])
        .arg(tmp("never2.csv"))
        .output()
        .unwrap();
    assert!(!output.status.success());
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(
        err.contains("scene `no-such-scene`: no such file, and no shipped scene"),
        "{err}"
    );
    assert!(err.contains("static-bench, thermal-ramp"), "{err}");
}

/// `--pack` writes the blob the emulated board embeds: decoded and simulated,
/// it gives the very samples `triad sim` writes for the same scene and seed,
/// for every shipped scene.
#[test]
fn packed_scenes_simulate_exactly_what_triad_sim_writes() {
    use triad_sim::scenes::scene_blob::decode;
    use triad_sim::scenes::simulator::Simulator;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let (blob, csv) = (tmp(&format!("{name}.bin")), tmp(&format!("{name}-p.csv")));
        let packed = triad()
            .args(["sim", "--scene", &name, "--seed", "42", "--pack"])
            .arg(&blob)
            .status()
            .unwrap();
        assert!(packed.success(), "{name}: pack");
        let simulated = triad()
            .args([
                "sim",
                "--scene",
                &name,
                "--seed",
                "42",
                "--seconds",
                "0.2",
                "--out",
            ])
            .arg(&csv)
            .status()
            .unwrap();
        assert!(simulated.success(), "{name}: sim");

        let (scene, seed) = decode(&std::fs::read(&blob).unwrap()).unwrap();
        assert_eq!(seed, 42);
        let mut sim = Simulator::new(&scene, seed).unwrap();
        let text = std::fs::read_to_string(&csv).unwrap();
        let rows: Vec<&str> = text.lines().skip(1).collect();
        assert!(!rows.is_empty(), "{name}: rows");
        for row in rows {
            let s = sim.step();
            let mut line = Vec::new();
            let m = s.measured;
            write!(
                line,
                "{},{},{},{},{},{},{},{}",
                s.t,
                m.specific_force[0],
                m.specific_force[1],
                m.specific_force[2],
                m.angular_rate[0],
                m.angular_rate[1],
                m.angular_rate[2],
                m.temperature
            )
            .unwrap();
            assert_eq!(String::from_utf8(line).unwrap(), row, "{name}");
        }
    }
}

#[test]
fn pack_refuses_to_go_without_a_file_and_sim_without_out() {
    let out = triad()
        .args(["sim", "--scene", "static-bench"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--out"));
}
