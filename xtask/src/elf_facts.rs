//! Facts xtask reads from the firmware it built instead of restating them:
//! the firmware exports each as a `#[no_mangle]` static (firmware/src/main.rs).

use anyhow::{bail, Context, Result};
use object::{Object, ObjectSection, ObjectSymbol};
use std::path::Path;

/// The link's baud rate: the board's description, as the firmware holds it
/// (symbol `TRIAD_LINK_BAUD`, a little-endian u32).
pub fn link_baud(elf: &Path) -> Result<u32> {
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    read_u32(&bytes, "TRIAD_LINK_BAUD").with_context(|| format!("in {}", elf.display()))
}

fn read_u32(elf: &[u8], name: &str) -> Result<u32> {
    let file = object::File::parse(elf).context("parsing the firmware ELF")?;
    let Some(symbol) = file.symbols().find(|s| s.name() == Ok(name)) else {
        bail!("no symbol {name}: the firmware exports it");
    };
    let section = symbol
        .section_index()
        .and_then(|i| file.section_by_index(i).ok())
        .with_context(|| format!("symbol {name} has no section"))?;
    let data = section.data().context("reading the section")?;
    let start = usize::try_from(symbol.address() - section.address())?;
    let word = data
        .get(start..start + 4)
        .with_context(|| format!("symbol {name} lies outside its section"))?;
    Ok(u32::from_le_bytes(word.try_into()?))
}
