//! `cargo xtask test`: formatting and lints, every host test (the statistical
//! sweeps in release), the docs, the first-run checks (`cargo xtask run`'s
//! stdout, an installed `triad`), clippy and the build of the firmware for
//! every board × bus (and chip model), of the
//! benchmark firmware and of the user-firmware example, the end-to-end
//! tests on QEMU for every chip and bus of the emulated board, and those of
//! the device link against the emulated board served as `xtask serve` serves it.

use crate::board::{Board, Firmware, Sampling};
use crate::cmd::{self, cargo, check};
use crate::{bench, embedded_checks, first_run, hil, qemu, setup};
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::sync::OnceLock;
use std::time::Instant;

/// When the test run began: each step's note says how far in it starts, so
/// a slow step shows (the suite must stay under 15 minutes on 2 cores).
static STARTED: OnceLock<Instant> = OnceLock::new();

/// Minutes and seconds since the run began, as `[mm:ss]`.
fn at() -> String {
    let seconds = STARTED.get_or_init(Instant::now).elapsed().as_secs();
    format!("[{:02}:{:02}]", seconds / 60, seconds % 60)
}
use triad::model::Triad;

/// Frames the end-to-end run captures (the issue asks for at least 1000).
const E2E_FRAMES: u64 = 1500;
/// Samples captured from the FIFO build: 2 s at its rate.
const E2E_BATCH_SAMPLES: u64 = 16_000;
/// The FIFO build's sample rate, Hz: the ICM-42688-P's 8 kHz.
const BATCH_RATE_HZ: u32 = 8000;
/// The FIFO build's watermark: the largest the firmware offers.
const BATCH_WATERMARK: u16 = 32;
/// The high-resolution FIFO build (the ICM-42688-P's 20-bit packets): its
/// rate, its slower sensor (the accelerometer at half the rate: packets
/// with only the gyroscope's data between, checked held as in
/// [`DIFFERENT_RATES`]) and watermark. It streams a data frame per sample,
/// so a rate the link carries frame by frame.
const HIRES_RATE_HZ: u32 = 1000;
const HIRES_SLOWER: (Triad, u32) = (Triad::Accel, 500);
const HIRES_WATERMARK: u16 = 8;
/// Seconds of stream per sampling setting in the hardware-in-the-loop run.
const HIL_SECONDS: f64 = 2.0;
/// Each chip at two rates, on the emulated board: (chip, the stream's rate,
/// the slower sensor and its rate, the FIFO watermark). The slower rate
/// divides the faster, so the chip's samples come at the board's one
/// data-ready rate; the slower sensor is the accelerometer, whose
/// demo-motion reading moves (the gyro's is a constant rate: a held value
/// could not be told from a new one). The ICM-42688-P reads its data
/// registers on data ready (W = 1; its FIFO at two rates is the
/// high-resolution build's); the LSM6DSOX drains its tagged FIFO (W = 16),
/// whose words come at each sensor's own rate.
const DIFFERENT_RATES: [(&str, u32, (Triad, u32), u16); 2] = [
    ("icm42688", 1000, (Triad::Accel, 500), 1),
    ("lsm6dsox", 1666, (Triad::Accel, 833), 16),
];
/// The scene of the simulated end-to-end run, and its seed.
const E2E_SCENE: &str = "thermal-ramp";
const E2E_SEED: u64 = 7;
/// The unit and script the emulated board plays for `triad calib
/// session`'s end-to-end test, and the record's seed.
const SESSION_UNIT: &str = "consumer-mems";
const SESSION_SCRIPT: &str = "hand-session";
const SESSION_SEED: u64 = 1;

/// Which tests `cargo xtask test` runs.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Everything.
    All,
    /// The firmware builds and the end-to-end tests on QEMU.
    EndToEnd,
    /// The first-run checks of [`first_run`] alone.
    FirstRun,
    /// The end-to-end tests of each chip at two rates alone ([`DIFFERENT_RATES`]).
    DifferentRates,
    /// The end-to-end test of the high-resolution FIFO alone ([`high_resolution`]).
    HighResolution,
}

/// Runs the tests of `scope`; fails on the first failing step.
pub fn run(scope: Scope) -> Result<()> {
    STARTED.get_or_init(Instant::now);
    setup::ensure_all()?;
    if scope == Scope::FirstRun {
        return first_run::run(&cmd::build_quick_host_tool()?);
    }
    if scope == Scope::DifferentRates {
        let triad = cmd::build_quick_host_tool()?;
        return different_rates(&triad, &cmd::pack_calibration(&triad, None)?);
    }
    if scope == Scope::HighResolution {
        let triad = cmd::build_quick_host_tool()?;
        return high_resolution(&triad, &cmd::pack_calibration(&triad, None)?);
    }
    let e2e_only = scope == Scope::EndToEnd;
    if !e2e_only {
        step("cargo fmt --check", &["fmt", "--all", "--", "--check"])?;
        let clippy = ["clippy", "--all-targets", "--quiet", "--", "-D", "warnings"];
        step("cargo clippy (host)", &clippy)?;
        step("cargo test (host)", &["test", "--quiet"])?;
        // The AFL binaries link only through cargo-afl (the benchmark runs
        // them): here they are checked, and their targets run over the seeds.
        let fuzz = ["-p", "triad-fuzz", "--features", "afl", "--all-targets"];
        step(
            "cargo clippy (the fuzz targets)",
            &[&["clippy", "--quiet"][..], &fuzz, &["--", "-D", "warnings"]].concat(),
        )?;
        step(
            "cargo test (the fuzz targets over their seeds)",
            &["test", "--quiet", "-p", "triad-fuzz"],
        )?;
        recordings_peers()?;
        // Statistical sweeps are ignored in debug builds: run here optimised
        // (the `quick-release` profile: release without LTO, see Cargo.toml).
        let sweeps = [
            "test",
            "--profile",
            "quick-release",
            "--quiet",
            "-p",
            "triad-lab",
            "--test",
            "allan_coverage",
            "--test",
            "allan_strided_coverage",
            "--test",
            "rig_free",
            "--test",
            "thermal_fit",
            "--test",
            "thermal_gyro",
        ];
        step(
            "cargo test --profile quick-release (the Allan coverage sweeps, fully overlapping and strided, the rig-free, g-sensitivity and thermal fits' σ coverage over 60 seeds)",
            &sweeps,
        )?;
        note!("xtask: cargo doc (core, sim, lab) {}", at());
        embedded_checks::docs()?;
    }

    let triad = cmd::build_quick_host_tool()?;
    if !e2e_only {
        first_run::run(&triad)?;
    }
    let calibration = cmd::pack_calibration(&triad, None)?;
    let mut qemu_elves = Vec::new();
    for firmware in Firmware::all() {
        note!(
            "xtask: clippy and build of the firmware for {} {}",
            firmware.label(),
            at()
        );
        embedded_checks::clippy_firmware(firmware, &calibration, None)?;
        let elf = cmd::build_firmware(firmware, &calibration)?;
        // What `cargo xtask run --board nucleo-f401re` reads to open the port.
        let baud = crate::elf_facts::link_baud(&elf)?;
        note!("xtask: {} links at {baud} baud", firmware.label());
        if firmware.board.is_emulated() {
            qemu_elves.push((firmware, elf));
        }
    }

    note!(
        "xtask: clippy on the benchmark firmware and the user-firmware example {}",
        at()
    );
    embedded_checks::clippy_bench_firmware()?;
    embedded_checks::check_example()?;

    note!(
        "xtask: benchmark firmware on the emulated cores, outputs against the host's {}",
        at()
    );
    bench::check_firmware_outputs()?;

    for (firmware, elf) in &qemu_elves {
        end_to_end(*firmware, elf, &triad, &calibration, None)?;
    }

    // The chip's FIFO: 8 kHz, 32 samples per interrupt, batch frames.
    let batched = Firmware {
        sampling: Sampling {
            rate_hz: Some(BATCH_RATE_HZ),
            watermark: Some(BATCH_WATERMARK),
            ..Sampling::default()
        },
        ..Firmware::default_emulated()
    };
    note!(
        "xtask: clippy and build of the firmware for {}",
        batched.label()
    );
    embedded_checks::clippy_firmware(batched, &calibration, None)?;
    let elf = cmd::build_firmware(batched, &calibration)?;
    end_to_end(batched, &elf, &triad, &calibration, None)?;
    let batched_elf = elf;

    different_rates(&triad, &calibration)?;
    high_resolution(&triad, &calibration)?;

    // The chip model fed by the simulator: a scene with noise, biases,
    // scale errors and a temperature ramp, on the default chip and bus.
    let firmware = Firmware::default_emulated();
    let blob = cmd::pack_scene(&triad, E2E_SCENE, E2E_SEED)?;
    note!(
        "xtask: building the firmware for {} with scene {E2E_SCENE}",
        firmware.label()
    );
    embedded_checks::clippy_firmware(firmware, &calibration, Some(&blob))?;
    let elf = cmd::build_firmware_with_scene(firmware, &calibration, &blob)?;
    end_to_end(firmware, &elf, &triad, &calibration, Some(&blob))?;

    // The device link, on the default chip and bus built above.
    let (firmware, elf) = qemu_elves
        .iter()
        .find(|(f, _)| *f == firmware)
        .context("the default emulated firmware was built")?;
    served_board(*firmware, elf, &calibration)?;
    sensor_faults(*firmware, elf, &batched_elf)?;

    // The procedure a person runs on a board, against the emulated one.
    note!(
        "xtask: the hardware-in-the-loop procedure (`cargo xtask hil`) on the emulated board {}",
        at()
    );
    hil::run(hil::HilArgs {
        board: Board::emulated(),
        port: None,
        bus: firmware.bus,
        sensor: firmware.emulated_chip.map(str::to_string),
        sampling: vec![
            Sampling::default(),
            Sampling {
                rate_hz: Some(BATCH_RATE_HZ),
                watermark: Some(BATCH_WATERMARK),
                ..Sampling::default()
            },
        ],
        seconds: HIL_SECONDS,
        report: None,
    })?;

    // `triad calib session` on the board playing a unit turned by hand.
    let blob = cmd::pack_unit(&triad, SESSION_UNIT, SESSION_SCRIPT, SESSION_SEED)?;
    note!(
        "xtask: building the firmware for {} with unit {SESSION_UNIT} doing {SESSION_SCRIPT}",
        firmware.label()
    );
    let elf = cmd::build_firmware_with_scene(*firmware, &calibration, &blob)?;
    calib_session(*firmware, &elf, &calibration)?;
    note!("xtask: all tests passed {}", at());
    Ok(())
}

/// Each chip with its accelerometer and gyroscope at different rates
/// (docs/PROTOCOL.md §22), the stream at the faster one's: built, captured
/// and checked by host/tests/e2e_qemu.rs like the default builds.
fn different_rates(triad: &Path, calibration: &Path) -> Result<()> {
    for (chip, rate_hz, slower, watermark) in DIFFERENT_RATES {
        let firmware = Firmware {
            emulated_chip: Some(chip),
            sampling: Sampling {
                rate_hz: Some(rate_hz),
                slower: Some(slower),
                watermark: (watermark > 1).then_some(watermark),
                ..Sampling::default()
            },
            ..Firmware::default_emulated()
        };
        note!("xtask: building the firmware for {}", firmware.label());
        let elf = cmd::build_firmware(firmware, calibration)?;
        end_to_end(firmware, &elf, triad, calibration, None)?;
    }
    Ok(())
}

/// The ICM-42688-P's high-resolution FIFO (20-bit packets 4, DS-000347
/// §6.1) with the accelerometer at half the gyroscope's rate, streamed as
/// data frames: built, captured and checked by host/tests/e2e_hires_qemu.rs.
fn high_resolution(triad: &Path, calibration: &Path) -> Result<()> {
    let firmware = Firmware {
        emulated_chip: Some("icm42688"),
        sampling: Sampling {
            rate_hz: Some(HIRES_RATE_HZ),
            slower: Some(HIRES_SLOWER),
            watermark: Some(HIRES_WATERMARK),
            high_resolution: true,
        },
        ..Firmware::default_emulated()
    };
    note!("xtask: building the firmware for {}", firmware.label());
    embedded_checks::clippy_firmware(firmware, calibration, None)?;
    let elf = cmd::build_firmware(firmware, calibration)?;
    end_to_end(firmware, &elf, triad, calibration, None)
}

/// Captures `E2E_FRAMES` frames of `elf` on QEMU and runs host/tests/e2e_qemu.rs
/// on them, telling it which chip and bus the firmware read (it rebuilds the same).
fn end_to_end(
    firmware: Firmware,
    elf: &Path,
    triad: &Path,
    calibration: &Path,
    scene: Option<&Path>,
) -> Result<()> {
    let label = match scene {
        Some(_) => format!("{} with scene {E2E_SCENE}", firmware.label()),
        None => firmware.label(),
    };
    note!("xtask: end-to-end on QEMU, {label} {}", at());
    let dir = cmd::root().join("target/e2e").join(format!(
        "{}{}",
        firmware.stem(),
        if scene.is_some() { "-scene" } else { "" }
    ));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let (raw, csv) = (dir.join("stream.bin"), dir.join("decoded.csv"));
    let sink = qemu::Sink::Files {
        raw: raw.clone(),
        csv: csv.clone(),
    };
    // A FIFO build streams batch frames (E2E_BATCH_SAMPLES samples, rows of
    // the CSV), checked by their own test file; a high-resolution one data
    // frames, checked by its own.
    let batched = firmware.sampling.watermark.unwrap_or(1) > 1;
    let (rows, test) = match (firmware.sampling.high_resolution, batched) {
        (true, _) => (E2E_FRAMES, "e2e_hires_qemu"),
        (false, true) => (E2E_BATCH_SAMPLES, "e2e_batch_qemu"),
        (false, false) => (E2E_FRAMES, "e2e_qemu"),
    };
    let status = qemu::stream_to_decoder(elf, triad, qemu::Stop::Frames(rows), sink)?;
    if !status.success() {
        bail!("triad decode of the QEMU stream of {label} exited with {status}");
    }
    let mut command = ignored_host_tests(test, &["--nocapture"]);
    command
        .env("TRIAD_E2E_STREAM", &raw)
        .env("TRIAD_E2E_CSV", &csv)
        .env("TRIAD_E2E_BLOB", calibration)
        .env(
            "TRIAD_E2E_CALIBRATION",
            cmd::root().join("calibrations/default.toml"),
        )
        .env("TRIAD_E2E_FRAMES", rows.to_string())
        .envs(firmware.build_env())
        .env("TRIAD_E2E_BUS", firmware.bus.name());
    if let Some(blob) = scene {
        command.env("TRIAD_E2E_SCENE", blob);
    }
    check(
        command,
        &format!("the end-to-end tests on QEMU for {label}"),
    )
}

/// Runs host/tests/device_qemu.rs: `elf` served by `xtask serve` (a copy of
/// this executable, as cargo may rebuild xtask's own while the tests run),
/// driven by `triad device`; `calibration` is the blob the firmware embeds.
/// One test at a time: each QEMU keeps a core busy.
fn served_board(firmware: Firmware, elf: &Path, calibration: &Path) -> Result<()> {
    note!(
        "xtask: end-to-end on QEMU, the device link of {} served: upload, save and restart, \
         erase, bad uploads, raw mode, commands while streaming, power cuts during a save, \
         serve's standard streams, a client written from docs/PROTOCOL.md alone, a stream \
         recorded as MCAP read back by Python's mcap",
        firmware.label()
    );
    let xtask = cmd::serving_xtask()?;
    crate::setup::ensure_python()?;
    // A stream recorded as MCAP is read back by Python's mcap.
    let peers = setup::python_peers::ensure()?;
    let mut command = ignored_host_tests("device_qemu", &["--test-threads=1", "--nocapture"]);
    command
        .env("TRIAD_SERVE_XTASK", &xtask)
        .env("TRIAD_PEERS_PYTHON", peers)
        .env("TRIAD_SERVE_ELF", elf)
        .env("TRIAD_SERVE_BLOB", calibration)
        .envs(firmware.build_env())
        .env("TRIAD_E2E_BUS", firmware.bus.name());
    check(
        command,
        &format!(
            "the device link's end-to-end tests for {}",
            firmware.label()
        ),
    )
}

/// Runs host/tests/faults_qemu.rs: `elf` served by `xtask serve --fault`
/// showing each sensor fault (one firmware build serves every schedule),
/// and `fifo_elf` (the chip's FIFO on) an impossible FIFO count.
/// One test at a time: each QEMU keeps a core busy.
fn sensor_faults(firmware: Firmware, elf: &Path, fifo_elf: &Path) -> Result<()> {
    note!(
        "xtask: end-to-end on QEMU, sensor faults on {}: a chip that vanishes, browns out or \
         stops, a data-ready line held high or silent, NACK storms, an impossible FIFO count, \
         a chip absent at start or coming late",
        firmware.label()
    );
    let mut command = ignored_host_tests("faults_qemu", &["--test-threads=1", "--nocapture"]);
    command
        .env("TRIAD_SERVE_XTASK", cmd::serving_xtask()?)
        .env("TRIAD_SERVE_ELF", elf)
        .env("TRIAD_FAULTS_FIFO_ELF", fifo_elf);
    check(
        command,
        &format!(
            "the sensor faults' end-to-end tests for {}",
            firmware.label()
        ),
    )
}

/// Runs host/tests/calib_session_qemu.rs: `elf` (the firmware whose chip
/// model plays SESSION_UNIT doing SESSION_SCRIPT) served by `xtask serve`,
/// calibrated by `triad calib session`.
fn calib_session(firmware: Firmware, elf: &Path, calibration: &Path) -> Result<()> {
    note!(
        "xtask: end-to-end on QEMU, triad calib session on {} playing {SESSION_UNIT} doing {SESSION_SCRIPT}: \
         a declined session, then fit, upload, save and verify against the unit's truth",
        firmware.label()
    );
    let mut command =
        ignored_host_tests("calib_session_qemu", &["--test-threads=1", "--nocapture"]);
    command
        .env("TRIAD_SERVE_XTASK", cmd::serving_xtask()?)
        .env("TRIAD_SERVE_ELF", elf)
        .env("TRIAD_SERVE_BLOB", calibration)
        .env("TRIAD_SESSION_UNIT", SESSION_UNIT)
        .env("TRIAD_SESSION_SCRIPT", SESSION_SCRIPT)
        .env("TRIAD_SESSION_SEED", SESSION_SEED.to_string());
    check(
        command,
        &format!(
            "triad calib session's end-to-end test on {}",
            firmware.label()
        ),
    )
}

/// `cargo test` of the host's integration test `name`, its ignored tests
/// only (they need what xtask prepares), `harness` passed to the test harness.
fn ignored_host_tests(name: &str, harness: &[&str]) -> std::process::Command {
    let mut command = cargo();
    command
        .args(["test", "--quiet", "-p", "triad-host", "--test", name])
        .args(["--", "--ignored"])
        .args(harness);
    command
}

/// host/tests/recordings_peers.rs: bags written by Python's rosbags, an
/// MCAP of triad's read by Python's mcap-ros2-support, a ULog as pyulog
/// reads it; the Python peers installed first ([`setup::python_peers`]).
fn recordings_peers() -> Result<()> {
    let python = setup::python_peers::ensure()?;
    note!(
        "xtask: recordings against the Python peers (rosbags, pyulog, mcap) {}",
        at()
    );
    let mut command = ignored_host_tests("recordings_peers", &[]);
    command.env("TRIAD_PEERS_PYTHON", python);
    check(command, "the recordings tests against the Python peers")
}

fn step(what: &str, args: &[&str]) -> Result<()> {
    note!("xtask: {what} {}", at());
    let mut command = cargo();
    command.args(args);
    check(command, what)
}
