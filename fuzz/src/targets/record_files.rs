//! The recording readers ([`triad_host::record`]): the bytes as a file,
//! its format found from the content as `triad` finds it, read to the end.
//! Invariants ([`crate::invariants`]): no panic (a reader thread's panic,
//! which `triad` turns into an error for the user, is broken here), every
//! error names the file, every chunk holds samples, every sample is
//! finite-timed, and the samples' places (line or message) increase.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use triad_host::record::{self, Options};

use crate::invariants::{
    chunk_has_samples, error_names_file, no_library_panic, places_increase, sample_time_finite,
    Broken,
};

/// The name a fuzzed file has in messages (`acc…`: an imu_tk file reads as the accelerometer).
const NAME: &str = "acc_fuzzed";

/// A file of this process and input for the input (on /dev/shm where there
/// is one: AFL runs thousands of inputs a second), numbered so that
/// threads (the tests) never share one.
fn scratch(extension: &str) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let dir = Path::new("/dev/shm");
    let dir = if dir.is_dir() {
        dir.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    dir.join(format!(
        "triad-fuzz-{}-{}-{NAME}.{extension}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Reads `bytes` as a recording of any format (found from the content);
/// the samples read (0: refused, with a message that passed).
pub fn record(bytes: &[u8]) -> Result<u64, Broken> {
    read_as(bytes, "rec")
}

/// Reads `bytes` as triad's CSV (`t,ax,…`): the extension says CSV.
pub fn triad_csv(bytes: &[u8]) -> Result<u64, Broken> {
    read_as(bytes, "csv")
}

fn read_as(bytes: &[u8], extension: &str) -> Result<u64, Broken> {
    let path = scratch(extension);
    let written = std::fs::File::create(&path).and_then(|mut f| f.write_all(bytes));
    // Not a parser's fault (a full /dev/shm): no verdict.
    if written.is_err() {
        let _ = std::fs::remove_file(&path);
        return Ok(0);
    }
    let read = check(&path);
    let _ = std::fs::remove_file(&path);
    read
}

/// Opens and reads the file at `path` to its end, checking each chunk;
/// the samples read (0: refused, with a message that passed).
fn check(path: &Path) -> Result<u64, Broken> {
    let shown = path.display().to_string();
    let opened = match record::open(path, &Options::default()) {
        Ok(o) => o,
        Err(e) => return refused(&shown, &e),
    };
    let mut reader = opened.reader;
    let (mut last_at, mut samples) = (0u64, 0u64);
    loop {
        match reader.next_chunk() {
            Ok(Some(chunk)) => {
                chunk_has_samples(chunk.len())?;
                for s in &chunk {
                    sample_time_finite(s.t)?;
                    places_increase(s.at, last_at)?;
                    last_at = s.at;
                }
                samples += chunk.len() as u64;
            }
            Ok(None) => return Ok(samples),
            Err(e) => return refused(&shown, &e),
        }
    }
}

/// A refusal: not a library's panic, and a message naming the file.
fn refused(shown: &str, e: &anyhow::Error) -> Result<u64, Broken> {
    let message = format!("{e:#}");
    no_library_panic(&message)?;
    error_names_file(&message, shown)?;
    Ok(0)
}
