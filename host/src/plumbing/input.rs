//! Opening a CSV input: a file, or standard input for `-`; a UTF-8
//! byte-order mark (as some spreadsheet exports write) is not part of the
//! first column's name. A recording in another format (a bag, a ULog,
//! EuRoC, imu_tk: see [`crate::record`]) is read as the CSV of its samples
//! (`t,ax,ay,az,gx,gy,gz[,temp]`, SI, every number exact), so every command
//! that reads CSV reads them; its name in messages then says so, and a
//! "line" there is the header (1) or a sample (2 on).

use std::fs::File;
use std::io::{self, BufRead, BufReader};
use std::path::Path;

use anyhow::Context;

use crate::record;

/// An opened input.
pub struct Input {
    /// For messages: the path, or `stdin`.
    pub name: String,
    /// The bytes.
    pub reader: Box<dyn BufRead + Send>,
    /// Its size in bytes (0 when unknown: standard input).
    pub size: u64,
}

/// True when `path` means standard input (`-`).
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The name of `path` in messages: `stdin` for `-`.
pub fn name(path: &Path) -> String {
    if is_stdin(path) {
        "stdin".to_string()
    } else {
        path.display().to_string()
    }
}

/// Opens `path` (`-`: standard input) with a `capacity`-byte buffer; a
/// recording in another format than triad's CSV is read as its CSV.
pub fn open(path: &Path, capacity: usize) -> anyhow::Result<Input> {
    if !is_stdin(path) {
        if let Some(record) = foreign_record(path, capacity)? {
            return Ok(record);
        }
    }
    open_bytes(path, capacity)
}

/// Opens `path` (`-`: standard input) as it is, with a `capacity`-byte buffer.
pub fn open_bytes(path: &Path, capacity: usize) -> anyhow::Result<Input> {
    let name = name(path);
    if is_stdin(path) {
        return Ok(Input {
            name,
            reader: Box::new(BufReader::with_capacity(capacity, io::stdin())),
            size: 0,
        });
    }
    let file = File::open(path).with_context(|| format!("{name}: cannot open"))?;
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    Ok(Input {
        name,
        reader: Box::new(BufReader::with_capacity(capacity, file)),
        size,
    })
}

/// A recording at `path` that is not triad's CSV (a regular file or a bag
/// directory; FIFOs and devices are not looked into), as a CSV stream.
fn foreign_record(path: &Path, capacity: usize) -> anyhow::Result<Option<Input>> {
    if !is_foreign_record(path)? {
        return Ok(None);
    }
    let opened = record::open(path, &record::options::global())?;
    let name = format!(
        "{} (read as CSV from {})",
        name(path),
        opened.source.format.name()
    );
    Ok(Some(Input {
        name,
        reader: Box::new(BufReader::with_capacity(
            capacity,
            record::to_csv::CsvStream::new(opened),
        )),
        size: 0,
    }))
}

/// True when `path` is a recording that is not triad's CSV: a regular file
/// or a bag directory whose content says so (FIFOs, devices and standard
/// input are read as CSV, not looked into).
pub fn is_foreign_record(path: &Path) -> anyhow::Result<bool> {
    if is_stdin(path) {
        return Ok(false);
    }
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(false);
    };
    Ok(
        (meta.is_file() || meta.is_dir())
            && record::detect::detect(path)?.is_container_or_foreign(),
    )
}

/// The UTF-8 byte-order mark.
const BOM: &str = "\u{feff}";

/// `line` without a leading byte-order mark.
pub fn strip_bom(line: &str) -> &str {
    line.strip_prefix(BOM).unwrap_or(line)
}

/// `line` without a leading byte-order mark (bytes).
pub fn strip_bom_bytes(line: &[u8]) -> &[u8] {
    line.strip_prefix(BOM.as_bytes()).unwrap_or(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_dropped_and_dash_is_stdin() {
        assert_eq!(strip_bom("\u{feff}t,ax"), "t,ax");
        assert_eq!(strip_bom("t,ax"), "t,ax");
        assert_eq!(strip_bom_bytes(b"\xef\xbb\xbft"), b"t");
        assert_eq!(name(Path::new("-")), "stdin");
        assert_eq!(name(Path::new("a.csv")), "a.csv");
        let err = open(Path::new("/no/such.csv"), 16).err().unwrap();
        assert!(err.to_string().starts_with("/no/such.csv: cannot open"));
    }
}
