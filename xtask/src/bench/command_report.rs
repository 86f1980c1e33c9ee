//! docs/BENCHMARKS.md's "Command handling" section: what each command costs
//! the `link` task, the longest of them (how long the task keeps frames
//! waiting), what the flash's own time adds on the NUCLEO, and the flash's
//! wear, all from the measured rows and the RAM flash's counters.

use super::commands::CommandRow;
use super::Core;
use anyhow::{Context, Result};
use std::fmt::Write;
use triad_bench::command_handling::{
    save_wear, BenchCommand, LINK_BAUD, REPETITIONS, UPLOAD_CHUNKS,
};
use triad_bench::ram_flash::{ERASE_SIZE, UNITS};

/// The NUCLEO's core clock (boards/nucleo-f401re/README.md).
const NUCLEO_HZ: f64 = 84e6;

/// The STM32F401's flash (data sheet DS10086, "Flash memory programming",
/// as boards/nucleo-f401re/README.md states it): a 128 KiB sector erase at
/// x32 parallelism, typical and maximum, seconds.
const SECTOR_ERASE_S: (f64, f64) = (1.0, 2.0);
/// Programming one byte (the NUCLEO's `Flash` writes bytes), typical and
/// maximum, seconds.
const BYTE_PROGRAM_S: (f64, f64) = (16e-6, 100e-6);
/// Erase cycles a sector endures (DS10086, N_END).
const ENDURANCE_CYCLES: f64 = 10_000.0;
/// Saves the wear count runs.
const WEAR_SAVES: u16 = 10;

fn row(rows: &[CommandRow], core: Core, command: BenchCommand) -> Option<&CommandRow> {
    rows.iter().find(|r| r.core == core && r.command == command)
}

/// Seconds the NUCLEO's flash itself takes for a row's operations (typical, maximum).
fn flash_time_s(r: &CommandRow) -> (f64, f64) {
    let time = |erase: f64, byte: f64| r.erases * erase + r.bytes_written * byte;
    (
        time(SECTOR_ERASE_S.0, BYTE_PROGRAM_S.0),
        time(SECTOR_ERASE_S.1, BYTE_PROGRAM_S.1),
    )
}

/// Seconds `bytes` take on the link (8N1: 10 bit times each).
fn wire_s(bytes: f64) -> f64 {
    bytes * 10.0 / f64::from(LINK_BAUD)
}

fn ops_cell(r: &CommandRow) -> String {
    if r.erases == 0.0 && r.writes == 0.0 && r.reads == 0.0 {
        return "–".into();
    }
    format!(
        "{} erase, {} write ({} B), {} read ({} B)",
        r.erases, r.writes, r.bytes_written, r.reads, r.bytes_read
    )
}

/// The section.
pub fn section(md: &mut String, rows: &[CommandRow]) -> Result<()> {
    writeln!(md, "## Command handling\n")?;
    writeln!(
        md,
        "{}",
        METHOD
            .replace("{REPETITIONS}", &REPETITIONS.to_string())
            .replace("{CHUNK_RUNS}", &(REPETITIONS * UPLOAD_CHUNKS).to_string())
            .replace("{ERASE_SIZE}", &ERASE_SIZE.to_string())
    )?;
    writeln!(
        md,
        "| command | wire bytes in / out | flash operations | Cortex-M4F instr. | Cortex-M0 instr. | stack bytes M4F / M0 | reply on the link at {LINK_BAUD} baud | NUCLEO flash time, typ / max |"
    )?;
    writeln!(md, "|---|---:|---|---:|---:|---:|---:|---:|")?;
    for command in BenchCommand::ALL {
        let Some(m4) = row(rows, Core::CortexM4F, command) else {
            continue;
        };
        let m0 = row(rows, Core::CortexM0, command);
        let (typ, max) = flash_time_s(m4);
        let flash = if typ > 0.0 {
            format!("{typ:.2} s / {max:.2} s")
        } else {
            "–".into()
        };
        writeln!(
            md,
            "| {} | {} / {} | {} | {:.0} | {} | {} / {} | {:.0} µs | {flash} |",
            command.name(),
            m4.command_bytes,
            m4.reply_bytes,
            ops_cell(m4),
            m4.instructions,
            m0.map_or("–".into(), |r| format!("{:.0}", r.instructions)),
            m4.stack_bytes,
            m0.map_or("–".into(), |r| r.stack_bytes.to_string()),
            wire_s(m4.reply_bytes) * 1e6
        )?;
    }
    writeln!(md)?;
    stretch(md, rows)?;
    wear(md, rows)?;
    Ok(())
}

/// The longest command at the link task's priority, and what it delays.
fn stretch(md: &mut String, rows: &[CommandRow]) -> Result<()> {
    let longest = |core| {
        rows.iter()
            .filter(|r| r.core == core)
            .max_by(|a, b| a.instructions.total_cmp(&b.instructions))
    };
    let m4 = longest(Core::CortexM4F).context("no Cortex-M4F command rows")?;
    let longest_reply = rows
        .iter()
        .filter(|r| r.core == Core::CortexM4F)
        .max_by(|a, b| a.reply_bytes.total_cmp(&b.reply_bytes))
        .context("no Cortex-M4F command rows")?;
    writeln!(
        md,
        "- Worst-case stretch at the `link` task's priority (1): **{}**, {:.0} instructions on the Cortex-M4F, **{:.0} µs** at the NUCLEO's 84 MHz if one instruction took one cycle. That is an optimistic bound: on silicon loads and stores take two cycles, taken branches up to four, integer divides up to twelve (the commit's f64 arithmetic is software floating point on this single-precision FPU), and the flash adds wait states (2 at 84 MHz) to the fetches its ART accelerator misses. For that long the task keeps queued frames (and the replies to later commands) waiting.",
        m4.command.name(),
        m4.instructions,
        m4.instructions / NUCLEO_HZ * 1e6
    )?;
    if let Some(m0) = longest(Core::CortexM0) {
        writeln!(
            md,
            "- On the Cortex-M0 (no FPU: every float operation is a library call) the longest is {}, {:.0} instructions; the command benchmark fits its 16 KiB of RAM, the device's state (handler, decoder, RAM flash) beside the handler's stack.",
            m0.command.name(),
            m0.instructions
        )?;
    }
    let m4_rows = || rows.iter().filter(|r| r.core == Core::CortexM4F);
    let deepest = m4_rows()
        .max_by_key(|r| r.stack_bytes)
        .context("no Cortex-M4F command rows")?;
    let shallowest = m4_rows().map(|r| r.stack_bytes).min().unwrap_or(0);
    writeln!(
        md,
        "- Stack: {} goes deepest, {} bytes below the caller on the Cortex-M4F, and no command takes less than {shallowest} (no packet or reply is copied on the way: the command is read where it lies, its reply written where it is kept and encoded from there; the commands that hold more on the stack, identify, the upload's commit, read-back, save and erase, run in frames of their own). The command task's share of the firmware's one stack must hold that, with the data-ready and receive tasks' frames nested on it.",
        deepest.command.name(),
        deepest.stack_bytes
    )?;
    writeln!(
        md,
        "- The task then queues the reply whole in the transmit queue (`LinkTx::queue`; the USART's interrupt or DMA sends it): the longest reply, {}'s {:.0} bytes, holds the line for {:.0} µs at {LINK_BAUD} baud, which is the link's time, not the CPU's, but frames queued behind the reply wait for it.",
        longest_reply.command.name(),
        longest_reply.reply_bytes,
        wire_s(longest_reply.reply_bytes) * 1e6
    )?;
    writeln!(
        md,
        "- The data-ready task (priority 2) preempts the `link` task, so none of this delays a sample, with one exception on the NUCLEO: its flash has a single bank, and while it erases or programs, the CPU stalls on every fetch, interrupts included (RM0368, \"Erase and program operations\"). A save or an erase therefore pauses sampling for the flash time in the table's last column (data-ready edges in the meantime are lost and the next frame says OVERRUN; boards/nucleo-f401re/README.md)."
    )?;
    Ok(())
}

/// "once", "twice", "N times".
fn times(n: f64) -> String {
    if n == 1.0 {
        "once".into()
    } else if n == 2.0 {
        "twice".into()
    } else {
        format!("{n} times")
    }
}

/// Erases per save and per erase command, and saves until a sector wears out.
fn wear(md: &mut String, rows: &[CommandRow]) -> Result<()> {
    let save = row(rows, Core::CortexM4F, BenchCommand::Save).context("no save row")?;
    let erase = row(rows, Core::CortexM4F, BenchCommand::Erase).context("no erase row")?;
    let units = save_wear(WEAR_SAVES)
        .map_err(|e| anyhow::anyhow!("counting the erases of {WEAR_SAVES} saves: {e:?}"))?;
    let most = f64::from(units.iter().copied().max().unwrap_or(0));
    if most == 0.0 {
        anyhow::bail!("{WEAR_SAVES} saves erased no flash unit: the store did not save");
    }
    let wear_per_save = most / f64::from(WEAR_SAVES);
    let erase_per_unit = erase.erases / UNITS as f64;
    writeln!(
        md,
        "- Flash wear, counted by the RAM flash: a save erases **{}** sector (the slot not holding the newest record), an `erase` command **{}** (both). {WEAR_SAVES} saves from an empty store erased the two sectors {:?} times: the slots alternate, so each sector is erased once per {:.0} saves, and at the data sheet's {ENDURANCE_CYCLES:.0} erase cycles per sector (DS10086, N_END) a sector wears out after **{:.0} saves**. Each `erase` command erases each sector {}: the wear of {:.0} saves.\n",
        save.erases,
        erase.erases,
        units,
        1.0 / wear_per_save,
        ENDURANCE_CYCLES / wear_per_save,
        times(erase_per_unit),
        erase_per_unit / wear_per_save
    )?;
    Ok(())
}

const METHOD: &str = "\
The firmware's command task (priority 1, below the data-ready task) runs,
for each command, the receive decoder over the command's wire bytes
(`Decoder::push_command`: the command read where it lies in the decoder's
buffer), `CommandHandler::answer_received` (the reply's payload written in
place into the reply the handler keeps), and that reply's encoding straight
to wire bytes (`Reply::to_wire`, into the transmitter's reply slot on the
device): each row counts those,
on the NUCLEO's device facts and the benchmark's ICM-42688-P scale
(`bench/src/command_handling.rs`). Each figure is the mean of {REPETITIONS} runs
({CHUNK_RUNS} for the upload chunk: each of the blob's chunks is timed), every run on a device
started afresh whose flash holds two records, so that a save reads and
checks both slots (its longest case). The upload is the calibration with
temperature terms, so its commit (CRC, blob decode, `Corrector::new` with the
temperature validation, `FixedCorrector::new`, the new corrector queued for
the data-ready task) is the longest validation an upload costs. `bad_crc` is
an identify whose CRC byte was changed.

The flash is RAM (`bench/src/ram_flash.rs`: two erase units of one
{ERASE_SIZE}-byte record each, one per slot as the NUCLEO's 128 KiB sectors, byte
writes as on the NUCLEO) that counts its operations; its instructions
(filling a unit with 0xFF, copying bytes) stand in for the driver's, and
the flash's own erase and programming time is the hardware's: the last
column gives the NUCLEO's from the counts and the data sheet (DS10086,
boards/nucleo-f401re/README.md: a 128 KiB sector erase typ 1 s, max 2 s;
a byte programmed typ 16 µs, max 100 µs). Every reply's bytes and every
flash count are checked against the host's run of the same commands.
SysTick's resolution is one tick: 6 instructions on the Cortex-M4F, 62.5
on the Cortex-M0, for each run of the mean.
";
