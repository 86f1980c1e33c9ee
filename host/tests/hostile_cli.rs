//! The `triad` command under hostile conditions, run as a user would: a
//! reader that closes the pipe, stdout on a full device or closed, outputs
//! over inputs, failing runs beside good files, unbounded work, odd input.
//! Each case checks the exit status, what is said, and what is on disk.

mod common;

use std::fs;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::Mutex;

use common::{calibration, dir, s, text, TRIAD};
use triad_host::fixtures::{entries, stream};

/// What `main` returns when the reader of stdout went away (128 + SIGPIPE).
const READER_GONE: i32 = 141;

/// Spawning is serialised in this file: a child forked by another test's
/// thread would inherit a copy of a pipe's read end until it execs, and a
/// reader that "left" would still be there for a small write.
static SPAWN: Mutex<()> = Mutex::new(());

fn spawn(cmd: &mut Command) -> Child {
    let _one_at_a_time = SPAWN.lock().unwrap_or_else(|e| e.into_inner());
    cmd.spawn().unwrap()
}

/// `cmd.output()`, spawned under [`SPAWN`].
fn output(cmd: &mut Command) -> Output {
    spawn(
        cmd.stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
    )
    .wait_with_output()
    .unwrap()
}

/// `triad ARGS` run to its end, spawned under [`SPAWN`].
fn triad(args: &[&str]) -> Output {
    output(Command::new(TRIAD).args(args))
}

/// Runs with `stdin` fed and stdout a pipe whose reader is gone before the
/// command writes (as `| head -0` would; `| head -1` is tested on a long
/// stream below). The command waits behind a shell's `read` for a line that
/// is sent once the reader is gone: else a small output could fit in the
/// pipe, and the command exit, before the reader leaves.
fn reader_gone(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = {
        let _one_at_a_time = SPAWN.lock().unwrap_or_else(|e| e.into_inner());
        let mut child = Command::new("sh")
            .arg("-c")
            .arg("read -r go && exec \"$0\" \"$@\"")
            .arg(TRIAD)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Gone before any other process is forked with a copy of it.
        drop(child.stdout.take());
        child
    };
    let mut input = child.stdin.take().unwrap();
    input.write_all(b"go\n").unwrap();
    // A command that does not read stdin closes it: not the test's failure.
    let _ = input.write_all(stdin);
    drop(input);
    child.wait_with_output().unwrap()
}

/// Runs with stdout on /dev/full (every write: ENOSPC).
fn to_dev_full(args: &[&str], stdin: &[u8]) -> Output {
    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let mut child = spawn(
        Command::new(TRIAD)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(full)
            .stderr(Stdio::piped()),
    );
    let mut input = child.stdin.take().unwrap();
    let _ = input.write_all(stdin);
    drop(input);
    child.wait_with_output().unwrap()
}

/// Runs with stdout closed (`>&-`).
fn stdout_closed(args: &[&str]) -> Output {
    output(
        Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" >&-")
            .arg(TRIAD)
            .args(args),
    )
}

/// `triad sim` of a shipped scene into `out`.
fn simulate(scene: &str, seconds: &str, out: &Path) {
    let run = triad(&[
        "sim",
        "--scene",
        scene,
        "--seconds",
        seconds,
        "--out",
        s(out),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
}

fn no_panic(out: &Output, what: &str) {
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
}

/// The inputs of the stdout cases: a static and a tumble record, a stream.
struct Inputs {
    d: PathBuf,
    still: PathBuf,
    tumble: PathBuf,
    frames: PathBuf,
}

fn inputs(name: &str) -> Inputs {
    let d = dir(name);
    let still = d.join("still.csv");
    let tumble = d.join("tumble.csv");
    simulate("static-bench", "20", &still);
    simulate("tumble-6", "120", &tumble);
    let frames = d.join("frames.bin");
    fs::write(&frames, stream(50)).unwrap();
    Inputs {
        d,
        still,
        tumble,
        frames,
    }
}

/// Every command that prints, with the file it writes (if any).
fn printing_commands(i: &Inputs) -> Vec<(Vec<String>, Option<PathBuf>)> {
    let owned = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let pq = i.d.join("pq.toml");
    let bias = i.d.join("bias.toml");
    let table = i.d.join("table.csv");
    let default = calibration("default.toml");
    vec![
        (
            owned(&[
                "calib",
                "fit",
                "accel",
                "--axis-aligned",
                "--positions",
                s(&i.tumble),
                "--out",
                s(&pq),
            ]),
            Some(pq.clone()),
        ),
        (
            owned(&[
                "calib",
                "fit",
                "gyro",
                "--static",
                s(&i.still),
                "--out",
                s(&bias),
            ]),
            Some(bias.clone()),
        ),
        (owned(&["calib", "check", s(&default)]), None),
        (
            owned(&["correct", "--calib", s(&default), s(&i.still)]),
            None,
        ),
        (owned(&["decode", s(&i.frames)]), None),
        (
            owned(&["allan", s(&i.still), "--out", s(&table)]),
            Some(table.clone()),
        ),
        (
            owned(&[
                "sim",
                "--scene",
                "static-bench",
                "--seconds",
                "1",
                "--out",
                "-",
            ]),
            None,
        ),
        (owned(&["completions", "bash"]), None),
        (owned(&["man"]), None),
    ]
}

#[test]
fn a_reader_that_leaves_ends_every_command_quietly_and_keeps_its_files() {
    let i = inputs("reader-gone");
    for (args, file) in printing_commands(&i) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        if let Some(f) = &file {
            let _ = fs::remove_file(f);
        }
        let out = reader_gone(&args, b"");
        let what = args.join(" ");
        no_panic(&out, &what);
        assert_eq!(
            out.status.code(),
            Some(READER_GONE),
            "{what}: {}",
            text(&out.stderr)
        );
        if args[0] != "decode" {
            // decode's summary is its normal stderr; the others say nothing.
            assert!(out.stderr.is_empty(), "{what}: {}", text(&out.stderr));
        }
        if let Some(f) = file {
            // Written whole before anything was printed.
            assert!(f.exists(), "{what}: {} lost", f.display());
            if f.extension().is_some_and(|e| e == "toml") {
                let check = triad(&["calib", "check", s(&f)]);
                assert!(check.status.success(), "{what}: {}", text(&check.stderr));
            }
        }
    }
}

#[test]
fn a_full_stdout_is_an_error_naming_standard_output() {
    let i = inputs("dev-full");
    for (args, file) in printing_commands(&i) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = to_dev_full(&args, b"");
        let what = args.join(" ");
        let stderr = text(&out.stderr);
        no_panic(&out, &what);
        assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
        assert!(
            stderr.contains("standard output: No space left on device"),
            "{what}: {stderr}"
        );
        if let Some(f) = file {
            assert!(f.exists(), "{what}: the file is written before the report");
        }
    }
    // decode counts the rows the output took: none.
    let out = to_dev_full(&["decode", s(&i.frames)], b"");
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("frames: 50 (0 stored as CSV rows)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("stopped at an output error (No space left on device"),
        "{stderr}"
    );
}

#[test]
fn a_closed_stdout_is_refused_before_any_work() {
    let d = dir("closed");
    let still = d.join("still.csv");
    simulate("static-bench", "5", &still);
    let bias = d.join("bias.toml");
    for args in [
        vec![
            "correct",
            "--calib",
            s(&calibration("default.toml")),
            s(&still),
        ],
        vec![
            "calib",
            "fit",
            "gyro",
            "--static",
            s(&still),
            "--out",
            s(&bias),
        ],
        vec!["calib", "check", s(&calibration("default.toml"))],
    ] {
        let out = stdout_closed(&args);
        let stderr = text(&out.stderr);
        no_panic(&out, &args.join(" "));
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("standard output was closed when triad started"),
            "{stderr}"
        );
    }
    assert!(!bias.exists(), "nothing done");
}

/// /dev/null opened read-write: what Python's `subprocess.DEVNULL`, nohup
/// and service managers give a process, and what Rust's runtime puts on a
/// closed descriptor (so only the state before the runtime tells them apart).
fn dev_null_read_write() -> fs::File {
    fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open("/dev/null")
        .unwrap()
}

#[test]
fn every_standard_stream_on_a_read_write_dev_null_is_legitimate() {
    let i = inputs("dev-null-rw");
    for (args, file) in printing_commands(&i) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let what = args.join(" ");
        if let Some(f) = &file {
            let _ = fs::remove_file(f);
        }
        // stdout alone on /dev/null (stderr kept to read), then all three.
        let out = spawn(
            Command::new(TRIAD)
                .args(&args)
                .stdin(dev_null_read_write())
                .stdout(dev_null_read_write())
                .stderr(Stdio::piped()),
        )
        .wait_with_output()
        .unwrap();
        no_panic(&out, &what);
        assert!(out.status.success(), "{what}: {}", text(&out.stderr));
        let status = spawn(
            Command::new(TRIAD)
                .args(&args)
                .stdin(dev_null_read_write())
                .stdout(dev_null_read_write())
                .stderr(dev_null_read_write()),
        )
        .wait()
        .unwrap();
        assert!(status.success(), "{what} with every stream on /dev/null");
        if let Some(f) = file {
            assert!(f.exists(), "{what}: {} not written", f.display());
        }
    }
}

/// Runs `triad ARGS` with stderr on `stderr` (stdout piped and read).
fn with_stderr(args: &[&str], stderr: impl Into<Stdio>) -> Output {
    spawn(
        Command::new(TRIAD)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(stderr),
    )
    .wait_with_output()
    .unwrap()
}

#[test]
fn a_closed_full_or_abandoned_stderr_loses_only_the_notes() {
    let i = inputs("stderr");
    let table = i.d.join("table.csv");
    let args = ["allan", s(&i.still), "--out", s(&table)];
    let closed = output(
        Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" 2>&-")
            .arg(TRIAD)
            .args(args),
    );
    let full = with_stderr(&args, fs::File::create("/dev/full").unwrap());
    let abandoned = {
        let mut child = spawn(
            Command::new(TRIAD)
                .args(args)
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped()),
        );
        drop(child.stderr.take());
        child.wait_with_output().unwrap()
    };
    for (what, out) in [
        ("2>&-", closed),
        ("2>/dev/full", full),
        ("2>|gone", abandoned),
    ] {
        assert!(out.status.success(), "{what}: {:?}", out.status);
        assert!(!out.stdout.is_empty(), "{what}: the report is on stdout");
    }
    // An error still sets the status when its message has nowhere to go.
    let missing = i.d.join("missing.csv");
    let failed = with_stderr(
        &["allan", s(&missing)],
        fs::File::create("/dev/full").unwrap(),
    );
    assert_eq!(failed.status.code(), Some(1));
}

#[test]
fn correct_piped_to_head_stops_quietly() {
    let d = dir("head");
    let still = d.join("still.csv");
    // 40 000 rows: far more than a pipe holds, so triad is still writing
    // when the reader leaves after one line.
    simulate("static-bench", "200", &still);
    let mut child = Command::new(TRIAD);
    child
        .args([
            "correct",
            "--calib",
            s(&calibration("default.toml")),
            s(&still),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = spawn(&mut child);
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "t,ax,ay,az,gx,gy,gz,temp\n");
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(READER_GONE),
        "{}",
        text(&out.stderr)
    );
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
}

#[test]
fn a_failed_run_leaves_an_existing_output_untouched() {
    let d = dir("untouched");
    let keep = d.join("keep.csv");
    let keep_toml = d.join("keep.toml");
    let keep_bin = d.join("keep.bin");
    for f in [&keep, &keep_toml, &keep_bin] {
        fs::write(f, "precious").unwrap();
    }
    let table = d.join("table.csv");
    simulate("rate-table", "10", &table);
    let bad = d.join("bad.csv");
    fs::write(&bad, "t,gx\n0,1\n0.01,x\n").unwrap();
    let singular = calibration("bad/singular.toml");
    let cases: Vec<Vec<&str>> = vec![
        // The second output cannot be written: neither is.
        vec![
            "sim",
            "--scene",
            "static-bench",
            "--seconds",
            "1",
            "--out",
            s(&keep),
            "--truth",
            "nodir/t.csv",
        ],
        // A record that turned is refused after the output was checked.
        vec![
            "calib",
            "fit",
            "gyro",
            "--static",
            s(&table),
            "--out",
            s(&keep_toml),
        ],
        vec!["allan", s(&bad), "--out", s(&keep)],
        vec!["calib", "pack", s(&singular), "-o", s(&keep_bin)],
    ];
    for args in cases {
        let out = triad(&args);
        no_panic(&out, &args.join(" "));
        assert_eq!(out.status.code(), Some(1), "{args:?} succeeded");
        for f in [&keep, &keep_toml, &keep_bin] {
            assert_eq!(fs::read_to_string(f).unwrap(), "precious", "{args:?}");
        }
    }
    assert_eq!(
        entries(&d),
        ["bad.csv", "keep.bin", "keep.csv", "keep.toml", "table.csv"],
        "no temporary file left"
    );
}

#[test]
fn an_output_over_an_input_or_another_output_is_refused_naming_both() {
    let d = dir("same-path");
    let x = d.join("x.csv");
    simulate("static-bench", "2", &x);
    let scene = d.join("s.toml");
    fs::write(
        &scene,
        "rate_hz = 100.0\nduration_s = 1.0\n[motion]\nkind = \"static\"\n",
    )
    .unwrap();
    let cal = d.join("c.toml");
    fs::copy(calibration("default.toml"), &cal).unwrap();
    let plot = d.join("f.svg");
    let t = d.join("t.csv");
    let other_x = d.join(".").join("x.csv");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["allan", s(&x), "--out", s(&other_x)],
            format!(
                "--out {} is the same file as the input {}",
                s(&other_x),
                s(&x)
            ),
        ),
        (
            vec!["allan", s(&x), "--out", s(&plot), "--plot", s(&plot)],
            format!("--out {0} and --plot {0} are the same file", s(&plot)),
        ),
        (
            vec![
                "calib",
                "fit",
                "accel",
                "--positions",
                s(&x),
                "--out",
                s(&x),
            ],
            format!("--out {0} is the same file as the --positions {0}", s(&x)),
        ),
        (
            vec![
                "calib",
                "fit",
                "gyro",
                "--static",
                s(&x),
                "--base",
                s(&cal),
                "--out",
                s(&cal),
            ],
            format!("--out {0} is the same file as the --base {0}", s(&cal)),
        ),
        (
            vec!["calib", "pack", s(&cal), "-o", s(&cal)],
            format!("--output {0} is the same file as the file {0}", s(&cal)),
        ),
        (
            vec!["sim", "--scene", s(&scene), "--out", s(&scene)],
            format!("--out {0} is the same file as the --scene {0}", s(&scene)),
        ),
        (
            vec![
                "sim",
                "--scene",
                s(&scene),
                "--out",
                s(&t),
                "--truth",
                s(&t),
            ],
            format!("--out {0} and --truth {0} are the same file", s(&t)),
        ),
    ];
    let before: Vec<Vec<u8>> = [&x, &scene, &cal]
        .iter()
        .map(|p| fs::read(p).unwrap())
        .collect();
    for (args, message) in cases {
        let out = triad(&args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains(&message),
            "{args:?}: expected `{message}` in {stderr}"
        );
    }
    let after: Vec<Vec<u8>> = [&x, &scene, &cal]
        .iter()
        .map(|p| fs::read(p).unwrap())
        .collect();
    assert!(before == after, "an input changed");
    assert!(!t.exists() && !plot.exists());
}

#[test]
fn sim_refuses_unbounded_work_naming_the_limit_and_the_value() {
    let err = |args: &[&str]| {
        let out = triad(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        text(&out.stderr)
    };
    let e = err(&[
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        "1e12",
        "--out",
        "/dev/null",
    ]);
    assert!(
        e.contains("--seconds 1000000000000 at 100 Hz is 100000000000000 samples, above the limit of 100000000"),
        "{e}"
    );
    let e = err(&[
        "sim",
        "--scene",
        "static-bench",
        "--rate",
        "1e12",
        "--out",
        "/dev/null",
    ]);
    assert!(
        e.contains(
            // The shipped scene (built into triad) is named `shipped:static-bench`.
            "static-bench duration_s 3600 at 1000000000000 Hz is 3600000000000000 samples"
        ),
        "{e}"
    );
    assert!(
        e.contains("above the limit of 100000000 (--max-samples N raises it"),
        "{e}"
    );
    // Readable, not 301 digits.
    let e = err(&[
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        "1e300",
        "--out",
        "/dev/null",
    ]);
    assert!(
        e.contains("--seconds 1e300 at 100 Hz is 1e302 samples"),
        "{e}"
    );
    assert!(e.len() < 300, "{e}");
    // The limit is the option's: 20 samples pass at 20, not at 19.
    let args = [
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        "0.2",
        "--out",
        "/dev/null",
        "--max-samples",
    ];
    assert!(triad(&[&args[..], &["20"]].concat()).status.success());
    let e = err(&[&args[..], &["19"]].concat());
    assert!(e.contains("is 20 samples, above the limit of 19"), "{e}");
}

#[test]
fn an_option_value_is_blamed_on_the_option() {
    let default = calibration("default.toml");
    for (args, message) in [
        (
            vec!["calib", "check", s(&default), "--accel-range-g", "-16"],
            "triad: --accel-range-g -16: the full scale must be a positive number of g\n",
        ),
        (
            vec!["calib", "check", s(&default), "--gyro-range-dps", "0"],
            "triad: --gyro-range-dps 0: the full scale must be a positive number of °/s\n",
        ),
        (
            vec![
                "sim",
                "--scene",
                "static-bench",
                "--seconds",
                "-1",
                "--out",
                "/dev/null",
            ],
            "triad: --seconds -1: must be a non-negative number\n",
        ),
        (
            vec![
                "sim",
                "--scene",
                "static-bench",
                "--rate",
                "-1e300",
                "--out",
                "/dev/null",
            ],
            "triad: --rate -1e300: the sample rate must be a positive number of Hz\n",
        ),
    ] {
        let out = triad(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert_eq!(text(&out.stderr), message, "{args:?}");
    }
    // A negative latitude is a latitude (not an unknown option).
    let d = dir("options");
    let still = d.join("still.csv");
    simulate("static-bench", "5", &still);
    let out = triad(&[
        "calib",
        "fit",
        "gyro",
        "--static",
        s(&still),
        "--latitude",
        "-33.9",
        "--out",
        s(&d.join("b.toml")),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn dash_is_standard_input_and_standard_output() {
    let d = dir("dash");
    // sim → stdout; allan and calib fit read it from stdin.
    let out = triad(&[
        "sim",
        "--scene",
        "static-bench",
        "--seconds",
        "20",
        "--out",
        "-",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(out.stdout.starts_with(b"t,ax,ay,az,gx,gy,gz,temp\n"));
    assert!(!Path::new("-").exists(), "no file named -");
    let record = out.stdout;
    let piped = |args: &[&str]| {
        let mut child = spawn(
            Command::new(TRIAD)
                .args(args)
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped()),
        );
        child.stdin.take().unwrap().write_all(&record).unwrap();
        child.wait_with_output().unwrap()
    };
    let allan = piped(&["allan", "-", "--columns", "gx"]);
    assert!(allan.status.success(), "{}", text(&allan.stderr));
    assert!(
        text(&allan.stdout).starts_with("stdin: 2000 samples"),
        "{}",
        text(&allan.stdout)
    );
    // The calibration to stdout, the report to stderr.
    let fit = piped(&["calib", "fit", "gyro", "--static", "-", "--out", "-"]);
    assert!(fit.status.success(), "{}", text(&fit.stderr));
    assert!(
        text(&fit.stdout).contains("[gyro]"),
        "{}",
        text(&fit.stdout)
    );
    assert!(text(&fit.stderr).starts_with("gyro static bias: 2000 samples of stdin"));
    // The blob to stdout equals the blob to a file.
    let blob = d.join("c.bin");
    let default = calibration("default.toml");
    assert!(triad(&["calib", "pack", s(&default), "-o", s(&blob)])
        .status
        .success());
    let to_stdout = triad(&["calib", "pack", s(&default), "-o", "-"]);
    assert_eq!(to_stdout.stdout, fs::read(&blob).unwrap());
    // Two outputs cannot both be stdout.
    let both = triad(&[
        "sim",
        "--scene",
        "static-bench",
        "--out",
        "-",
        "--truth",
        "-",
    ]);
    assert!(text(&both.stderr)
        .contains("--out - and --truth -: only one output can go to standard output"));
}

#[test]
fn a_byte_order_mark_before_the_header_is_accepted() {
    let d = dir("bom");
    let still = d.join("still.csv");
    simulate("static-bench", "5", &still);
    let mut bytes = "\u{feff}".as_bytes().to_vec();
    bytes.extend(fs::read(&still).unwrap());
    let bom = d.join("bom.csv");
    fs::write(&bom, bytes).unwrap();
    for args in [
        vec!["allan", s(&bom), "--columns", "gz"],
        vec![
            "correct",
            "--calib",
            s(&calibration("default.toml")),
            s(&bom),
        ],
        vec![
            "calib",
            "fit",
            "gyro",
            "--static",
            s(&bom),
            "--out",
            s(&d.join("b.toml")),
        ],
    ] {
        let out = triad(&args);
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    }
}

#[test]
fn correct_reads_what_decode_writes() {
    let d = dir("decode-correct");
    let frames = d.join("frames.bin");
    fs::write(&frames, stream(5)).unwrap();
    let decoded = triad(&["decode", s(&frames)]);
    assert!(decoded.status.success(), "{}", text(&decoded.stderr));
    let csv = d.join("decoded.csv");
    fs::write(&csv, &decoded.stdout).unwrap();
    let out = triad(&[
        "correct",
        "--calib",
        s(&calibration("default.toml")),
        s(&csv),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let lines: Vec<String> = text(&out.stdout).lines().map(String::from).collect();
    assert_eq!(lines.len(), 6);
    assert_eq!(lines[0], "seq,t,ax,ay,az,gx,gy,gz,temp,flags");
    // seq, t, temp and flags copied as written; the values corrected.
    assert!(lines[3].starts_with("2,1.020000,"), "{}", lines[3]);
    assert!(lines[3].ends_with(",25.5,0"), "{}", lines[3]);
    assert_ne!(lines[3], text(&decoded.stdout).lines().nth(3).unwrap());
}

#[test]
fn decode_of_junk_fails_saying_no_frame_decoded() {
    let d = dir("junk");
    let junk = d.join("junk.bin");
    fs::write(
        &junk,
        (0..5000u32)
            .map(|i| (i * 7 % 251) as u8)
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let out = triad(&["decode", s(&junk)]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("frames: 0 (0 stored as CSV rows)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("triad: no frame decoded from 5000 bytes: not a triad stream"),
        "{stderr}"
    );
}

#[test]
fn gyro_static_refuses_a_record_that_turned_with_the_figure() {
    let d = dir("static-test");
    let table = d.join("table.csv");
    let tumble = d.join("tumble.csv");
    simulate("rate-table", "10", &table);
    simulate("tumble-6", "120", &tumble);
    let out_path = d.join("b.toml");
    let fit = |record: &Path, extra: &[&str]| {
        triad(
            &[
                &[
                    "calib",
                    "fit",
                    "gyro",
                    "--static",
                    s(record),
                    "--out",
                    s(&out_path),
                ],
                extra,
            ]
            .concat(),
        )
    };
    let out = fit(&table, &[]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("the mean rate about z is 30.0")
            && stderr.contains("above --max-bias 10 °/s"),
        "{stderr}"
    );
    // A tumble is static poses with turns between them: each pose is
    // checked still, and the bias (and G where the faces support it) comes
    // from the poses.
    let out = fit(&tumble, &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("gyro at rest in 5 static poses"),
        "{}",
        text(&out.stdout)
    );
    std::fs::remove_file(&out_path).unwrap();
    // The same tumble turning at 2 °/s about x for 5 s within its third
    // pose (48.5..67.5 s), where the accelerometer does not see it:
    // refused, naming the pose and its time.
    let turned = d.join("turned.csv");
    let text_in = std::fs::read_to_string(&tumble).unwrap();
    let mut lines = text_in.lines();
    let mut csv = format!("{}\n", lines.next().unwrap());
    for line in lines {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        let t: f64 = fields[0].parse().unwrap();
        if (50.0..55.0).contains(&t) {
            let gx: f64 = fields[4].parse().unwrap();
            fields[4] = (gx + 2f64.to_radians()).to_string();
        }
        csv.push_str(&fields.join(","));
        csv.push('\n');
    }
    std::fs::write(&turned, csv).unwrap();
    let out = fit(&turned, &[]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(
            "turned.csv pose 3 (t = 48.50..67.49 s) is not static: the mean rate about x"
        ),
        "{stderr}"
    );
    assert!(!out_path.exists());
    // The steady 30 °/s passes the steadiness test: only --max-bias holds it.
    let out = fit(&table, &["--max-bias", "40"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn progress_lines_show_off_a_terminal_and_quiet_silences_them() {
    let d = dir("progress");
    let out_path = d.join("s.csv");
    let run = |quiet: bool| {
        let mut cmd = Command::new(TRIAD);
        cmd.args([
            "sim",
            "--scene",
            "static-bench",
            "--seconds",
            "2000",
            "--out",
            s(&out_path),
        ]);
        if quiet {
            cmd.arg("--quiet");
        }
        // A line at every update (every 65 536 samples) instead of every 3 s.
        output(cmd.env("TRIAD_PROGRESS_SECONDS", "0"))
    };
    let out = run(false);
    assert!(out.status.success());
    let stderr = text(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    // 200 000 samples: updates at 65 536, 131 072 and 196 608, then the end.
    assert_eq!(lines.len(), 4, "{stderr}");
    assert!(
        lines[0].starts_with("triad: 65536/200000 samples (32.8 %), ")
            && lines[0].ends_with(" s left"),
        "{stderr}"
    );
    assert!(lines[3].starts_with("triad: done in "), "{stderr}");
    let quiet = run(true);
    assert!(quiet.status.success());
    assert!(quiet.stderr.is_empty(), "{}", text(&quiet.stderr));
}

#[test]
fn huge_values_in_messages_are_readable() {
    let d = dir("readable");
    let big = d.join("big.toml");
    let default = fs::read_to_string(calibration("default.toml")).unwrap();
    let edited = default.replace("bias = [0.05, -0.02, 0.10]", "bias = [1e308, 0, 0]");
    assert_ne!(edited, default);
    fs::write(&big, edited).unwrap();
    let out = triad(&["calib", "check", s(&big)]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("accel bias[0] = 1e308: beyond the sensor's full scale ±156.9064"),
        "{stderr}"
    );
    assert!(stderr.len() < 200, "{stderr}");
}
