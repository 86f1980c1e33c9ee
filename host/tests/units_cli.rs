//! `triad units` as a user runs it: every equivalent of a value, one value
//! for scripts (`--to`), and a clear refusal for what cannot be converted.

use std::process::{Command, Output};

fn triad(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_triad"))
        .arg("units")
        .args(args)
        .output()
        .expect("triad runs")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_value_is_printed_in_every_unit_of_its_quantity_with_kalibrs_name() {
    let out = triad(&["0.15", "deg/sqrt(h)"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.starts_with("0.15 °/√h is gyro white noise: angle random walk"),
        "{text}"
    );
    assert!(text.contains("  0.0025 °/s/√Hz\n"), "{text}");
    assert!(
        text.contains("  0.0000436332313 rad/s/√Hz   (Kalibr gyroscope_noise_density)\n"),
        "{text}"
    );
    assert!(text.contains("  9 °/h/√Hz\n"), "{text}");
}

#[test]
fn to_prints_one_number_and_bandwidth_gives_the_resolution() {
    let out = triad(&["1", "g/√Hz", "--to", "m/s/sqrt(h)"]);
    assert_eq!(stdout(&out), "588.399\n");
    let out = triad(&["10", "°/h", "--to", "rad/s"]);
    assert_eq!(stdout(&out), "0.0000484813681\n");
    let out = triad(&["100", "ug/sqrt(Hz)", "--bandwidth", "100"]);
    assert!(
        stdout(&out).contains("resolution over 100 Hz: 0.00980665 m/s² rms = 1 mg"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn what_cannot_be_converted_is_refused_with_the_reason() {
    for (args, message) in [
        (&["3", "furlongs"][..], "unknown unit \"furlongs\""),
        (
            &["3", "deg/h", "--to", "ug"],
            "--to µg: µg measures an acceleration",
        ),
        (
            &["3", "deg/h", "--to", "parsecs"],
            "--to \"parsecs\": unknown unit",
        ),
        (
            &["3", "deg/h", "--bandwidth", "10"],
            "°/h is not a noise density",
        ),
        (
            &["3", "ug/sqrt(Hz)", "--bandwidth", "0"],
            "--bandwidth 0: must be a positive number of Hz",
        ),
        (&["NaN", "deg/h"], "the value must be a finite number"),
    ] {
        let out = triad(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        assert!(stderr(&out).contains(message), "{args:?}: {}", stderr(&out));
    }
}
