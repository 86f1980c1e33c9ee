//! The board the procedure runs on, and what only it can do: load a
//! firmware, reset, and say which port its link is on. A hardware board is
//! flashed and reset with probe-rs and talks on the port the person names;
//! the emulated board is `xtask serve --deterministic` on a storage file
//! that stands in for its flash, and a reset is a restart of QEMU on the
//! same file (flash survives a reset; RAM does not).

use crate::cmd;
use anyhow::{bail, Context, Result};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// How long the emulated board may take to print its port.
const SERVE_START: Duration = Duration::from_secs(60);

/// How long a hardware board takes from reset to answering (its start-up
/// reads the chip and the flash): the procedure waits this long after a
/// flash or reset.
const HARDWARE_START: Duration = Duration::from_millis(1500);

/// A board under test.
pub enum DeviceUnderTest {
    /// A board on the bench: its serial port.
    Hardware {
        /// The port the person named (e.g. /dev/ttyACM0).
        port: String,
        /// The board's microcontroller, as probe-rs names it.
        chip: &'static str,
    },
    /// The emulated board.
    Emulated {
        /// Its flash (a file).
        storage: PathBuf,
        /// xtask serve's log (and the firmware's defmt log), appended.
        log: PathBuf,
        /// The running `xtask serve`, and its port.
        served: Option<(Child, String)>,
    },
}

impl DeviceUnderTest {
    /// The emulated board with a fresh, erased flash in `dir`.
    pub fn emulated(dir: &Path) -> Result<DeviceUnderTest> {
        let storage = dir.join("flash.bin");
        let _ = std::fs::remove_file(&storage);
        Ok(DeviceUnderTest::Emulated {
            storage,
            log: dir.join("board.log"),
            served: None,
        })
    }

    /// Whether a flash erase or write stalls the board's CPU: on the
    /// NUCLEO-F401RE (the hardware board) one flash bank holds the program
    /// and the calibration; the emulated board's flash is a host file.
    pub fn flash_stalls_the_cpu(&self) -> bool {
        matches!(self, DeviceUnderTest::Hardware { .. })
    }

    /// What the report calls it.
    pub fn describe(&self) -> String {
        match self {
            DeviceUnderTest::Hardware { port, chip } => {
                format!("hardware ({chip}) on {port}, flashed with probe-rs")
            }
            DeviceUnderTest::Emulated { storage, .. } => format!(
                "the emulated board (`xtask serve --deterministic`), its flash the file {}",
                storage.display()
            ),
        }
    }

    /// Loads `elf` and starts it; returns the port to talk to.
    pub fn load(&mut self, elf: &Path) -> Result<String> {
        match self {
            DeviceUnderTest::Hardware { port, chip } => {
                probe_rs(&["download", "--chip", chip], Some(elf))?;
                probe_rs(&["reset", "--chip", chip], None)?;
                std::thread::sleep(HARDWARE_START);
                Ok(port.clone())
            }
            DeviceUnderTest::Emulated {
                storage,
                log,
                served,
            } => {
                stop(served);
                let (child, port) = serve(elf, storage, log)?;
                *served = Some((child, port.clone()));
                Ok(port)
            }
        }
    }

    /// What a reset is on this board, for the report.
    pub fn reset_means(&self) -> String {
        match self {
            DeviceUnderTest::Hardware { chip, .. } => {
                format!("reset: `probe-rs reset --chip {chip}` (flash kept)")
            }
            DeviceUnderTest::Emulated { .. } => {
                "reset: QEMU restarted on the same flash file (RAM lost, flash kept)".into()
            }
        }
    }

    /// Resets the running firmware `elf` (RAM lost, flash kept); returns the port.
    pub fn reset(&mut self, elf: &Path) -> Result<String> {
        match self {
            DeviceUnderTest::Hardware { port, chip } => {
                probe_rs(&["reset", "--chip", chip], None)?;
                std::thread::sleep(HARDWARE_START);
                Ok(port.clone())
            }
            DeviceUnderTest::Emulated { .. } => self.load(elf),
        }
    }
}

impl Drop for DeviceUnderTest {
    fn drop(&mut self) {
        if let DeviceUnderTest::Emulated { served, .. } = self {
            stop(served);
        }
    }
}

/// Stops a served board (xtask serve; QEMU dies with it).
fn stop(served: &mut Option<(Child, String)>) {
    if let Some((mut child, _)) = served.take() {
        let _ = child.kill();
        let _ = child.wait();
    }
}

/// `xtask serve --elf ELF --storage FILE --deterministic`, from a copy of
/// this executable (cargo may rebuild xtask's own meanwhile); its stderr
/// appended to `log`; returns it with the port it printed.
fn serve(elf: &Path, storage: &Path, log: &Path) -> Result<(Child, String)> {
    let log_file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(log)
        .with_context(|| format!("opening {}", log.display()))?;
    let mut child = Command::new(cmd::serving_xtask()?)
        .arg("serve")
        .arg("--elf")
        .arg(elf)
        .arg("--storage")
        .arg(storage)
        .arg("--deterministic")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(log_file)
        .spawn()
        .context("starting xtask serve")?;
    let stdout = child.stdout.take().context("xtask serve's stdout")?;
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = send.send(line);
    });
    match receive.recv_timeout(SERVE_START) {
        Ok(line) if !line.trim().is_empty() => Ok((child, line.trim().to_string())),
        _ => {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "xtask serve printed no port within {} s; its log: {}",
                SERVE_START.as_secs(),
                log.display()
            )
        }
    }
}

/// `probe-rs ARGS [ELF]`, which must succeed.
fn probe_rs(args: &[&str], elf: Option<&Path>) -> Result<()> {
    if !cmd::runs("probe-rs") {
        bail!(
            "probe-rs not found: install it with `cargo install probe-rs-tools --locked` \
             and connect the board's ST-LINK"
        );
    }
    let mut command = Command::new("probe-rs");
    command.args(args);
    if let Some(elf) = elf {
        command.arg(elf);
    }
    cmd::check(command, &format!("probe-rs {}", args.join(" ")))
}
