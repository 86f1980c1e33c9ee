//! What a new user does first, checked as they would do it (issue 16):
//! `cargo xtask run > samples.csv` gives a file that is CSV and nothing else,
//! and `cargo install --path host` gives a `triad` that runs a shipped scene
//! from a directory outside the checkout.

use crate::cmd::{self, check};
use anyhow::{bail, ensure, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The CSV header of `triad decode` (docs/PROTOCOL.md, README).
const DECODED_HEADER: &str = "seq,t,ax,ay,az,gx,gy,gz,temp,flags";

/// Both checks; each prints how long it took.
pub fn run(triad: &Path) -> Result<()> {
    timed(
        "cargo xtask run: stdout is the CSV alone",
        xtask_run_prints_only_csv,
    )?;
    timed(
        "cargo xtask run in other people's processes: streams on /dev/null, full, closed, abandoned",
        xtask_run_with_other_peoples_streams,
    )?;
    timed(
        "cargo install --path host: triad runs a shipped scene outside the checkout",
        || installed_triad_runs_anywhere(triad),
    )
}

fn timed(what: &str, job: impl FnOnce() -> Result<()>) -> Result<()> {
    note!("xtask: {what}");
    let start = Instant::now();
    job()?;
    note!("xtask: {what}: {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
}

/// `cargo xtask run --seconds 0.5` (this very xtask) with its stdout kept:
/// the decoder's header, then rows of ten numbers, and not one other line.
fn xtask_run_prints_only_csv() -> Result<()> {
    // Through cargo, as the README runs it: this xtask's own executable may
    // have been rebuilt (replaced on disk) by the test steps before this one.
    let output = cmd::cargo()
        .args(["xtask", "run", "--seconds", "0.5"])
        .stdin(Stdio::null())
        .stderr(Stdio::inherit())
        .output()
        .context("starting cargo xtask run")?;
    ensure!(
        output.status.success(),
        "cargo xtask run --seconds 0.5 exited with {}",
        output.status
    );
    let stdout =
        String::from_utf8(output.stdout).context("cargo xtask run's stdout is not UTF-8")?;
    let mut lines = stdout.lines();
    let header = lines.next().unwrap_or_default();
    ensure!(
        header == DECODED_HEADER,
        "cargo xtask run's stdout begins with {header:?}, not the CSV header {DECODED_HEADER:?}"
    );
    let mut rows = 0;
    for (n, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        let numeric = fields.iter().all(|f| f.parse::<f64>().is_ok());
        ensure!(
            fields.len() == 10 && numeric,
            "cargo xtask run's stdout line {}: {line:?} is not a CSV row of ten numbers",
            n + 2
        );
        rows += 1;
    }
    ensure!(rows > 0, "cargo xtask run printed the header and no rows");
    Ok(())
}

/// `cargo xtask run --seconds SECONDS` through `sh -c` with `redirect`
/// (e.g. `2>&-`), stdin on a read-write /dev/null.
fn xtask_run(seconds: &str, redirect: &str) -> Command {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut command = Command::new("sh");
    command
        .current_dir(cmd::root())
        .arg("-c")
        .arg(format!(
            "exec \"$0\" xtask run --seconds {seconds} {redirect}"
        ))
        .arg(cargo)
        .stdin(dev_null_read_write());
    command
}

/// /dev/null opened read-write: what Python's `subprocess.DEVNULL`, nohup
/// and service managers give a process.
fn dev_null_read_write() -> std::fs::File {
    std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open("/dev/null")
        .expect("/dev/null")
}

/// `cargo xtask run` as a script, a service manager or a pipeline runs it:
/// every stream on a read-write /dev/null runs; a stderr full or whose
/// reader left costs only the notes (the CSV is whole); a full stdout
/// is an error naming it (`triad decode`'s); a reader of stdout that leaves
/// ends the run quietly with 141, as `seq | head -1` does.
fn xtask_run_with_other_peoples_streams() -> Result<()> {
    let status = xtask_run("0.2", "")
        .stdout(dev_null_read_write())
        .stderr(dev_null_read_write())
        .status()
        .context("starting cargo xtask run")?;
    ensure!(status.success(), "every stream on /dev/null: {status}");

    let csv_whole = |what: &str, output: std::process::Output| -> Result<()> {
        let stdout = String::from_utf8_lossy(&output.stdout);
        ensure!(
            output.status.success() && stdout.starts_with(DECODED_HEADER),
            "{what}: {} with {} bytes of CSV",
            output.status,
            stdout.len()
        );
        let rows = stdout.lines().count() - 1;
        ensure!(rows >= 200, "{what}: {rows} rows for 0.2 s at 1 kHz");
        Ok(())
    };
    let full = || std::fs::File::create("/dev/full").expect("/dev/full");
    let to_full = xtask_run("0.2", "").stderr(full()).output()?;
    csv_whole("2> /dev/full", to_full)?;
    // A closed stderr (`2>&-`) reaches xtask as the read-write /dev/null
    // of the first run: cargo's runtime reopens a closed descriptor so.
    let mut abandoned = xtask_run("0.2", "")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    drop(abandoned.stderr.take());
    csv_whole("2> a pipe whose reader left", abandoned.wait_with_output()?)?;

    let out = xtask_run("0.2", "")
        .stdout(full())
        .stderr(Stdio::piped())
        .output()?;
    let said = String::from_utf8_lossy(&out.stderr);
    ensure!(
        out.status.code() == Some(1) && said.contains("No space left on device"),
        "> /dev/full: {} and {said}",
        out.status
    );

    // Five seconds of rows: far more than a pipe holds, so the run is
    // still writing when the reader leaves after the header.
    let mut reader_leaves = xtask_run("5", "")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    let stdout = reader_leaves.stdout.take().context("stdout")?;
    let mut header = String::new();
    std::io::BufRead::read_line(&mut std::io::BufReader::new(stdout), &mut header)?;
    ensure!(header.trim_end() == DECODED_HEADER, "| head -1: {header:?}");
    let out = reader_leaves.wait_with_output()?;
    let said = String::from_utf8_lossy(&out.stderr);
    ensure!(
        out.status.code() == Some(141) && !said.contains("exited with"),
        "| head -1: {} and {said}",
        out.status
    );
    Ok(())
}

/// `cargo install --locked --path host --root TMP` (into the host target
/// directory, so the release build is reused), then the installed `triad`,
/// in an empty directory outside the checkout, packs the scene
/// `static-bench` (saying where it took it from: `shipped:static-bench`, the
/// copy built in, not a file) and simulates it: its samples must be exactly
/// those of the checkout's scenes/static-bench.toml.
fn installed_triad_runs_anywhere(triad: &Path) -> Result<()> {
    let scratch = std::env::temp_dir().join(format!("triad-first-run-{}", std::process::id()));
    let result = install_and_simulate(triad, &scratch);
    let _ = std::fs::remove_dir_all(&scratch);
    result
}

fn install_and_simulate(triad: &Path, scratch: &Path) -> Result<()> {
    let (root, elsewhere) = (scratch.join("root"), scratch.join("elsewhere"));
    std::fs::create_dir_all(&elsewhere)
        .with_context(|| format!("creating {}", elsewhere.display()))?;
    // The quick-release profile: the build of the tool xtask drives is
    // reused (what is checked, the scenes built into the binary, does not
    // depend on the profile; release would build it all again with fat LTO).
    let mut install = cmd::cargo();
    install
        .args(["install", "--quiet", "--locked", "--path", "host"])
        .args(["--profile", "quick-release", "--root"])
        .arg(&root)
        .arg("--target-dir")
        .arg(cmd::host_target_dir());
    check(install, "cargo install --path host")?;
    let installed = root.join("bin/triad");

    let packed = Command::new(&installed)
        .current_dir(&elsewhere)
        .args([
            "sim",
            "--scene",
            "static-bench",
            "--pack",
            "static-bench.bin",
        ])
        .output()
        .context("starting the installed triad")?;
    let said = String::from_utf8_lossy(&packed.stderr);
    ensure!(
        packed.status.success() && said.contains("scene shipped:static-bench at"),
        "the installed triad did not take static-bench from its built-in scenes: {said}"
    );

    let simulate = |triad: &Path, scene: &str, out: &PathBuf| -> Result<Vec<u8>> {
        let mut command = Command::new(triad);
        command
            .current_dir(&elsewhere)
            .args([
                "sim",
                "--scene",
                scene,
                "--seconds",
                "2",
                "--seed",
                "3",
                "--out",
            ])
            .arg(out);
        check(command, &format!("{} sim --scene {scene}", triad.display()))?;
        std::fs::read(out).with_context(|| format!("reading {}", out.display()))
    };
    let shipped = simulate(&installed, "static-bench", &elsewhere.join("shipped.csv"))?;
    let file = cmd::root().join("scenes/static-bench.toml");
    let from_file = simulate(
        triad,
        file.to_str().context("the checkout's path is not UTF-8")?,
        &elsewhere.join("file.csv"),
    )?;
    if shipped != from_file || shipped.iter().filter(|&&b| b == b'\n').count() < 2 {
        bail!(
            "the installed triad's static-bench ({} bytes) is not the checkout's \
             scenes/static-bench.toml ({} bytes) simulated alike",
            shipped.len(),
            from_file.len()
        );
    }
    Ok(())
}
