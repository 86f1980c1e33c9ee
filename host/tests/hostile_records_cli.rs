//! Records as loggers and hands make them, each fitted by `triad calib fit
//! imu` or refused with a message naming the time and what to do: held
//! stretches between poses, a record whose noise is under one LSB, stamps
//! that repeat at a coarse clock, a gap, a shake after the last pose beyond
//! the gyro's range, and stamps that cannot time the record at all.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use common::{dir, hand_unit as unit, s, text, triad};
use triad_lab::calib_fit::hand_record::{self, Axes, Sample, Script, Unit};
use triad_sim::effects::rng::Rng;

/// 16 poses of 4 s with 1.5 s turns at `rate_hz`.
fn samples(rate_hz: f64, unit: &Unit, seed: u64) -> Vec<Sample> {
    let script = Script {
        rate_hz,
        poses: 16,
        static_s: 4.0,
        turn_s: 1.5,
        angle_deg: (60.0, 150.0),
        axes: Axes::Any,
        drift: None,
    };
    let mut rng = Rng::from_seed(seed);
    let mut out = Vec::new();
    hand_record::generate(&script, unit, &mut || rng.uniform(), |s| out.push(s));
    out
}

/// Writes `samples` as CSV (t formatted by `stamp`).
fn write(d: &Path, name: &str, samples: &[Sample], stamp: impl Fn(f64) -> String) -> PathBuf {
    let mut csv = String::from("t,ax,ay,az,gx,gy,gz\n");
    for s in samples {
        let [ax, ay, az] = s.accel;
        let [gx, gy, gz] = s.gyro;
        writeln!(csv, "{},{ax},{ay},{az},{gx},{gy},{gz}", stamp(s.t)).unwrap();
    }
    let path = d.join(format!("{name}.csv"));
    std::fs::write(&path, csv).unwrap();
    path
}

/// `triad calib fit imu --positions INPUT EXTRA… --out CAL`: success, report, stderr.
fn fit(d: &Path, input: &Path, extra: &[&str]) -> (bool, String, String) {
    let cal = d.join("cal.toml");
    let mut args = vec!["calib", "fit", "imu", "--positions", s(input)];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--out", s(&cal)]);
    let o = triad(&args);
    (o.status.success(), text(&o.stdout), text(&o.stderr))
}

/// The number of static poses the report says were fitted.
fn poses(report: &str) -> usize {
    report
        .split_once("rig-free fit of ")
        .and_then(|(_, r)| r.split_once(": "))
        .and_then(|(_, r)| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{report}"))
}

/// The sample indices of the turns (between the 4 s poses) at `rate` Hz.
fn turn(k: usize, rate: f64) -> std::ops::Range<usize> {
    let pose = (4.0 * rate) as usize;
    let turn = (1.5 * rate) as usize;
    let start = (k + 1) * pose + k * turn;
    start..start + turn
}

#[test]
fn held_stretches_in_turns_make_no_poses_and_their_moves_are_left_out() {
    let d = dir("held");
    let mut rec = samples(100.0, &unit(), 3);
    // In three turns a logger repeats one sample for 0.6 s (lost frames).
    for k in [2, 6, 10] {
        let r = turn(k, 100.0);
        let held = rec[r.start + 40];
        for s in &mut rec[r.start + 40..r.start + 100] {
            s.accel = held.accel;
            s.gyro = held.gyro;
        }
    }
    let input = write(&d, "held", &rec, |t| format!("{t}"));
    let (ok, report, err) = fit(&d, &input, &[]);
    assert!(ok, "{err}");
    assert_eq!(poses(&report), 16, "{report}");
    assert_eq!(
        report
            .matches("the gyro repeats one value for 60 samples")
            .count(),
        3,
        "{report}"
    );
    assert!(
        report.contains("move from pose 3 to pose 4 (t = "),
        "{report}"
    );
}

#[test]
fn a_record_whose_noise_is_under_one_lsb_still_has_its_poses() {
    let d = dir("quantised");
    let mut u = unit();
    u.accel.noise = 0.002;
    u.gyro.noise = 2e-4;
    // LSBs four times the noise: most still samples repeat one count.
    let (accel_lsb, gyro_lsb) = (0.008, 8e-4);
    let rec: Vec<Sample> = samples(100.0, &u, 4)
        .into_iter()
        .map(|s| Sample {
            accel: s.accel.map(|x| (x / accel_lsb).round() * accel_lsb),
            gyro: s.gyro.map(|x| (x / gyro_lsb).round() * gyro_lsb),
            ..s
        })
        .collect();
    let input = write(&d, "coarse", &rec, |t| format!("{t}"));
    let (ok, report, err) = fit(&d, &input, &[]);
    assert!(ok, "{err}");
    assert_eq!(poses(&report), 16, "{report}");
}

#[test]
fn stamps_at_a_clock_coarser_than_the_sample_period_are_repaired_and_said() {
    let d = dir("stamps");
    let rec = samples(200.0, &unit(), 5);
    // 200 Hz stamped at 10 ms (Unix time): pairs of samples share a stamp.
    let input = write(&d, "coarse_clock", &rec, |t| {
        format!("{:.2}", 1672887159.71 + (t / 0.01).floor() * 0.01)
    });
    let (ok, report, err) = fit(&d, &input, &[]);
    assert!(ok, "{err}");
    assert!(report.contains("time stamps repaired"), "{report}");
    assert!(report.contains("repeated"), "{report}");
    assert_eq!(poses(&report), 16, "{report}");
}

#[test]
fn a_gap_splits_the_record_and_the_move_across_it_is_left_out() {
    let d = dir("gap");
    let mut rec = samples(100.0, &unit(), 6);
    // The logger lost the whole 8th turn (and 0.2 s either side).
    let lost = turn(7, 100.0);
    rec.drain(lost.start - 20..lost.end + 20);
    let input = write(&d, "gap", &rec, |t| format!("{t}"));
    let (ok, report, err) = fit(&d, &input, &[]);
    assert!(ok, "{err}");
    assert!(report.contains("2 part(s) split at gaps"), "{report}");
    assert!(
        report.contains("move from pose 8 to pose 9 (t = ")
            && report.contains("left out: it crosses a gap in the time stamps"),
        "{report}"
    );
    assert_eq!(poses(&report), 16, "{report}");
}

#[test]
fn a_shake_after_the_last_pose_beyond_the_range_is_ignored_and_reported() {
    let d = dir("shake");
    let mut rec = samples(100.0, &unit(), 7);
    let last = rec.last().unwrap().t;
    // 2 s of shaking at up to 298 °/s on a ±300 °/s gyro.
    for k in 1..=200 {
        let t = last + k as f64 * 0.01;
        let w = 298f64.to_radians() * (k as f64 * 0.7).sin();
        rec.push(Sample {
            t,
            accel: [3.0 * (k as f64).sin(), 9.0, 2.0 * (k as f64).cos()],
            gyro: [w, -0.5 * w, 0.3 * w],
        });
    }
    let input = write(&d, "shake", &rec, |t| format!("{t}"));
    let (ok, report, err) = fit(&d, &input, &["--gyro-range-dps", "300"]);
    assert!(ok, "{err}");
    assert!(
        report.contains(
            "beyond 90 % of the gyro's full scale lie outside the poses and moves the fit uses"
        ) && report.contains("ignored"),
        "{report}"
    );
}

#[test]
fn a_record_whose_stamps_cannot_time_it_is_refused_saying_to_pass_the_rate() {
    let d = dir("untimed");
    let rec = samples(100.0, &unit(), 8);
    let input = write(&d, "frozen_clock", &rec, |_| "12.5".to_string());
    let (ok, _, err) = fit(&d, &input, &[]);
    assert!(!ok);
    assert!(
        err.contains("time stamps do not advance (first 12.5, last 12.5)")
            && err.contains("pass --rate HZ"),
        "{err}"
    );
    // Given the rate, the same record fits.
    let (ok, report, err) = fit(&d, &input, &["--rate", "100"]);
    assert!(ok, "{err}");
    assert!(
        report.contains("timed by --rate: 100.000000 Hz"),
        "{report}"
    );
}
