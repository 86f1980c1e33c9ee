//! `cargo xtask serve`: the emulated board served like hardware. QEMU runs
//! the firmware paced to real time (no `-icount`: virtual time is the host's
//! clock), its link USART on a pair of FIFOs that xtask pumps to and from a
//! pseudo-terminal; the pty's path is the first line on stdout, so that
//! `triad device --port PATH` and `triad decode --port PATH` work against it
//! exactly as against a board. It runs until killed (Ctrl-C), or until the
//! firmware stops. With `--deterministic` (the end-to-end tests of the
//! link, and `triad calib session` on a busy machine) it runs on QEMU's
//! `-icount` clock, as `cargo xtask run` does, so the host's load causes
//! no overrun, and a client slower than the board loses nothing: the board
//! waits for it.
//!
//! The calibration flash is the file `--storage FILE` names (created all
//! 0xFF when missing, so it persists across runs); without it the board
//! has no storage and `save` answers "not supported".

use crate::pty::{Pty, Unread};
use crate::{defmt_log, qemu};
use anyhow::{bail, Context, Result};
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::os::fd::AsFd;
use std::path::{Path, PathBuf};

/// Bytes of the emulated board's flash file (its `semihosting_flash::CAPACITY`).
pub const STORAGE_BYTES: usize = 32 * 1024;

/// How the emulated board's storage is set up.
pub struct Storage {
    /// The file (absolute).
    pub path: PathBuf,
    /// For the power-cut test: the run ends at this write or erase operation.
    pub cut_after: Option<u32>,
}

/// Creates the storage file when missing (all 0xFF: erased flash); refuses
/// one of the wrong size rather than touching it.
pub fn prepare_storage(path: &Path) -> Result<PathBuf> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.len() == STORAGE_BYTES as u64 => {}
        Ok(meta) => bail!(
            "--storage {}: {} bytes, but the emulated board's flash is {STORAGE_BYTES} bytes; \
             not a triad storage file (remove it to start afresh)",
            path.display(),
            meta.len()
        ),
        Err(e) if e.kind() == ErrorKind::NotFound => {
            std::fs::write(path, vec![0xFFu8; STORAGE_BYTES])
                .with_context(|| format!("creating the storage file {}", path.display()))?;
        }
        Err(e) => return Err(e).with_context(|| format!("--storage {}", path.display())),
    }
    let path =
        std::fs::canonicalize(path).with_context(|| format!("--storage {}", path.display()))?;
    if path.to_str().is_none_or(|p| p.contains(',')) {
        bail!(
            "--storage {}: QEMU's semihosting options cannot carry this path (commas, or not UTF-8)",
            path.display()
        );
    }
    Ok(path)
}

/// The semihosting arguments that hand the fault schedule (entries checked
/// by [`fault_entry`]) and the storage file to the firmware: the faults
/// first, as the storage path runs to the end of the line.
pub fn semihosting_args(faults: &[String], storage: Option<&Storage>) -> Vec<String> {
    if faults.is_empty() && storage.is_none() {
        return Vec::new();
    }
    let mut args = vec!["triad".to_string()];
    args.extend(faults.iter().map(|f| format!("fault={f}")));
    if let Some(storage) = storage {
        args.push(format!("storage={}", storage.path.display()));
        if let Some(n) = storage.cut_after {
            args.push(format!("cut-after={n}"));
        }
    }
    args
}

/// `--fault SPEC`: one entry of the emulated board's fault schedule, checked
/// with the parser the board uses (`KIND@START[+DURATION]`, seconds of device
/// time; `nack@START*COUNT`).
pub fn fault_entry(spec: &str) -> Result<String, String> {
    let mut schedule = triad_sim::chips::fault_schedule::FaultSchedule::new();
    schedule.add(spec).map_err(|e| e.to_string())?;
    Ok(spec.to_string())
}

/// How long the deterministic board's bytes gather before the pump passes
/// them on (wall time; see [`serve`]).
const GATHER: std::time::Duration = std::time::Duration::from_millis(2);

/// Serves `elf` with `clock` (real time, or deterministic for the tests)
/// until QEMU stops (the firmware ended the run, or it was killed); an
/// early stop is an error.
pub fn serve(
    elf: &Path,
    storage: Option<&Storage>,
    faults: &[String],
    clock: qemu::Clock,
) -> Result<()> {
    let pty = Pty::open()?;
    let args = semihosting_args(faults, storage);
    let mut board = qemu::Board::start(elf, clock, &args)?;
    let elf_bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let log = board.take_log()?;
    std::thread::spawn(move || defmt_log::print(&elf_bytes, log));

    // The first stdout line is the port: scripts read it. A board nobody
    // can be told the port of is not served (stdout full, or its reader
    // gone); a /dev/null stdout is the caller's choice.
    let mut stdout = std::io::stdout();
    writeln!(stdout, "{}", pty.path.display())
        .and_then(|()| stdout.flush())
        .context("writing the port's path to standard output")?;
    note!(
        "xtask: the emulated board's link is {} ({}); Ctrl-C stops it",
        pty.path.display(),
        match storage {
            Some(s) => format!("storage {}", s.path.display()),
            None => "no storage".to_string(),
        }
    );

    let mut from_device = board.link.try_clone().context("cloning the link")?;
    let mut to_device = board.link.try_clone().context("cloning the link")?;
    let mut master_out = pty.master.try_clone().context("cloning the pty")?;
    let mut master_in = pty.master.try_clone().context("cloning the pty")?;
    let unread = pty.unread()?;
    // Device → host: in real time, when the pty is full (no client, or one
    // not reading), what it holds unread is dropped, so the newest bytes (a
    // reply) get in. Deterministic, the pump waits for the client instead:
    // QEMU then waits on its full pipe and the board's virtual time with it,
    // so a slow host loses nothing, as the instruction clock promises.
    std::thread::spawn(move || -> Result<()> {
        // No more than the pty takes: in real time a chunk that does not
        // fit is written again whole after the unread bytes are dropped.
        let mut buffer = [0u8; 4096];
        loop {
            let n = from_device.read(&mut buffer)?;
            if n == 0 {
                return Ok(());
            }
            match clock {
                qemu::Clock::RealTime => to_client(&mut master_out, &unread, &buffer[..n])?,
                qemu::Clock::Deterministic => {
                    to_client_waiting(&mut master_out, &buffer[..n])?;
                    // QEMU's USART writes the pipe a byte at a time:
                    // woken for each few bytes, this thread and the
                    // client cost two context switches apiece, which
                    // bound the board's speed on a busy machine. Letting
                    // the bytes gather first costs the board nothing (its
                    // pipe, 1 MiB, holds far more than it sends meanwhile) and
                    // a reply at most this much wall time.
                    if n < buffer.len() {
                        std::thread::sleep(GATHER);
                    }
                }
            }
        }
    });
    // Host → device.
    std::thread::spawn(move || -> Result<()> {
        let mut buffer = [0u8; 4096];
        loop {
            poll(
                &mut [PollFd::new(master_in.as_fd(), PollFlags::POLLIN)],
                PollTimeout::NONE,
            )?;
            match master_in.read(&mut buffer) {
                Ok(0) => return Ok(()),
                Ok(n) => to_device.write_all(&buffer[..n])?,
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                // EIO: no client has the slave open (cannot happen while
                // xtask holds it, but never spin on it).
                Err(e) => return Err(e.into()),
            }
        }
    });
    let status = board.wait()?;
    bail!("the firmware stopped QEMU ({status})")
}

/// Writes all of `chunk` into the pty's master, waiting while the pty is
/// full (the deterministic board: nothing is dropped, the board waits).
fn to_client_waiting(master: &mut File, chunk: &[u8]) -> Result<()> {
    let mut rest = chunk;
    while !rest.is_empty() {
        match master.write(rest) {
            Ok(n) => rest = &rest[n..],
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                poll(
                    &mut [PollFd::new(master.as_fd(), PollFlags::POLLOUT)],
                    PollTimeout::NONE,
                )?;
            }
            Err(e) => return Err(e.into()),
        }
    }
    Ok(())
}

/// Writes `chunk` into the pty's master. When the pty is full (no client,
/// or one not reading), what the client has not read is dropped and the
/// whole chunk written again, so a reply in it arrives whole; bytes that
/// still do not fit are dropped, as on a line nobody listens to.
fn to_client(master: &mut File, unread: &Unread, chunk: &[u8]) -> Result<()> {
    let mut rest = chunk;
    let mut discarded = false;
    while !rest.is_empty() {
        let full = match master.write(rest) {
            Ok(0) => true,
            Ok(n) => {
                rest = &rest[n..];
                false
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => true,
            Err(e) => return Err(e.into()),
        };
        if full {
            if discarded {
                return Ok(());
            }
            // The chunk's head, if written, went with the rest.
            unread.discard()?;
            discarded = true;
            rest = chunk;
        }
    }
    Ok(())
}
