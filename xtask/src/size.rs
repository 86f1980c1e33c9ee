//! `cargo xtask size`: the flash and RAM of each firmware build, per board
//! and per bus (release, the default calibration and sampling settings),
//! against each board's memory map; writes docs/FIRMWARE_SIZE.md and prints
//! the table.

use crate::board::{Board, Bus, Firmware, Sampling};
use crate::cmd::{self, root};
use anyhow::{bail, Context, Result};
use object::{Object, ObjectSection};
use std::path::Path;
use triad::sensor::CHIP_NAMES;

/// Where the table goes.
const REPORT: &str = "docs/FIRMWARE_SIZE.md";

/// What a firmware ELF occupies, bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Footprint {
    /// Flash: the vector table, code, read-only data and `.data`'s initial image.
    pub flash: u64,
    /// RAM set aside at link time: `.data`, `.bss` and `.uninit` (the stack
    /// takes what is left, and is not counted).
    pub ram: u64,
}

/// Flash and RAM of the ELF at `elf`, from cortex-m-rt's output sections.
pub fn footprint(elf: &Path) -> Result<Footprint> {
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file =
        object::File::parse(&*bytes).with_context(|| format!("parsing {}", elf.display()))?;
    let size = |name: &str| file.section_by_name(name).map_or(0, |s| s.size());
    if size(".text") == 0 {
        bail!("{}: no .text section: not a firmware ELF", elf.display());
    }
    Ok(Footprint {
        flash: size(".vector_table") + size(".text") + size(".rodata") + size(".data"),
        ram: size(".data") + size(".bss") + size(".uninit"),
    })
}

/// The FLASH and RAM lengths (bytes) in the board's memory.x.
pub fn memory_map(board: Board) -> Result<(u64, u64)> {
    let path = root().join("boards").join(board.name()).join("memory.x");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let length = |region: &str| -> Result<u64> {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(region) && l.contains("LENGTH"))
            .with_context(|| format!("{}: no {region} region", path.display()))?;
        let value = line
            .split("LENGTH")
            .nth(1)
            .and_then(|v| v.split('=').nth(1))
            .map(str::trim)
            .with_context(|| format!("{}: {line:?}: no LENGTH value", path.display()))?;
        parse_length(value).with_context(|| format!("{}: {line:?}", path.display()))
    };
    Ok((length("FLASH")?, length("RAM")?))
}

/// A linker-script length: `256K`, `1M`, `0x40000` or decimal bytes.
fn parse_length(text: &str) -> Result<u64> {
    let (digits, scale) = match text.strip_suffix(['K', 'k']) {
        Some(d) => (d, 1024),
        None => match text.strip_suffix(['M', 'm']) {
            Some(d) => (d, 1024 * 1024),
            None => (text, 1),
        },
    };
    let value = match digits.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => digits.parse(),
    }
    .with_context(|| format!("{text:?} is not a length"))?;
    Ok(value * scale)
}

/// Builds every board with every bus and writes the table.
pub fn run() -> Result<()> {
    let calibration = root().join("calibrations/default.bin");
    let mut rows = Vec::new();
    for &board in Board::all() {
        crate::setup::ensure_for(board)?;
        let (flash_len, ram_len) = memory_map(board)?;
        for bus in Bus::ALL {
            let firmware = Firmware {
                board,
                bus,
                emulated_chip: board.is_emulated().then_some(CHIP_NAMES[0]),
                sampling: Sampling::default(),
            };
            let elf = cmd::build_firmware(firmware, &calibration)?;
            let used = footprint(&elf)?;
            rows.push(row(board, bus, used, (flash_len, ram_len)));
        }
    }
    let report = format!(
        "# Firmware size\n\n\
         Written by `cargo xtask size`: each board with each bus, built as \
         `cargo xtask run` builds it (release, the default calibration and \
         sampling settings; the emulated board with its first chip model, \
         {chip}). Flash: the vector table, code, read-only data and the \
         initial image of `.data`; RAM: `.data`, `.bss` and `.uninit`, set \
         aside at link time (the stack takes the rest). The share is of the \
         region in the board's memory.x (the NUCLEO's program region is the \
         256 KiB below the calibration's sectors).\n\n\
         | board | bus | flash, bytes | of the board's | RAM, bytes | of the board's |\n\
         |-------|-----|-------------:|---------------:|-----------:|---------------:|\n\
         {rows}\n",
        chip = CHIP_NAMES[0],
        rows = rows.join("\n")
    );
    print!("{report}");
    let path = root().join(REPORT);
    std::fs::write(&path, &report).with_context(|| format!("writing {}", path.display()))?;
    note!("xtask: wrote {}", path.display());
    Ok(())
}

/// One table row.
fn row(board: Board, bus: Bus, used: Footprint, (flash_len, ram_len): (u64, u64)) -> String {
    let share = |used: u64, of: u64| {
        format!(
            "{:.1} % of {} KiB",
            100.0 * used as f64 / of as f64,
            of / 1024
        )
    };
    format!(
        "| {} | {} | {} | {} | {} | {} |",
        board.name(),
        bus.name(),
        used.flash,
        share(used.flash, flash_len),
        used.ram,
        share(used.ram, ram_len)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linker_lengths_read_as_the_linker_reads_them() {
        assert_eq!(parse_length("256K").unwrap(), 256 * 1024);
        assert_eq!(parse_length("1M").unwrap(), 1024 * 1024);
        assert_eq!(parse_length("0x400").unwrap(), 1024);
        assert_eq!(parse_length("96").unwrap(), 96);
        assert!(parse_length("lots").is_err());
    }

    #[test]
    fn each_board_s_memory_map_is_read() {
        let nucleo = Board::parse("nucleo-f401re").unwrap();
        assert_eq!(memory_map(nucleo).unwrap(), (256 * 1024, 96 * 1024));
        assert_eq!(
            memory_map(Board::emulated()).unwrap(),
            (1024 * 1024, 128 * 1024)
        );
    }

    #[test]
    fn a_file_that_is_not_a_firmware_elf_is_refused() {
        let path = std::env::temp_dir().join(format!("xtask-size-{}.elf", std::process::id()));
        std::fs::write(&path, b"not an ELF").unwrap();
        let error = footprint(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(format!("{error:#}").contains("parsing"), "{error:#}");
    }
}
