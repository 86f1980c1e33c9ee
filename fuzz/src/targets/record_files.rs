//! The recording readers ([`triad_host::record`]): the bytes as a file,
//! its format found from the content as `triad` finds it, read to the end.
//! Invariants: no panic (a reader thread's panic, which `triad` turns into
//! an error for the user, is a crash here), every error names the file,
//! every sample is finite-timed and within the time check's order, and
//! the samples' places (line or message) increase.

use std::io::Write;
use std::path::{Path, PathBuf};

use triad_host::record::{self, Options};

/// The name a fuzzed file has in messages (`acc…`: an imu_tk file reads as the accelerometer).
const NAME: &str = "acc_fuzzed";

/// A file of this process for the input (on /dev/shm where there is one:
/// AFL runs thousands of inputs a second).
fn scratch(extension: &str) -> PathBuf {
    let dir = Path::new("/dev/shm");
    let dir = if dir.is_dir() {
        dir.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    dir.join(format!(
        "triad-fuzz-{}-{NAME}.{extension}",
        std::process::id()
    ))
}

/// Reads `bytes` as a recording of any format (found from the content);
/// the samples read (None: refused).
pub fn record(bytes: &[u8]) -> Option<u64> {
    read_as(bytes, "rec")
}

/// Reads `bytes` as triad's CSV (`t,ax,…`): the extension says CSV.
pub fn triad_csv(bytes: &[u8]) -> Option<u64> {
    read_as(bytes, "csv")
}

fn read_as(bytes: &[u8], extension: &str) -> Option<u64> {
    let path = scratch(extension);
    let written = std::fs::File::create(&path).and_then(|mut f| f.write_all(bytes));
    // Not a parser's fault (a full /dev/shm): no verdict.
    written.ok()?;
    let read = check(&path);
    let _ = std::fs::remove_file(&path);
    read
}

/// Opens and reads the file at `path` to its end, checking each chunk;
/// the samples read (None: refused, with a message that passed).
fn check(path: &Path) -> Option<u64> {
    let shown = path.display().to_string();
    let opened = match record::open(path, &Options::default()) {
        Ok(o) => o,
        Err(e) => {
            refused(&shown, &e);
            return None;
        }
    };
    let mut reader = opened.reader;
    let (mut last_at, mut samples) = (0u64, 0u64);
    loop {
        match reader.next_chunk() {
            Ok(Some(chunk)) => {
                assert!(!chunk.is_empty(), "an empty chunk");
                for s in &chunk {
                    assert!(s.t.is_finite(), "a sample at t = {} passed", s.t);
                    assert!(s.at > last_at, "places go back: {} after {last_at}", s.at);
                    last_at = s.at;
                }
                samples += chunk.len() as u64;
            }
            Ok(None) => return Some(samples),
            Err(e) => {
                refused(&shown, &e);
                return None;
            }
        }
    }
}

/// A refusal: a message naming the file, and not a library's panic.
fn refused(shown: &str, e: &anyhow::Error) {
    let message = format!("{e:#}");
    assert!(
        !message.contains("failed on this file with an internal error"),
        "a reader's library panicked: {message}"
    );
    assert!(
        message.contains(shown),
        "an error without the file's name: {message}"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every seed (valid files of each format, and their cuts) passes;
    /// the whole seeds read their samples (the cut ULog is read up to its cut).
    #[test]
    fn the_seeds_and_their_cuts_pass() {
        let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds/record");
        let mut read = Vec::new();
        for entry in std::fs::read_dir(&seeds).unwrap() {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if !name.ends_with(".ulg") {
                read.push((name, record(&bytes)));
            }
            for keep in [bytes.len() * 2 / 3, bytes.len() / 3, 17, 0] {
                record(&bytes[..keep]);
                triad_csv(&bytes[..keep]);
            }
        }
        read.sort();
        let want = [
            ("euroc3.csv", 3),
            ("imu.bag", 200),
            ("imu.db3", 200),
            ("imu20.csv", 20),
            ("imu20.mcap", 20),
            ("imu_tk3.txt", 3),
        ];
        let want: Vec<(String, Option<u64>)> = want
            .iter()
            .map(|(n, k)| (n.to_string(), Some(*k)))
            .collect();
        assert_eq!(read, want);
    }
}
