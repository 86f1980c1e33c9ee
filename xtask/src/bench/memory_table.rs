//! Flash and RAM of each firmware build (each board with each bus, the
//! emulated board with its default chip model): from the release ELF's
//! sections, against the regions of the board's memory.x.

use std::fmt::Write;
use std::path::Path;

use anyhow::{Context, Result};
use object::{Object, ObjectSection, SectionKind};

use crate::board::{Board, Bus, Firmware};
use crate::cmd;

/// Where the STM32's flash and SRAM are mapped (RM0368 §2.3, RM0090 §2.3).
const FLASH_BASE: u64 = 0x0800_0000;
const RAM_BASE: u64 = 0x2000_0000;
const RAM_END: u64 = 0x4000_0000;

/// One build's memory.
#[derive(Clone, Debug)]
pub struct MemoryRow {
    /// The build's label (board, chip model, bus).
    pub label: String,
    /// Bytes programmed into flash: code, read-only data, vector table and
    /// the initial values of `.data`.
    pub flash: u64,
    /// Bytes of RAM the statics take (`.data`, `.bss`, `.uninit`); the stack
    /// has the rest of the region.
    pub ram: u64,
    /// The board's program flash region, bytes (its memory.x).
    pub flash_region: u64,
    /// The board's RAM region, bytes.
    pub ram_region: u64,
}

/// Flash and RAM from the ELF's allocated sections: a section mapped in
/// flash counts there, a section in RAM counts there, and one in RAM with
/// contents (`.data`) counts in flash too (its initial values are copied
/// from flash at reset).
fn measure_elf(elf: &[u8]) -> Result<(u64, u64)> {
    let file = object::File::parse(elf).context("parsing the firmware ELF")?;
    let (mut flash, mut ram) = (0, 0);
    for section in file.sections() {
        let (address, size) = (section.address(), section.size());
        let in_ram = (RAM_BASE..RAM_END).contains(&address);
        let kind = section.kind();
        if matches!(
            kind,
            SectionKind::Metadata
                | SectionKind::Debug
                | SectionKind::Other
                | SectionKind::OtherString
                | SectionKind::Note
                | SectionKind::Unknown
                | SectionKind::Linker
        ) || size == 0
        {
            continue;
        }
        if in_ram {
            ram += size;
            if !matches!(kind, SectionKind::UninitializedData) {
                flash += size;
            }
        } else if (FLASH_BASE..RAM_BASE).contains(&address) {
            flash += size;
        }
    }
    Ok((flash, ram))
}

/// The FLASH and RAM regions' lengths in a memory.x, bytes.
fn regions(memory_x: &str) -> Option<(u64, u64)> {
    let length = |region: &str| {
        let line = memory_x
            .lines()
            .find(|l| l.trim_start().starts_with(region) && l.contains("LENGTH"))?;
        let value = line.split("LENGTH").nth(1)?.trim_start_matches([' ', '=']);
        let value = value.trim().trim_end_matches(',');
        match value.strip_suffix('K') {
            Some(k) => k.trim().parse::<u64>().ok().map(|k| k * 1024),
            None => value.parse().ok(),
        }
    };
    Some((length("FLASH")?, length("RAM")?))
}

/// Builds every board with every bus and measures each.
pub fn measure(calibration: &Path) -> Result<Vec<MemoryRow>> {
    let mut rows = Vec::new();
    for board in Board::ALL {
        let memory_x = cmd::root()
            .join("boards")
            .join(board.name())
            .join("memory.x");
        let text = std::fs::read_to_string(&memory_x)
            .with_context(|| format!("reading {}", memory_x.display()))?;
        let (flash_region, ram_region) = regions(&text)
            .with_context(|| format!("{}: no FLASH and RAM LENGTH", memory_x.display()))?;
        for bus in Bus::ALL {
            let firmware = Firmware::all()
                .find(|f| f.board == board && f.bus == bus)
                .with_context(|| format!("no build of {} on {}", board.name(), bus.name()))?;
            let elf = cmd::build_firmware(firmware, calibration)?;
            let bytes =
                std::fs::read(&elf).with_context(|| format!("reading {}", elf.display()))?;
            let (flash, ram) = measure_elf(&bytes)?;
            rows.push(MemoryRow {
                label: firmware.label(),
                flash,
                ram,
                flash_region,
                ram_region,
            });
        }
    }
    Ok(rows)
}

/// The section of docs/BENCHMARKS.md.
pub fn markdown(rows: &[MemoryRow]) -> String {
    let mut md = String::from(
        "## Flash and RAM of each build\n\n\
         Each board with each bus, release (the firmware's profile), the emulated board \
         with its default chip model, whose simulation is in the build (no hardware build \
         carries one). Flash: code, read-only data, the vector table and `.data`'s initial \
         values; RAM: the statics (`.data`, `.bss`, `.uninit`), the stack having the rest \
         of the board's RAM region. Regions as in each board's memory.x (the NUCLEO's \
         program region stops below the calibration's sectors).\n\n\
         | build | flash bytes | of the program region | RAM bytes (statics) | of RAM | left for the stack |\n\
         |---|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.1} % of {} KiB | {} | {:.1} % of {} KiB | {} |",
            r.label,
            r.flash,
            100.0 * r.flash as f64 / r.flash_region as f64,
            r.flash_region / 1024,
            r.ram,
            100.0 * r.ram as f64 / r.ram_region as f64,
            r.ram_region / 1024,
            r.ram_region.saturating_sub(r.ram)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_regions_read_from_a_memory_x() {
        let text = "MEMORY\n{\n  FLASH : ORIGIN = 0x08000000, LENGTH = 256K\n  RAM   : ORIGIN = 0x20000000, LENGTH = 96K\n}\n";
        assert_eq!(regions(text), Some((256 * 1024, 96 * 1024)));
        assert_eq!(regions("MEMORY { }"), None);
    }
}
