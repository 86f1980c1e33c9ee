//! A pseudo-terminal standing in for a board's USB serial port: `cargo xtask
//! serve` pumps the emulated board's link between QEMU's socket and the
//! pty's master side, and `triad device --port` opens the slave side, as it
//! would /dev/ttyACM0.

use anyhow::{Context, Result};
use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::pty::{openpty, OpenptyResult};
use nix::sys::termios::{cfmakeraw, tcflush, tcgetattr, tcsetattr, FlushArg, SetArg};
use std::fs::File;
use std::os::fd::{AsFd, OwnedFd};
use std::path::PathBuf;

/// The two ends of a raw pseudo-terminal.
pub struct Pty {
    /// The side xtask reads and writes (non-blocking writes).
    pub master: File,
    /// Kept open so the master never sees end-of-file between two clients
    /// (each `triad device` command opens and closes the slave).
    slave: OwnedFd,
    /// The slave's path, for `--port`.
    pub path: PathBuf,
}

impl Pty {
    /// Opens a pty in raw mode: no echo (an echo would send the device its
    /// own output as commands), no line editing, no translation.
    pub fn open() -> Result<Pty> {
        let OpenptyResult { master, slave } = openpty(None, None).context("openpty")?;
        let mut termios = tcgetattr(slave.as_fd()).context("tcgetattr on the pty")?;
        cfmakeraw(&mut termios);
        tcsetattr(slave.as_fd(), SetArg::TCSANOW, &termios).context("tcsetattr on the pty")?;
        let path = nix::unistd::ttyname(slave.as_fd()).context("the pty's name")?;
        // A client that stops reading must not stall the emulated board:
        // what it does not read is dropped, as on a line nobody listens to.
        fcntl(master.as_fd(), FcntlArg::F_SETFL(OFlag::O_NONBLOCK)).context("O_NONBLOCK")?;
        Ok(Pty {
            master: File::from(master),
            slave,
            path,
        })
    }

    /// A handle on what the slave side holds unread, for the thread that
    /// writes the master.
    pub fn unread(&self) -> Result<Unread> {
        Ok(Unread(
            self.slave.try_clone().context("cloning the pty's slave")?,
        ))
    }
}

/// The bytes written to the master that no client has read yet.
///
/// The pty keeps what no client reads (xtask holds the slave open), up to a
/// few tens of KiB: a client opening the port later would find that much
/// stale stream before it, and a reply to its first command, arriving while
/// the queue is still full, would be lost. A board's USB serial port keeps
/// nothing while no one has it open; this keeps the newest bytes instead of
/// the oldest.
pub struct Unread(OwnedFd);

impl Unread {
    /// Drops every byte no client has read.
    pub fn discard(&self) -> Result<()> {
        tcflush(self.0.as_fd(), FlushArg::TCIFLUSH).context("flushing the pty's unread bytes")
    }
}
