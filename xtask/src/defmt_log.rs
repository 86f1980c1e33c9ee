//! The firmware's defmt log: binary frames on QEMU's stdout (semihosting),
//! decoded with the ELF's format table and printed on stderr.

use std::io::Read;

/// Decodes the defmt stream from `log` until it closes.
pub fn print(elf: &[u8], mut log: impl Read) {
    let table = match defmt_decoder::Table::parse(elf) {
        Ok(Some(table)) => table,
        Ok(None) => return eprintln!("firmware: the ELF has no defmt table; log not shown"),
        Err(error) => return eprintln!("firmware: cannot read the defmt table: {error}"),
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
                Ok(frame) => eprintln!("firmware: {}", frame.display(false)),
                Err(defmt_decoder::DecodeError::UnexpectedEof) => break,
                Err(defmt_decoder::DecodeError::Malformed) => {
                    eprintln!("firmware: malformed defmt frame skipped");
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
