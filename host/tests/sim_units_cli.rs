//! `triad sim --unit --script --record-seed`: records of one unit share its
//! turn-on errors and not their noise, units of other seeds differ, the
//! `--truth-calib` file corrects a unit's records back to the true motion
//! through `triad correct`, and what is asked wrongly is refused.

mod common;

use std::path::Path;

use common::{dir, s, text, triad};

/// A unit with only deterministic errors, temperature terms about two
/// references, so `correct` must apply them at every sample's temperature.
const CLEAN_UNIT: &str = "seed = 5\n\
[accel]\nturn_on_bias = \"20 mg\"\nturn_on_scale = \"0.5 %\"\nturn_on_misalignment = \"5 mrad\"\nscale_factor = \"1000 ppm\"\n\
[accel.temperature]\nreference_c = 20.0\nbias = [\"100 ug/degC\", \"-80 ug/degC\", \"150 ug/degC\"]\nscale = \"100 ppm/degC\"\n\
[gyro]\nturn_on_bias = \"0.5 deg/s\"\nturn_on_scale = \"0.5 %\"\nturn_on_misalignment = \"5 mrad\"\n\
g_sensitivity = [[\"0.12 deg/s/g\", \"0.02 deg/s/g\", \"0 deg/s/g\"], [\"-0.01 deg/s/g\", \"0.1 deg/s/g\", \"0.03 deg/s/g\"], [\"0 deg/s/g\", \"0.02 deg/s/g\", \"-0.08 deg/s/g\"]]\n\
[gyro.temperature]\nreference_c = 30.0\nbias = \"0.005 deg/s/degC\"\nscale = \"-100 ppm/degC\"\n";

/// Hand rotations through three soaks, 14 s each.
const SOAK_HAND: &str = "rate_hz = 50.0\nduration_s = 42.0\n\
[motion]\nkind = \"hand\"\nposes = 12\nseed = 9\ndwell_s = 3.0\nturn_s = 1.5\n\
[temperature]\nkind = \"soak\"\nlevels_c = [-5.0, 25.0, 55.0]\nhold_s = 14.0\n";

fn sim(args: &[&str]) -> String {
    let out = triad(&[&["sim"], args].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    text(&out.stderr)
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

/// The numeric columns of a CSV, row by row.
fn rows(p: &Path) -> Vec<Vec<f64>> {
    read(p)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn records_of_one_unit_share_its_turn_on_errors_but_not_their_noise() {
    let d = dir("records");
    let record = |unit: &str, k: &str, name: &str| {
        let (out, truth, cal) = (
            d.join(format!("{name}.csv")),
            d.join(format!("{name}-truth.csv")),
            d.join(format!("{name}.toml")),
        );
        sim(&[
            "--unit",
            unit,
            "--script",
            "hand-rotations",
            "--record-seed",
            k,
            "--seconds",
            "20",
            "--out",
            s(&out),
            "--truth",
            s(&truth),
            "--truth-calib",
            s(&cal),
        ]);
        (rows(&out), read(&truth), read(&cal))
    };
    let (m1, t1, c1) = record("tactical-mems", "1", "k1");
    let (m2, t2, c2) = record("tactical-mems", "2", "k2");
    let (m1_again, _, _) = record("tactical-mems", "1", "k1-again");
    assert_eq!(c1, c2, "the same unit: the same true calibration");
    assert_eq!(t1, t2, "the same script: the same motion");
    assert_eq!(m1, m1_again, "the same record seed: the same record");
    // Other noise: no sample of the gyro's x axis is the same in both.
    let same = m1.iter().zip(&m2).filter(|(a, b)| a[4] == b[4]).count();
    assert_eq!(same, 0, "{same} of {} samples share their noise", m1.len());
    // Another seed: another unit; only its turn-on errors differ (the
    // fixed temperature terms are the file's).
    let other = d.join("unit-seed-2.toml");
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/units/tactical-mems.toml");
    std::fs::write(&other, read(&shipped).replace("seed = 1\n", "seed = 2\n")).unwrap();
    let (_, _, c3) = record(s(&other), "1", "other");
    let line = |c: &str, key: &str| c.lines().find(|l| l.starts_with(key)).map(str::to_string);
    assert_ne!(line(&c1, "bias ="), line(&c3, "bias ="));
    assert_ne!(
        line(&c1, "scale_misalignment ="),
        line(&c3, "scale_misalignment =")
    );
    assert_eq!(
        line(&c1, "bias_coefficients"),
        line(&c3, "bias_coefficients")
    );

    // Fitted, not only declared: over the first pose (5 s still), two
    // records of consumer-mems (white noise only, 70 µg/√Hz at 100 Hz: σ of
    // a 500-sample mean 0.022 mg, of a difference 0.03 mg) agree within
    // 0.15 mg (5σ); a unit of another seed differs by its turn-on bias
    // (σ 20 mg) and scale (σ 0.5 %).
    let consumer = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/units/consumer-mems.toml");
    let other = d.join("consumer-other.toml");
    std::fs::write(&other, read(&consumer).replace("seed = 7\n", "seed = 8\n")).unwrap();
    let (a1, _, _) = record("consumer-mems", "1", "c1");
    let (a2, _, _) = record("consumer-mems", "2", "c2");
    let (b1, _, _) = record(s(&other), "1", "c3");
    let mean = |m: &[Vec<f64>], c: usize| m[..500].iter().map(|r| r[c]).sum::<f64>() / 500.0;
    let limit = 0.15e-3 * 9.80665;
    let mut apart = 0.0f64;
    for c in 1..4 {
        let same = (mean(&a1, c) - mean(&a2, c)).abs();
        assert!(
            same < limit,
            "axis {c}: {same} m/s² between records of one unit"
        );
        apart = apart.max((mean(&a1, c) - mean(&b1, c)).abs());
    }
    assert!(apart > 10.0 * limit, "two units {apart} m/s² apart");
}

#[test]
fn the_true_calibration_corrects_a_units_records_to_the_true_motion() {
    let d = dir("truth");
    let (unit, script) = (d.join("unit.toml"), d.join("script.toml"));
    std::fs::write(&unit, CLEAN_UNIT).unwrap();
    std::fs::write(&script, SOAK_HAND).unwrap();
    let (m, t, cal) = (d.join("m.csv"), d.join("t.csv"), d.join("cal.toml"));
    sim(&[
        "--unit",
        s(&unit),
        "--script",
        s(&script),
        "--record-seed",
        "3",
        "--out",
        s(&m),
        "--truth",
        s(&t),
        "--truth-calib",
        s(&cal),
    ]);
    let out = triad(&["correct", "--exact", "-q", "--calib", s(&cal), s(&m)]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let corrected = d.join("corrected.csv");
    std::fs::write(&corrected, &out.stdout).unwrap();
    let (c, truth, measured) = (rows(&corrected), rows(&t), rows(&m));
    assert_eq!(c.len(), truth.len());
    let temperatures: std::collections::BTreeSet<i64> = truth.iter().map(|r| r[7] as i64).collect();
    assert_eq!(temperatures.into_iter().collect::<Vec<_>>(), [-5, 25, 55]);
    let worst = |a: &[Vec<f64>], col: usize| {
        a.iter()
            .zip(&truth)
            .map(|(x, y)| (x[col] - y[col]).abs())
            .fold(0.0, f64::max)
    };
    for col in 1..7 {
        // The f64 correction of an exact model: rounding only (the
        // accelerations are ≈ 10 m/s², so 1e-12 is some 500 ulps).
        assert!(worst(&c, col) < 1e-12, "column {col}: {}", worst(&c, col));
        // What was corrected was wrong by far more.
        assert!(worst(&measured, col) > 1e-3, "column {col}");
    }
}

#[test]
fn what_is_asked_wrongly_is_refused_with_why() {
    let d = dir("refusals");
    let out = s(&d.join("x.csv")).to_string();
    let refused = |args: &[&str]| {
        let o = triad(&[&["sim"], args].concat());
        assert!(!o.status.success(), "{args:?}");
        text(&o.stderr)
    };
    let e = refused(&[
        "--unit",
        "tactical-mems",
        "--record-seed",
        "1",
        "--out",
        &out,
    ]);
    assert!(e.starts_with("triad: --unit needs --script: the unit is the sensor, the script what happens to it (shipped scripts: hand-rotations,"), "{e}");
    let e = refused(&[
        "--unit",
        "tactical-mems",
        "--script",
        "hand-rotations",
        "--out",
        &out,
    ]);
    assert!(e.contains("--unit needs --record-seed K"), "{e}");
    let e = refused(&["--script", "hand-rotations", "--out", &out]);
    assert!(e.contains("--script is a unit's record's option"), "{e}");
    let e = refused(&[
        "--scene",
        "static-bench",
        "--record-seed",
        "2",
        "--out",
        &out,
    ]);
    assert!(
        e.contains("--record-seed is a unit's record's option"),
        "{e}"
    );
    let e = refused(&[
        "--scene",
        "static-bench",
        "--truth-calib",
        "c.toml",
        "--out",
        &out,
    ]);
    assert!(e.contains("so it has no one true calibration"), "{e}");
    let e = refused(&[
        "--unit",
        "tactical-mems",
        "--script",
        "hand-rotations",
        "--record-seed",
        "1",
        "--seed",
        "3",
        "--out",
        &out,
    ]);
    assert!(e.contains("--seed is a scene's"), "{e}");
    let e = refused(&[
        "--unit",
        "no-such-unit",
        "--script",
        "hand-rotations",
        "--record-seed",
        "1",
        "--out",
        &out,
    ]);
    assert!(e.contains("unit `no-such-unit`: no such file, and no shipped unit of that name (shipped: consumer-mems, tactical-mems;"), "{e}");
    // A unit's key in a script, a script's in a unit, and a unit's key in a scene.
    let (unit, script, scene) = (d.join("u.toml"), d.join("s.toml"), d.join("scene.toml"));
    std::fs::write(&unit, "seed = 1\n[motion]\nkind = \"static\"\n").unwrap();
    std::fs::write(
        &script,
        "rate_hz = 10.0\n[motion]\nkind = \"static\"\n[accel]\ngrade = \"tactical\"\n",
    )
    .unwrap();
    std::fs::write(
        &scene,
        "rate_hz = 10.0\n[motion]\nkind = \"static\"\n[gyro]\nturn_on_misalignment = \"1 mrad\"\n",
    )
    .unwrap();
    let unit_and_script = || {
        refused(&[
            "--unit",
            s(&unit),
            "--script",
            s(&script),
            "--record-seed",
            "1",
            "--out",
            &out,
        ])
    };
    let e = unit_and_script();
    assert!(
        e.contains("u.toml:2:2: unknown field `motion`")
            && e.contains("that is a script's key (--script)"),
        "{e}"
    );
    std::fs::write(&unit, "seed = 1\n").unwrap();
    let e = unit_and_script();
    assert!(
        e.contains("s.toml:4:2: unknown field `accel`")
            && e.contains("the sensor's effects are the unit's (--unit UNIT.toml)"),
        "{e}"
    );
    let e = refused(&["--scene", s(&scene), "--out", &out]);
    assert!(
        e.contains("scene.toml:5:24: `turn_on_misalignment` is a unit file's key"),
        "{e}"
    );
}

#[test]
fn every_shipped_script_runs_with_every_shipped_unit() {
    let d = dir("shipped");
    for script in [
        "hand-rotations",
        "rate-table-6",
        "tumble-soak",
        "thermal-ramp-static",
        "thermal-ramp-tumble",
    ] {
        for unit in ["tactical-mems", "consumer-mems"] {
            let out = d.join(format!("{unit}-{script}.csv"));
            sim(&[
                "--unit",
                unit,
                "--script",
                script,
                "--record-seed",
                "1",
                "--seconds",
                "2",
                "--out",
                s(&out),
            ]);
            assert_eq!(rows(&out).len(), read(&out).lines().count() - 1);
            assert!(rows(&out).len() >= 40, "{script}");
        }
    }
}
