//! The emulated board: QEMU's netduinoplus2 running the firmware, its USART2
//! stream piped into `triad decode`, its defmt log (semihosting, on QEMU's
//! stdout) decoded onto stderr.
//!
//! `-icount shift=0,sleep=off`: each instruction advances virtual time by 1 ns
//! and idle time is skipped, so runs are deterministic and faster than real
//! time (DESIGN.md, "The emulated board").

use crate::{defmt_log, setup};
use anyhow::{bail, Context, Result};
use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

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

/// How long QEMU may take to open its serial socket.
const SOCKET_TIMEOUT: Duration = Duration::from_secs(20);

/// Runs `elf` on QEMU until `triad decode` stops at `stop`, then stops QEMU.
/// Returns the decoder's exit status.
pub fn stream_to_decoder(elf: &Path, triad: &Path, stop: Stop, sink: Sink) -> Result<ExitStatus> {
    let dir = elf.parent().context("firmware path has a parent")?;
    let socket = dir.join(format!("serial-{}.sock", std::process::id()));
    let _ = std::fs::remove_file(&socket);
    let mut qemu = QemuGuard(spawn_qemu(elf, &socket)?);

    let elf_bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let log = qemu.0.stdout.take().context("QEMU stdout")?;
    let log_thread = std::thread::spawn(move || defmt_log::print(&elf_bytes, log));

    let mut serial = connect(&socket, &mut qemu.0)?;
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
    let qemu_status = qemu.stop();
    let _ = pump.join();
    let _ = log_thread.join();
    if let Some(qemu_status) = qemu_status {
        // QEMU exits on its own only through a semihosting exit: the firmware
        // ended the run early (a fatal error or a panic).
        if !qemu_status.success() {
            bail!("the firmware stopped QEMU with {qemu_status} before {stop:?} streamed");
        }
    }
    Ok(status)
}

/// QEMU on `machine` running `elf` deterministically: no display or
/// monitor, one instruction per virtual nanosecond, idle time skipped,
/// semihosting on (the firmware's log and exit status).
pub fn command(machine: &str, elf: &Path) -> Command {
    let mut command = Command::new(setup::qemu());
    command
        .args(["-machine", machine, "-display", "none", "-monitor", "none"])
        .args(["-icount", "shift=0,sleep=off"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null());
    command
}

fn spawn_qemu(elf: &Path, socket: &Path) -> Result<Child> {
    let mut command = command("netduinoplus2", elf);
    command
        .arg("-chardev")
        .arg(format!(
            "socket,id=stream,path={},server=on,wait=on",
            socket.display()
        ))
        // The first -serial is USART1 (unused), the second USART2: the link.
        .args(["-serial", "null", "-serial", "chardev:stream"])
        .stdout(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting {}", command.get_program().to_string_lossy()))
}

fn connect(socket: &Path, qemu: &mut Child) -> Result<UnixStream> {
    let start = Instant::now();
    loop {
        match UnixStream::connect(socket) {
            Ok(stream) => return Ok(stream),
            Err(error) => {
                if let Some(status) = qemu.try_wait()? {
                    bail!("QEMU exited ({status}) before opening {}", socket.display());
                }
                if start.elapsed() > SOCKET_TIMEOUT {
                    bail!(
                        "QEMU did not open {} within {SOCKET_TIMEOUT:?}: {error}",
                        socket.display()
                    );
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    }
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
