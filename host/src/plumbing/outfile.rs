//! Output files written whole or not at all.
//!
//! [`OutFile::create`] opens a temporary file beside the target (same
//! directory, so the final rename cannot cross file systems); writes go
//! there; [`OutFile::commit`] flushes, fsyncs and renames it over the
//! target. Dropped without a commit (an error, Ctrl-C handled by the
//! command) the temporary file is removed, and an existing target is
//! untouched. Two exceptions: `-` is standard output (a stream: what was
//! written is gone when an error follows), and an existing target that is
//! not a regular file (`/dev/null`, a FIFO) is written in place.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use anyhow::{anyhow, Context};

use crate::plumbing::stdio;

/// True when `path` means standard output (`-`).
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Where the bytes go.
enum Sink {
    /// A temporary file beside the target, renamed over it on commit.
    Beside { temporary: PathBuf },
    /// An existing non-regular file written in place.
    InPlace,
    /// Standard output.
    Stdout,
}

/// An output being written.
pub struct OutFile {
    path: PathBuf,
    sink: Sink,
    writer: Option<BufWriter<File>>,
}

/// Distinguishes the temporary files of one process.
static COUNTER: AtomicU32 = AtomicU32::new(0);

/// `.NAME.triad-PID-K.tmp` beside `path`.
fn temporary_beside(path: &Path) -> anyhow::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
    let k = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = format!(
        ".{}.triad-{}-{k}.tmp",
        name.to_string_lossy(),
        std::process::id()
    );
    Ok(path.with_file_name(tmp))
}

impl OutFile {
    /// Opens the output `path` (`-`: standard output). Fails, naming the
    /// path, when its directory does not exist or cannot be written.
    pub fn create(path: &Path) -> anyhow::Result<OutFile> {
        if is_stdout(path) {
            let file = stdio::raw_stdout()?;
            return Ok(OutFile {
                path: path.to_path_buf(),
                sink: Sink::Stdout,
                writer: Some(BufWriter::with_capacity(1 << 16, file)),
            });
        }
        let existing = fs::metadata(path).ok();
        if let Some(m) = &existing {
            if m.is_dir() {
                anyhow::bail!("{}: is a directory", path.display());
            }
            if !m.is_file() {
                let file = OpenOptions::new()
                    .write(true)
                    .open(path)
                    .with_context(|| format!("{}: cannot open for writing", path.display()))?;
                return Ok(OutFile {
                    path: path.to_path_buf(),
                    sink: Sink::InPlace,
                    writer: Some(BufWriter::with_capacity(1 << 16, file)),
                });
            }
        }
        let temporary = temporary_beside(path)?;
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temporary)
            .with_context(|| format!("{}: cannot create it", path.display()))?;
        if let Some(m) = existing {
            // The new file keeps the old one's permissions.
            let _ = fs::set_permissions(&temporary, m.permissions());
        }
        Ok(OutFile {
            path: path.to_path_buf(),
            sink: Sink::Beside { temporary },
            writer: Some(BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The target's path (`-` for standard output).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// True when this output is standard output.
    pub fn is_stdout(&self) -> bool {
        matches!(self.sink, Sink::Stdout)
    }

    /// The error of a failed write to this output, naming it.
    pub fn error(&self, e: io::Error) -> anyhow::Error {
        match self.sink {
            Sink::Stdout => stdio::stdout_error(e),
            _ => anyhow!("writing {}: {e}", self.path.display()),
        }
    }

    /// Flushes and syncs the data, then puts the file in place.
    pub fn commit(mut self) -> anyhow::Result<()> {
        let Some(writer) = self.writer.take() else {
            return Ok(());
        };
        let file = match writer.into_inner() {
            Ok(file) => file,
            Err(e) => {
                let e = e.into_error();
                return Err(self.error(e));
            }
        };
        // A device or a FIFO written in place has nothing to sync.
        let synced = match self.sink {
            Sink::Beside { .. } => file.sync_all(),
            _ => stdio::sync_if_file(&file),
        };
        synced.map_err(|e| self.error(e))?;
        drop(file);
        if let Sink::Beside { temporary } = &self.sink {
            fs::rename(temporary, &self.path).with_context(|| {
                format!(
                    "{}: cannot put the written file in place",
                    self.path.display()
                )
            })?;
            sync_directory_of(&self.path);
            // Committed: nothing for Drop to remove.
            self.sink = Sink::InPlace;
        }
        Ok(())
    }
}

/// Makes the rename durable (best effort: not every system can sync a directory).
fn sync_directory_of(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

impl Write for OutFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.writer.as_mut() {
            Some(w) => w.write(buf),
            None => Err(io::Error::other("output already committed")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self.writer.as_mut() {
            Some(w) => w.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for OutFile {
    fn drop(&mut self) {
        if let Sink::Beside { temporary } = &self.sink {
            drop(self.writer.take());
            let _ = fs::remove_file(temporary);
        }
    }
}

/// Checks that `path` can be created (its directory exists and takes a
/// new file), without touching it: for long commands, before the work.
pub fn probe(path: &Path) -> anyhow::Result<()> {
    OutFile::create(path).map(drop)
}

/// Writes `bytes` to `path` whole (or to standard output for `-`).
pub fn write_whole(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut out = OutFile::create(path)?;
    out.write_all(bytes).map_err(|e| out.error(e))?;
    out.commit()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::entries;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("triad-outfile-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_committed_file_replaces_the_old_one_and_leaves_nothing_beside() {
        let d = dir("commit");
        let path = d.join("a.txt");
        fs::write(&path, "old").unwrap();
        let mut out = OutFile::create(&path).unwrap();
        out.write_all(b"new").unwrap();
        // Until the commit the old content is in place.
        assert_eq!(fs::read_to_string(&path).unwrap(), "old");
        out.commit().unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(entries(&d), ["a.txt"]);
    }

    #[test]
    fn an_uncommitted_file_leaves_the_old_one_untouched() {
        let d = dir("drop");
        let path = d.join("a.txt");
        fs::write(&path, "old").unwrap();
        let mut out = OutFile::create(&path).unwrap();
        out.write_all(b"half").unwrap();
        drop(out);
        assert_eq!(fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(entries(&d), ["a.txt"]);
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_path() {
        let d = dir("missing");
        let err = probe(&d.join("no/such/x.csv")).unwrap_err().to_string();
        assert!(err.contains("no/such/x.csv: cannot create it"), "{err}");
        assert!(probe(&d)
            .unwrap_err()
            .to_string()
            .contains("is a directory"));
    }

    #[test]
    fn a_device_is_written_in_place() {
        write_whole(Path::new("/dev/null"), b"x").unwrap();
        // Still the device: not replaced by a regular file.
        assert!(!fs::metadata("/dev/null").unwrap().is_file());
    }
}
