//! Serial ports as `triad decode` and `triad device` open them: 8N1 at the
//! given baud, reads that give up after a poll period (so a command can
//! check Ctrl-C or its own deadline), and errors that name the port.

use std::io::{self, ErrorKind};
use std::time::Duration;

use anyhow::Context;

/// Opens `port` at `baud` with reads timing out after `poll`; a port that
/// does not exist or cannot be opened is an error naming it and the baud.
pub fn open(
    port: &str,
    baud: u32,
    poll: Duration,
) -> anyhow::Result<Box<dyn serialport::SerialPort>> {
    serialport::new(port, baud)
        .timeout(poll)
        .open()
        .with_context(|| format!("cannot open serial port {port} at {baud} baud"))
}

/// EIO (5 on Linux and macOS) and the kinds that mean "the other end left":
/// a serial port that goes away (USB unplugged, pty closed) reads so.
pub fn is_port_gone(e: &io::Error) -> bool {
    const EIO: i32 = 5;
    e.raw_os_error() == Some(EIO)
        || matches!(
            e.kind(),
            ErrorKind::BrokenPipe | ErrorKind::UnexpectedEof | ErrorKind::ConnectionReset
        )
}
