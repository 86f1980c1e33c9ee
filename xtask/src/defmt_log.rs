//! The firmware's defmt log: binary frames on QEMU's stdout (semihosting),
//! decoded with the ELF's format table and printed on stderr.

use std::io::Read;

/// Decodes the defmt stream from `log` until it closes, printing each line.
pub fn print(elf: &[u8], log: impl Read) {
    each_line(elf, log, |line| note!("firmware: {line}"));
}

/// Decodes the defmt stream from `log` until it closes; returns its lines
/// (and prints them, as [`print`] does).
pub fn collect(elf: &[u8], log: impl Read) -> Vec<String> {
    let mut lines = Vec::new();
    each_line(elf, log, |line| {
        note!("firmware: {line}");
        lines.push(line);
    });
    lines
}

/// Calls `line` with each decoded log line of `log` until it closes.
fn each_line(elf: &[u8], mut log: impl Read, mut line: impl FnMut(String)) {
    let table = match defmt_decoder::Table::parse(elf) {
        Ok(Some(table)) => table,
        Ok(None) => return note!("firmware: the ELF has no defmt table; log not shown"),
        Err(error) => return note!("firmware: cannot read the defmt table: {error}"),
    };
    let mut decoder = table.new_stream_decoder();
    let mut buffer = [0u8; 1024];
    loop {
        let n = match log.read(&mut buffer) {
            Ok(0) | Err(_) => return,
            Ok(n) => n,
        };
        decoder.received(&buffer[..n]);
        loop {
            match decoder.decode() {
                Ok(frame) => line(frame.display(false).to_string()),
                Err(defmt_decoder::DecodeError::UnexpectedEof) => break,
                Err(defmt_decoder::DecodeError::Malformed) => {
                    note!("firmware: malformed defmt frame skipped");
                    break;
                }
            }
        }
    }
}

/// Decodes a captured log file.
pub fn print_file(elf: &std::path::Path, log: &std::path::Path) -> anyhow::Result<()> {
    use anyhow::Context;
    let elf = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let log = std::fs::File::open(log).with_context(|| format!("opening {}", log.display()))?;
    print(&elf, log);
    Ok(())
}
