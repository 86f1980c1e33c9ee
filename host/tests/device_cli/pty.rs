//! A pseudo-terminal: the master end is the device's line, the slave end's
//! path (`/dev/pts/N`) is what `triad device --port` opens, as it would a
//! board's USB serial port.

use std::fs::File;
use std::os::fd::OwnedFd;

use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use nix::unistd::ttyname;

/// An open pseudo-terminal.
pub struct Pty {
    /// The device's end; reads return `WouldBlock` when nothing came.
    pub master: File,
    /// Held open so the line stays up between two runs of `triad`.
    _slave: OwnedFd,
    /// The path `--port` takes.
    pub path: String,
}

impl Pty {
    /// A raw (no echo, no line editing) pseudo-terminal.
    pub fn open() -> Pty {
        let pair = openpty(None, None).expect("openpty");
        // Raw from the start: bytes the device sends before `triad` opens
        // the port must not be echoed back or edited as lines.
        let mut termios = tcgetattr(&pair.slave).expect("tcgetattr");
        cfmakeraw(&mut termios);
        tcsetattr(&pair.slave, SetArg::TCSANOW, &termios).expect("tcsetattr");
        fcntl(&pair.master, FcntlArg::F_SETFL(OFlag::O_NONBLOCK)).expect("non-blocking master");
        let path = ttyname(&pair.slave)
            .expect("the slave's path")
            .to_string_lossy()
            .into_owned();
        Pty {
            master: File::from(pair.master),
            _slave: pair.slave,
            path,
        }
    }
}
