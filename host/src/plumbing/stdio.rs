//! Standard output and standard error without panics.
//!
//! `println!` panics when stdout is a closed pipe or a full disk, and Rust's
//! stdout silently swallows writes when the descriptor is closed (`>&-`).
//! Here every write to stdout returns its error: a reader that went away
//! (`triad … | head -1`) becomes [`ReaderGone`], which `main` turns into a
//! quiet exit with status [`READER_GONE_STATUS`]; any other failure
//! (`> /dev/full`) is an error naming standard output. Messages to stderr
//! (`note!`) ignore their own errors: there is nowhere left to report them.

use std::fs::File;
use std::io::{self, Write};
use std::sync::atomic::{AtomicU8, Ordering};

/// Exit status when the reader of stdout closed the pipe: 128 + SIGPIPE
/// (13), what a shell reports for `cat`, `seq` and the other Unix tools that
/// a closed pipe stops, so `set -o pipefail` scripts see the same.
pub const READER_GONE_STATUS: u8 = 141;

/// The reader of standard output closed it: stop quietly (files already
/// written stay written).
#[derive(Debug)]
pub struct ReaderGone;

impl std::fmt::Display for ReaderGone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the reader of standard output closed it (broken pipe)")
    }
}

impl std::error::Error for ReaderGone {}

/// A line on stderr; a failure to write it is ignored (stderr is the last
/// place to report anything).
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
pub(crate) use note;

/// A line of a report built in a `String` (printed whole with [`print`]
/// once the command's files are written).
macro_rules! outln {
    ($out:expr) => {
        $out.push('\n')
    };
    ($out:expr, $($arg:tt)*) => {{
        $out.push_str(&format!($($arg)*));
        $out.push('\n');
    }};
}
pub(crate) use outln;

/// The error of a failed write to standard output.
pub fn stdout_error(e: io::Error) -> anyhow::Error {
    if e.kind() == io::ErrorKind::BrokenPipe {
        anyhow::Error::new(ReaderGone)
    } else {
        anyhow::anyhow!("writing to standard output: {e}")
    }
}

/// True when `error` (or what it wraps) is [`ReaderGone`].
pub fn is_reader_gone(error: &anyhow::Error) -> bool {
    error.chain().any(|e| e.is::<ReaderGone>())
}

/// Standard output as a file of its own (a duplicate of descriptor 1):
/// unbuffered, so a write's count is what the output took, and an error
/// when stdout is closed instead of writes that vanish.
#[cfg(unix)]
pub fn raw_stdout() -> anyhow::Result<File> {
    use std::os::fd::AsFd;
    let fd = io::stdout()
        .as_fd()
        .try_clone_to_owned()
        .map_err(|e| anyhow::anyhow!("standard output is closed ({e}): nothing done"))?;
    Ok(File::from(fd))
}

/// Standard output as a file of its own (a duplicate of its handle).
#[cfg(windows)]
pub fn raw_stdout() -> anyhow::Result<File> {
    use std::os::windows::io::AsHandle;
    let handle = io::stdout()
        .as_handle()
        .try_clone_to_owned()
        .map_err(|e| anyhow::anyhow!("standard output is closed ({e}): nothing done"))?;
    Ok(File::from(handle))
}

/// Fails when standard output was closed by the caller (`>&-`), before any
/// work: what is printed would be lost while the command reports success.
///
/// Rust's runtime puts /dev/null, opened read-write, on a closed standard
/// descriptor before `main`, so by then a closed stdout looks exactly like
/// the /dev/null that Python's `subprocess.DEVNULL`, nohup and service
/// managers hand a process on purpose. Only the state recorded before the
/// runtime started ([`record_stdout_at_start`]) tells them apart; where it
/// was not recorded, only a descriptor that cannot be duplicated is refused.
pub fn check_stdout_open() -> anyhow::Result<()> {
    raw_stdout()?;
    if STDOUT_AT_START.load(Ordering::Relaxed) == CLOSED {
        anyhow::bail!(
            "standard output was closed when triad started (>&-): nothing done \
             (use > /dev/null to discard it)"
        );
    }
    Ok(())
}

/// Descriptor 1 at process start: [`UNKNOWN`], [`OPEN`] or [`CLOSED`].
static STDOUT_AT_START: AtomicU8 = AtomicU8::new(UNKNOWN);
const UNKNOWN: u8 = 0;
const OPEN: u8 = 1;
const CLOSED: u8 = 2;

/// Records whether descriptor 1 is open. The `triad` binary runs it from
/// its ELF `.init_array`, before Rust's runtime replaces a closed standard
/// descriptor with /dev/null: the one moment the two can be told apart.
#[cfg(unix)]
pub extern "C" fn record_stdout_at_start() {
    // SAFETY: F_GETFD only reads descriptor 1's flags; on a closed
    // descriptor it fails with EBADF and changes nothing.
    let flags = unsafe { libc::fcntl(1, libc::F_GETFD) };
    let closed = flags == -1 && io::Error::last_os_error().raw_os_error() == Some(libc::EBADF);
    STDOUT_AT_START.store(if closed { CLOSED } else { OPEN }, Ordering::Relaxed);
}

/// Prints `text` (a string or bytes) on standard output, whole or with an error.
pub fn print(text: impl AsRef<[u8]>) -> anyhow::Result<()> {
    let mut out = raw_stdout()?;
    out.write_all(text.as_ref()).map_err(stdout_error)
}

/// Prints a command's report (a summary, a fit's figures): on standard
/// output, or as a note on stderr when `stdout_taken` (an output of the
/// command went to standard output).
pub fn report(text: &str, stdout_taken: bool) -> anyhow::Result<()> {
    if stdout_taken {
        note!("{}", text.trim_end());
        Ok(())
    } else {
        print(text)
    }
}

/// Makes what was written to `out` durable when it is a regular file (a
/// full or failing disk reports here what `write` accepted); pipes and
/// terminals have nothing to sync.
pub fn sync_if_file(out: &File) -> io::Result<()> {
    match out.metadata() {
        Ok(m) if m.is_file() => out.sync_all(),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_broken_pipe_is_the_reader_gone_and_other_errors_name_stdout() {
        let gone = stdout_error(io::Error::from(io::ErrorKind::BrokenPipe));
        assert!(is_reader_gone(&gone));
        let full = stdout_error(io::Error::from_raw_os_error(28));
        assert!(!is_reader_gone(&full));
        assert!(full
            .to_string()
            .starts_with("writing to standard output: No space left on device"));
        assert!(is_reader_gone(&gone.context("printing the report")));
    }
}
