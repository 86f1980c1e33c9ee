//! The emulated board's link: QEMU's USART2 on a pair of FIFOs
//! (`-chardev pipe,path=BASE`: QEMU reads BASE.in and writes BASE.out).
//!
//! Why not a Unix socket, as before: QEMU's STM32 USART writes its chardev
//! one byte per system call, and a Unix stream socket charges each write a
//! whole buffer (about 700 bytes of its send budget for one byte), so a
//! default socket holds only some 300 bytes. Each time the host side had
//! not read for a moment, QEMU found it full and slept 100 µs a retry:
//! the soak ran at 7 device seconds per wall second where QEMU alone gives
//! 16. A pipe appends small writes to the same page and holds as many
//! bytes as its size; this one is raised to 1 MiB (Linux's default
//! `pipe-max-size`, no privilege needed).

use anyhow::{bail, Context, Result};
use nix::errno::Errno;
use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use nix::sys::stat::Mode;
use std::fs::{File, OpenOptions};
use std::io::{ErrorKind, Read, Write};
use std::os::fd::AsFd;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::process::Child;
use std::time::{Duration, Instant};

/// What the device → host pipe holds (Linux's default `pipe-max-size`).
const PIPE_BYTES: i32 = 1 << 20;

/// How long QEMU may take to open its end of the link.
const OPEN_TIMEOUT: Duration = Duration::from_secs(20);

/// The two FIFOs, made before QEMU starts; [`Fifos::path`] is the
/// `-chardev pipe` path. Removed when dropped (the open ends stay valid).
pub struct Fifos {
    base: PathBuf,
    /// The device → host end, open for reading before QEMU starts, so no
    /// byte is written where nobody reads.
    from_device: File,
}

impl Fifos {
    /// Makes BASE.in and BASE.out and opens BASE.out for reading.
    pub fn make(base: &Path) -> Result<Fifos> {
        for end in ["in", "out"] {
            let path = base.with_extension(end);
            let _ = std::fs::remove_file(&path);
            nix::unistd::mkfifo(&path, Mode::S_IRUSR | Mode::S_IWUSR)
                .with_context(|| format!("making the FIFO {}", path.display()))?;
        }
        let out = base.with_extension("out");
        // Non-blocking: opening for reading does not wait for QEMU; reads
        // wait in `poll` instead (see `Link::read`).
        let from_device = OpenOptions::new()
            .read(true)
            .custom_flags(OFlag::O_NONBLOCK.bits())
            .open(&out)
            .with_context(|| format!("opening {}", out.display()))?;
        // A smaller pipe only makes QEMU wait sooner: not an error.
        let _ = fcntl(&from_device, FcntlArg::F_SETPIPE_SZ(PIPE_BYTES));
        Ok(Fifos {
            base: base.to_path_buf(),
            from_device,
        })
    }

    /// The path QEMU's `-chardev pipe,path=` takes.
    pub fn path(&self) -> &Path {
        &self.base
    }

    /// Waits until `qemu` has opened its ends, then returns the link.
    pub fn connect(self, qemu: &mut Child) -> Result<Link> {
        let input = self.base.with_extension("in");
        let start = Instant::now();
        // Opening a FIFO to write without waiting fails (ENXIO) until
        // there is a reader: QEMU, which opens both ends at start.
        let to_device = loop {
            match OpenOptions::new()
                .write(true)
                .custom_flags(OFlag::O_NONBLOCK.bits())
                .open(&input)
            {
                Ok(file) => break file,
                Err(error) if error.raw_os_error() == Some(Errno::ENXIO as i32) => {
                    if let Some(status) = qemu.try_wait()? {
                        // QEMU reports one open's error for two; which FIFO
                        // was there says more (seen once, cause unknown).
                        bail!(
                            "QEMU exited ({status}) before opening {} ({})",
                            input.display(),
                            self.which_exist()
                        );
                    }
                    if start.elapsed() > OPEN_TIMEOUT {
                        bail!(
                            "QEMU did not open {} within {OPEN_TIMEOUT:?}",
                            input.display()
                        );
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(error) => {
                    return Err(error).with_context(|| format!("opening {}", input.display()))
                }
            }
        };
        // Writes wait while QEMU's side is full, as a socket's did.
        fcntl(&to_device, FcntlArg::F_SETFL(OFlag::empty()))
            .with_context(|| format!("making {} blocking", input.display()))?;
        Ok(Link {
            from_device: self.from_device.try_clone()?,
            to_device,
        })
    }
}

impl Fifos {
    /// "BASE.in is there, BASE.out is missing": the FIFOs as they are now.
    fn which_exist(&self) -> String {
        let state = |end: &str| {
            let path = self.base.with_extension(end);
            let is = match std::fs::symlink_metadata(&path) {
                Ok(m) if m.file_type().is_fifo() => "is there",
                Ok(_) => "is there but not a FIFO",
                Err(e) if e.kind() == ErrorKind::NotFound => "is missing",
                Err(_) => "cannot be examined",
            };
            format!("{} {is}", path.display())
        };
        format!("{}, {}", state("in"), state("out"))
    }
}

impl Drop for Fifos {
    fn drop(&mut self) {
        for end in ["in", "out"] {
            let _ = std::fs::remove_file(self.base.with_extension(end));
        }
    }
}

/// The link: bytes the firmware sends (read), bytes it receives (written).
/// A read returns 0 once QEMU has closed its end (it exited).
pub struct Link {
    from_device: File,
    to_device: File,
}

impl Link {
    /// Another handle on the same two ends (one thread reads, one writes).
    pub fn try_clone(&self) -> std::io::Result<Link> {
        Ok(Link {
            from_device: self.from_device.try_clone()?,
            to_device: self.to_device.try_clone()?,
        })
    }
}

impl Read for Link {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            let mut fds = [PollFd::new(self.from_device.as_fd(), PollFlags::POLLIN)];
            match poll(&mut fds, PollTimeout::NONE) {
                Ok(_) | Err(Errno::EINTR) => {}
                Err(e) => return Err(e.into()),
            }
            // POLLHUP only once a writer came and went: QEMU exited.
            let hung_up = fds[0]
                .revents()
                .is_some_and(|r| r.contains(PollFlags::POLLHUP));
            match self.from_device.read(buf) {
                Ok(0) if hung_up => return Ok(0),
                Ok(0) => {}
                Ok(n) => return Ok(n),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
                Err(e) => return Err(e),
            }
        }
    }
}

impl Write for Link {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.to_device.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.to_device.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn which_fifo_is_there_is_said_by_name() {
        let base = std::env::temp_dir().join(format!("triad-link-test-{}", std::process::id()));
        let fifos = Fifos::make(&base).unwrap();
        let both = fifos.which_exist();
        assert!(
            both.contains(".in is there") && both.contains(".out is there"),
            "{both}"
        );
        std::fs::remove_file(base.with_extension("in")).unwrap();
        let one = fifos.which_exist();
        assert!(
            one.contains(".in is missing") && one.contains(".out is there"),
            "{one}"
        );
        drop(fifos);
        assert!(!base.with_extension("out").exists(), "removed when dropped");
    }
}
