//! The emulated board: QEMU's netduinoplus2 running the firmware, its USART2
//! stream piped into `triad decode`, its defmt log (semihosting, on QEMU's
//! stdout) decoded onto stderr.
//!
//! `-icount shift=0,sleep=off`: each instruction advances virtual time by 1 ns
//! and idle time is skipped, so runs are deterministic and faster than real
//! time (DESIGN.md, "The emulated board").

use crate::qemu_link::{Fifos, Link};
use crate::{defmt_log, setup};
use anyhow::{bail, Context, Result};
use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, ExitStatus, Stdio};

/// Where the decoded CSV goes.
pub enum Sink {
    /// To this process's stdout.
    Inherit,
    /// The raw stream bytes and the decoded CSV into files (end-to-end tests).
    Files {
        /// The bytes as they left USART2.
        raw: PathBuf,
        /// What `triad decode` printed.
        csv: PathBuf,
    },
}
pub use Sink::Inherit;

/// When `triad decode` stops reading the stream.
#[derive(Clone, Copy, Debug)]
pub enum Stop {
    /// After this many good frames.
    Frames(u64),
    /// After this many seconds of stream time, by the frames' own timestamps
    /// (so nothing here needs to know the sample rate or the decimation).
    Seconds(f64),
}

impl Stop {
    /// `triad decode`'s option for it.
    pub fn decode_args(self) -> [String; 2] {
        match self {
            Stop::Frames(n) => ["--max-frames".into(), n.to_string()],
            Stop::Seconds(s) => ["--seconds".into(), s.to_string()],
        }
    }
}

/// How QEMU's virtual time runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// `-icount shift=0,sleep=off`: one instruction per virtual nanosecond,
    /// idle time skipped: deterministic, for tests and `run`.
    Deterministic,
    /// No `-icount`: virtual time is the host's clock, so the board samples
    /// in real time (`serve`, which a person or a host tool talks to).
    RealTime,
}

/// The emulated board running: QEMU, and its link USART's FIFOs.
pub struct Board {
    qemu: QemuGuard,
    /// The link: bytes the firmware sends, and bytes it receives.
    pub link: Link,
}

impl Board {
    /// Starts QEMU's netduinoplus2 on `elf` with `clock`, the semihosting
    /// command line `semihosting_args` (empty: none), and opens the link.
    pub fn start(elf: &Path, clock: Clock, semihosting_args: &[String]) -> Result<Board> {
        let dir = elf.parent().context("firmware path has a parent")?;
        let fifos = Fifos::make(&dir.join(format!("link-{}-{}", std::process::id(), unique())))?;
        let mut qemu = QemuGuard(spawn_qemu(elf, fifos.path(), clock, semihosting_args)?);
        let link = fifos.connect(&mut qemu.0)?;
        Ok(Board { qemu, link })
    }

    /// QEMU's stdout: the firmware's defmt log (semihosting).
    pub fn take_log(&mut self) -> Result<ChildStdout> {
        self.qemu.0.stdout.take().context("QEMU stdout")
    }

    /// Waits for QEMU to exit (the firmware ended the run).
    pub fn wait(&mut self) -> Result<ExitStatus> {
        self.qemu.0.wait().context("waiting for QEMU")
    }

    /// Stops QEMU; returns its status if it had already exited by itself.
    pub fn stop(&mut self) -> Option<ExitStatus> {
        self.qemu.stop()
    }
}

/// A number no other board started by this process has used.
fn unique() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Runs `elf` on QEMU until `triad decode` stops at `stop`, then stops QEMU.
/// Returns the decoder's exit status.
pub fn stream_to_decoder(elf: &Path, triad: &Path, stop: Stop, sink: Sink) -> Result<ExitStatus> {
    stream_with_log(elf, triad, stop, sink).map(|(status, _)| status)
}

/// As [`stream_to_decoder`], and the firmware's log lines (printed too).
pub fn stream_with_log(
    elf: &Path,
    triad: &Path,
    stop: Stop,
    sink: Sink,
) -> Result<(ExitStatus, Vec<String>)> {
    let mut board = Board::start(elf, Clock::Deterministic, &[])?;
    let elf_bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let log = board.take_log()?;
    let log_thread = std::thread::spawn(move || defmt_log::collect(&elf_bytes, log));

    let mut serial = board.link.try_clone().context("cloning the link")?;
    let (mut decoder_cmd, raw_file) = match &sink {
        Sink::Inherit => (Command::new(triad), None),
        Sink::Files { raw, csv } => {
            let mut command = Command::new(triad);
            let out = File::create(csv).with_context(|| format!("creating {}", csv.display()))?;
            command.stdout(out);
            let raw = File::create(raw).with_context(|| format!("creating {}", raw.display()))?;
            (command, Some(raw))
        }
    };
    let mut decoder = decoder_cmd
        .args(["decode", "-"])
        .args(stop.decode_args())
        .stdin(Stdio::piped())
        .spawn()
        .context("starting triad decode")?;
    let mut stdin = decoder.stdin.take().context("decoder stdin")?;
    let pump = std::thread::spawn(move || -> std::io::Result<()> {
        let mut raw_file = raw_file;
        let mut buffer = [0u8; 4096];
        loop {
            let n = serial.read(&mut buffer)?;
            if n == 0 {
                return Ok(());
            }
            if let Some(file) = raw_file.as_mut() {
                file.write_all(&buffer[..n])?;
            }
            // The decoder closes its stdin when it stops: that ends the pump.
            if stdin.write_all(&buffer[..n]).is_err() {
                return Ok(());
            }
        }
    });
    let status = decoder.wait().context("waiting for triad decode")?;
    let qemu_status = board.stop();
    let _ = pump.join();
    let lines = log_thread.join().unwrap_or_default();
    if let Some(qemu_status) = qemu_status {
        // QEMU exits on its own only through a semihosting exit: the firmware
        // ended the run early (a fatal error or a panic).
        if !qemu_status.success() {
            bail!("the firmware stopped QEMU with {qemu_status} before {stop:?} streamed");
        }
    }
    Ok((status, lines))
}

/// QEMU on `machine` running `elf` deterministically: no display or
/// monitor, one instruction per virtual nanosecond, idle time skipped,
/// semihosting on (the firmware's log and exit status).
pub fn command(machine: &str, elf: &Path) -> Command {
    command_with(machine, elf, Clock::Deterministic, &[])
}

/// QEMU on `machine` running `elf` with `clock` and the semihosting command
/// line `semihosting_args`.
pub fn command_with(
    machine: &str,
    elf: &Path,
    clock: Clock,
    semihosting_args: &[String],
) -> Command {
    let mut command = Command::new(setup::qemu());
    command.args(["-machine", machine, "-display", "none", "-monitor", "none"]);
    if clock == Clock::Deterministic {
        command.args(["-icount", "shift=0,sleep=off"]);
    }
    let mut semihosting = String::from("enable=on,target=native");
    for arg in semihosting_args {
        semihosting.push_str(",arg=");
        semihosting.push_str(arg);
    }
    command
        .args(["-semihosting-config", &semihosting])
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null());
    command
}

fn spawn_qemu(elf: &Path, link: &Path, clock: Clock, semihosting_args: &[String]) -> Result<Child> {
    let mut command = command_with("netduinoplus2", elf, clock, semihosting_args);
    command
        .arg("-chardev")
        .arg(format!("pipe,id=stream,path={}", link.display()))
        // The first -serial is USART1 (unused), the second USART2: the link.
        .args(["-serial", "null", "-serial", "chardev:stream"])
        .stdout(Stdio::piped());
    // QEMU dies with xtask, even when xtask is killed outright.
    // SAFETY: prctl is async-signal-safe; nothing else runs in the child.
    unsafe {
        command.pre_exec(|| {
            nix::sys::prctl::set_pdeathsig(nix::sys::signal::Signal::SIGKILL)
                .map_err(std::io::Error::from)
        });
    }
    command.spawn().context("starting QEMU")
}

/// Kills QEMU when dropped, so an error path never leaves it running.
struct QemuGuard(Child);

impl QemuGuard {
    /// Stops QEMU; returns its status if it had already exited by itself.
    fn stop(&mut self) -> Option<ExitStatus> {
        let exited = self.0.try_wait().ok().flatten();
        if exited.is_none() {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
        exited
    }
}

impl Drop for QemuGuard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}
