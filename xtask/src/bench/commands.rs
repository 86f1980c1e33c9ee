//! The command-handling rows: the benchmark firmware's `command …` lines,
//! each checked against the host's run of the same commands (the replies'
//! bytes, bit for bit, and the flash's operations), turned into
//! instructions per command.

use anyhow::{bail, Context, Result};
use triad_bench::command_handling::{
    run_commands, BenchCommand, CommandStats, COMMANDS, COUNT_KEYS,
};
use triad_bench::kernels::NoMeter;

use super::cores::{digest, field, number, Core};

/// One command on one core, per command (the runs' mean).
#[derive(Clone, Debug)]
pub struct CommandRow {
    pub core: Core,
    pub command: BenchCommand,
    pub instructions: f64,
    pub stack_bytes: u64,
    /// Erase units erased.
    pub erases: f64,
    /// Flash write calls and bytes programmed.
    pub writes: f64,
    pub bytes_written: f64,
    /// Flash read calls and bytes read.
    pub reads: f64,
    pub bytes_read: f64,
    /// Wire bytes of the command and of its reply.
    pub command_bytes: f64,
    pub reply_bytes: f64,
}

/// What the firmware printed for one row.
struct CommandLine {
    command: BenchCommand,
    runs: u64,
    ticks: u64,
    overhead: u64,
    stack: u64,
    digest: u64,
    wrong: u64,
    /// The counts of `COUNT_KEYS`, in its order.
    counts: [u64; 7],
}

fn parse(line: &str) -> Result<CommandLine> {
    let name = field(line, "name")?;
    let mut counts = [0; 7];
    for (c, key) in counts.iter_mut().zip(COUNT_KEYS) {
        *c = number(line, key)?;
    }
    Ok(CommandLine {
        command: BenchCommand::from_name(name)
            .with_context(|| format!("unknown command row {name:?} in {line:?}"))?,
        runs: number(line, "runs")?,
        ticks: number(line, "ticks")?,
        overhead: number(line, "overhead")?,
        stack: number(line, "stack")?,
        digest: digest(line, "digest")?,
        wrong: number(line, "wrong")?,
        counts,
    })
}

/// The command rows of a run on `core`, checked: every reply as expected,
/// the replies' bytes and the flash's operations equal to the host's.
pub fn measure(core: Core, stdout: &str) -> Result<Vec<CommandRow>> {
    let lines: Vec<CommandLine> = stdout
        .lines()
        .filter(|l| l.starts_with("command "))
        .map(parse)
        .collect::<Result<_>>()?;
    if lines.len() != COMMANDS {
        bail!(
            "the benchmark on {} printed {} command rows, expected {COMMANDS}:\n{stdout}",
            core.name(),
            lines.len()
        );
    }
    let mut host = [CommandStats::default(); COMMANDS];
    run_commands(&mut [(); COMMANDS].map(|_| NoMeter), &mut host)
        .map_err(|e| anyhow::anyhow!("the host's command benchmark: {e:?}"))?;
    lines
        .iter()
        .map(|l| {
            let h = BenchCommand::ALL
                .iter()
                .position(|&c| c == l.command)
                .and_then(|at| host.get(at))
                .context("a command row the host does not run")?;
            let name = l.command.name();
            if l.wrong != 0 {
                bail!(
                    "{name} on {}: {} of {} replies were not the expected {} reply",
                    core.name(),
                    l.wrong,
                    l.runs,
                    l.command.expected_status()
                );
            }
            if l.digest != h.digest.value() || l.runs != u64::from(h.runs) {
                bail!(
                    "{name} on {}: the firmware's replies differ from the host's (digest {:#018x} over {} runs vs {:#018x} over {})",
                    core.name(),
                    l.digest,
                    l.runs,
                    h.digest.value(),
                    h.runs
                );
            }
            if l.counts != h.counts().map(u64::from) {
                bail!(
                    "{name} on {}: the firmware's flash operations and wire bytes {:?} differ from the host's {:?} ({COUNT_KEYS:?})",
                    core.name(),
                    l.counts,
                    h.counts().map(u64::from)
                );
            }
            let runs = l.runs.max(1) as f64;
            let ticks = l.ticks.saturating_sub(l.overhead * l.runs);
            let per_run = |i: usize| l.counts[i] as f64 / runs;
            Ok(CommandRow {
                core,
                command: l.command,
                instructions: ticks as f64 / core.ticks_per_instruction() / runs,
                stack_bytes: l.stack,
                erases: per_run(0),
                writes: per_run(1),
                bytes_written: per_run(2),
                reads: per_run(3),
                bytes_read: per_run(4),
                command_bytes: per_run(5),
                reply_bytes: per_run(6),
            })
        })
        .collect()
}
