//! `triad allan` end to end: the table's columns and values, the JSON report,
//! the SVG plot, the every-τ mode, and one-line errors for bad input.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::{allan, tmp};

fn triad() -> Command {
    Command::new(common::TRIAD)
}

/// A simulated static tactical IMU (`static-bench`), `seconds` at 10 Hz;
/// made once (tests run in parallel: the lock keeps a reader from a file
/// still being written).
fn simulated(name: &str, seconds: &str) -> PathBuf {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let out = tmp(name);
    if !out.exists() {
        let ok = triad()
            .args([
                "sim",
                "--scene",
                "static-bench",
                "--rate",
                "10",
                "--seconds",
                seconds,
            ])
            .args(["--seed", "2", "--out"])
            .arg(&out)
            .status()
            .unwrap()
            .success();
        assert!(ok);
    }
    out
}

/// The column `name` of a CSV file.
fn column(path: &PathBuf, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
        .collect()
}

/// The overlapping Allan deviation at m, written out from the definition
/// (averages of m samples, differences of averages m apart), independent of
/// the cumulative-sum code under test.
fn oadev_by_definition(y: &[f64], m: usize) -> f64 {
    let avg = |j: usize| y[j..j + m].iter().sum::<f64>() / m as f64;
    let n = y.len() - 2 * m + 1;
    let s: f64 = (0..n).map(|j| (avg(j + m) - avg(j)).powi(2)).sum();
    (s / (2.0 * n as f64)).sqrt()
}

struct Row {
    column: String,
    tau: f64,
    oadev: f64,
    lo: f64,
    hi: f64,
    m: u64,
}

fn table(path: &PathBuf) -> (String, Vec<Row>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            Row {
                column: c[0].to_string(),
                tau: c[1].parse().unwrap(),
                oadev: c[2].parse().unwrap(),
                lo: c[3].parse().unwrap(),
                hi: c[4].parse().unwrap(),
                m: c[5].parse().unwrap(),
            }
        })
        .collect();
    (header, rows)
}

#[test]
fn table_has_the_documented_columns_and_the_definition_values() {
    let input = simulated("bench-2000.csv", "2000");
    let out = tmp("table.csv");
    let o = allan(
        &input,
        &["--columns", "gx,az", "--out", out.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (header, rows) = table(&out);
    assert!(
        header.starts_with("column,tau,oadev,ci_low,ci_high"),
        "{header}"
    );
    // 20 000 samples: octaves m = 1 … 8192 (2m ≤ N) for each of the two columns.
    assert_eq!(rows.len(), 2 * 14);
    for name in ["gx", "az"] {
        let y = column(&input, name);
        let mine: Vec<&Row> = rows.iter().filter(|r| r.column == name).collect();
        for (k, r) in mine.iter().enumerate() {
            assert_eq!(r.m, 1 << k);
            assert!((r.tau - r.m as f64 / 10.0).abs() < 1e-12, "tau = m/rate");
            assert!(r.lo < r.oadev && r.oadev < r.hi, "{name} m={}", r.m);
        }
        // The definition, summed naively in f64: agreement to 1e-9 relative
        // (az holds 1 g, so the naive averages lose ≈ 1e-12 of the 9.8 m/s²
        // mean, ≈ 1e-10 of its noise; gx has no such mean).
        for r in mine.iter().take(4) {
            let d = oadev_by_definition(&y, r.m as usize);
            assert!(
                (r.oadev - d).abs() <= 1e-9 * d,
                "{name} m={}: {} vs {d}",
                r.m,
                r.oadev
            );
        }
    }
}

#[test]
fn json_reports_terms_in_datasheet_units_and_the_grade() {
    let input = simulated("bench-20000.csv", "20000");
    let o = allan(&input, &["--json", "--columns", "gx,ax"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["samples"], 200_000);
    assert!((v["rate_hz"].as_f64().unwrap() - 10.0).abs() < 1e-9);
    let cols = v["columns"].as_array().unwrap();
    assert_eq!(cols.len(), 2);
    let gx = &cols[0];
    assert_eq!(gx["column"], "gx");
    assert_eq!(gx["terms"]["N"]["unit"], "deg/sqrt(h)");
    assert_eq!(gx["terms"]["B"]["unit"], "deg/h");
    assert_eq!(gx["terms"]["K"]["unit"], "deg/h/sqrt(h)");
    // static-bench gyros are the tactical preset: ARW 0.15 °/√h, B 1 °/h.
    // Tolerance: 3σ of the reported uncertainty (as in tests/allan_recovery.rs).
    let n = gx["terms"]["N"]["value"].as_f64().unwrap();
    let n_sigma = gx["terms"]["N"]["sigma"].as_f64().unwrap();
    assert!((n - 0.15).abs() <= 3.0 * n_sigma, "N {n} ± {n_sigma}");
    assert_eq!(gx["grade"]["grade"], "tactical");
    let ax = &cols[1];
    assert_eq!(ax["terms"]["N"]["unit"], "ug/sqrt(Hz)");
    assert_eq!(ax["terms"]["B"]["unit"], "ug");
    assert_eq!(ax["terms"]["N_vrw"]["unit"], "m/s/sqrt(h)");
    let n = ax["terms"]["N"]["value"].as_f64().unwrap();
    let vrw = ax["terms"]["N_vrw"]["value"].as_f64().unwrap();
    // 1 µg/√Hz = 9.80665e-6 (m/s²)/√Hz = 5.88399e-4 (m/s)/√h.
    assert!((vrw - n * 9.806_65e-6 * 60.0).abs() < 1e-9 * vrw);
    assert_eq!(ax["grade"]["grade"], "tactical");
    assert!(gx["grade"]["decided_by"].as_str().is_some());
}

#[test]
fn summary_names_terms_and_grade() {
    let input = simulated("bench-2000.csv", "2000");
    let o = allan(&input, &["--columns", "gy"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    for needle in [
        "gy (gyro",
        "white noise",
        "bias instability",
        "deg/sqrt(h)",
        "grade:",
    ] {
        assert!(s.contains(needle), "{needle} in {s}");
    }
}

/// A minimal XML well-formedness check: every tag closes in order,
/// attributes are quoted, the root is `svg` in the SVG namespace.
fn assert_well_formed_svg(text: &str) {
    assert!(text.trim_start().starts_with("<svg"), "root element");
    assert!(text.contains(r#"xmlns="http://www.w3.org/2000/svg""#));
    let mut stack: Vec<String> = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unclosed tag") + start;
        let tag = &rest[start + 1..end];
        assert!(!tag.contains('<'), "'<' inside tag {tag}");
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name.trim()), "closing {name}");
        } else {
            let name: String = tag
                .chars()
                .take_while(|c| !c.is_whitespace() && *c != '/')
                .collect();
            assert_eq!(tag.matches('"').count() % 2, 0, "quotes in {tag}");
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        rest = &rest[end + 1..];
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    // Every '&' starts an entity.
    for (i, _) in text.match_indices('&') {
        let entity = &text[i..text[i..].find(';').map_or(text.len(), |j| i + j + 1)];
        assert!(
            ["&amp;", "&lt;", "&gt;", "&quot;"].contains(&entity),
            "bare & at {i}"
        );
    }
}

#[test]
fn plot_is_a_well_formed_svg_with_bars_and_term_lines() {
    let input = simulated("bench-2000.csv", "2000");
    let plot = tmp("allan.svg");
    let o = allan(
        &input,
        &["--columns", "gx,gy", "--plot", plot.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert_well_formed_svg(&svg);
    // One circle per point plus one legend marker per column, dashed term lines, labels.
    assert_eq!(svg.matches("<circle").count(), 2 * 14 + 2);
    assert!(svg.contains("stroke-dasharray"));
    assert!(svg.contains("N = ") && svg.contains("deg/sqrt(h)"));
}

#[test]
fn every_tau_mode_has_every_m_and_agrees_with_the_octaves() {
    let input = simulated("bench-200.csv", "200");
    let (all, oct) = (tmp("all.csv"), tmp("oct.csv"));
    let o = allan(
        &input,
        &[
            "--columns",
            "gz",
            "--all-tau",
            "--out",
            all.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = allan(&input, &["--columns", "gz", "--out", oct.to_str().unwrap()]);
    assert!(o.status.success());
    let (_, every) = table(&all);
    let (_, octave) = table(&oct);
    // 2000 samples: m = 1 … 1000.
    assert_eq!(every.len(), 1000);
    assert!(every.iter().enumerate().all(|(i, r)| r.m == i as u64 + 1));
    for r in &octave {
        let e = &every[r.m as usize - 1];
        assert!((e.oadev - r.oadev).abs() <= 1e-12 * r.oadev, "m={}", r.m);
    }
}

#[test]
fn rate_option_overrides_the_t_column() {
    let input = simulated("bench-200.csv", "200");
    let out = tmp("rate.csv");
    let o = allan(
        &input,
        &[
            "--columns",
            "gx",
            "--rate",
            "20",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success());
    let (_, rows) = table(&out);
    assert!((rows[0].tau - 0.05).abs() < 1e-15);
}

fn fails_with(input_text: &str, name: &str, args: &[&str], expected: &[&str]) {
    let path = tmp(name);
    std::fs::write(&path, input_text).unwrap();
    let o = allan(&path, args);
    assert!(!o.status.success(), "{name} should fail");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for e in expected {
        assert!(err.contains(e), "stderr {err:?} should contain {e:?}");
    }
}

fn rows(n: usize, f: impl Fn(usize) -> String) -> String {
    let mut s = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..n {
        s.push_str(&f(i));
        s.push('\n');
    }
    s
}

fn good_row(i: usize) -> String {
    let t = i as f64 * 0.01;
    let v = ((i * 7919) % 13) as f64 * 1e-3;
    format!("{t},{v},{v},9.8,{v},{v},{v},25")
}

#[test]
fn unknown_column_is_named() {
    fails_with(
        &rows(20, good_row),
        "unknown.csv",
        &["--columns", "gx,gq"],
        &["unknown column \"gq\"", "t,ax,ay"],
    );
}

#[test]
fn non_numeric_cell_names_its_line_and_column() {
    let text = rows(20, |i| {
        if i == 9 {
            "0.09,0,0,9.8,abc,0,0,25".into()
        } else {
            good_row(i)
        }
    });
    // Header is line 1, so row 9 is line 11.
    fails_with(
        &text,
        "nan.csv",
        &[],
        &["line 11", "column gx", "\"abc\"", "not a finite number"],
    );
    let text = rows(20, |i| {
        if i == 4 {
            "0.04,0,0,9.8,NaN,0,0,25".into()
        } else {
            good_row(i)
        }
    });
    fails_with(
        &text,
        "nan2.csv",
        &["--columns", "gx"],
        &["line 6", "\"NaN\""],
    );
}

#[test]
fn too_few_samples_is_an_error() {
    fails_with(
        &rows(5, good_row),
        "short.csv",
        &[],
        &["too few samples", "5 rows", "at least 8"],
    );
}

#[test]
fn non_positive_rate_is_an_error() {
    fails_with(
        &rows(20, good_row),
        "rate0.csv",
        &["--rate", "0"],
        &["--rate 0", "positive"],
    );
    fails_with(
        &rows(20, good_row),
        "rate-.csv",
        &["--rate=-5"],
        &["--rate -5", "positive"],
    );
    let text = rows(20, |i| {
        good_row(i).replacen(&format!("{}", i as f64 * 0.01), "1", 1)
    });
    fails_with(&text, "flat-t.csv", &[], &["line 3", "t must increase"]);
}

#[test]
fn non_uniform_t_is_an_error() {
    // A gap: row 12 is missing.
    let text = rows(30, |i| good_row(if i >= 12 { i + 1 } else { i }));
    fails_with(
        &text,
        "gap.csv",
        &[],
        &["line 14", "non-uniform t", "0.13", "0.11"],
    );
}

#[test]
fn missing_t_without_rate_is_an_error() {
    let text = "gx,gy\n".to_string() + &"0.1,0.2\n".repeat(20);
    fails_with(&text, "no-t.csv", &[], &["no t column", "--rate"]);
    let path = tmp("no-t-ok.csv");
    std::fs::write(
        &path,
        "gx,gy\n".to_string()
            + &(0..20)
                .map(|i| format!("{},{}\n", i % 3, i % 5))
                .collect::<String>(),
    )
    .unwrap();
    assert!(allan(&path, &["--rate", "100"]).status.success());
}

#[test]
fn missing_file_is_an_error() {
    let o = triad()
        .args(["allan", "/nonexistent/x.csv"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/x.csv"));
}

#[test]
fn errors_past_the_first_block_keep_their_line_numbers() {
    // The first 4096 rows are read before the parsing thread starts; later
    // errors travel through it and must still name their line.
    let text = rows(6000, |i| {
        if i == 5000 {
            "50,0,0,9.8,1e-3,zz,0,25".into()
        } else {
            good_row(i)
        }
    });
    fails_with(
        &text,
        "late.csv",
        &[],
        &["line 5002", "column gy", "\"zz\""],
    );
    let text = rows(6000, |i| good_row(if i >= 4500 { i + 3 } else { i }));
    fails_with(&text, "late-gap.csv", &[], &["line 4502", "non-uniform t"]);
}

#[test]
fn max_tau_bounds_the_grid() {
    let input = simulated("bench-2000.csv", "2000");
    let out = tmp("maxtau.csv");
    let o = allan(
        &input,
        &[
            "--columns",
            "gx",
            "--max-tau",
            "10",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (_, rows) = table(&out);
    // 10 s at 10 Hz: m ≤ 100, so octaves 1 … 64.
    assert_eq!(rows.last().map(|r| r.m), Some(64));
    fails_with(
        &rows_text(),
        "maxtau-bad.csv",
        &["--max-tau", "-1"],
        &["--max-tau -1", "positive"],
    );
}

fn rows_text() -> String {
    rows(20, good_row)
}
