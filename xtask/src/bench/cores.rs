//! The emulated cores: build the benchmark firmware for each, run it under
//! QEMU with `-icount shift=0`, parse its lines, and check each digest
//! against the host's computation of the same variant (the command-handling
//! lines: [`super::commands`]).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use triad_bench::kernels::NoMeter;
use triad_bench::{Bench, Variant, BATCH, BATCHES};

use super::commands::{self, CommandRow};
use crate::cmd::{cargo, check, root};
use crate::qemu;

/// A core the benchmark runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Core {
    /// QEMU netduinoplus2: STM32F405, Cortex-M4F at 168 MHz, single-precision FPU.
    CortexM4F,
    /// QEMU microbit: nRF51822, Cortex-M0 at 16 MHz, no FPU.
    CortexM0,
}

impl Core {
    /// Both cores, in the report's order.
    pub const ALL: [Core; 2] = [Core::CortexM4F, Core::CortexM0];

    /// The name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Core::CortexM4F => "cortex-m4f",
            Core::CortexM0 => "cortex-m0",
        }
    }

    fn machine(self) -> &'static str {
        match self {
            Core::CortexM4F => "netduinoplus2",
            Core::CortexM0 => "microbit",
        }
    }

    fn target(self) -> &'static str {
        match self {
            Core::CortexM4F => "thumbv7em-none-eabihf",
            Core::CortexM0 => "thumbv6m-none-eabi",
        }
    }

    /// SysTick ticks per instruction under `-icount shift=0` (1 ns each):
    /// the core clock in GHz.
    pub(super) fn ticks_per_instruction(self) -> f64 {
        match self {
            Core::CortexM4F => 0.168,
            Core::CortexM0 => 0.016,
        }
    }
}

/// One variant as measured on a core.
#[derive(Clone, Debug)]
pub struct Measured {
    pub variant: Variant,
    pub instructions_per_sample: f64,
    pub flash_bytes: Option<u64>,
    pub stack_bytes: u32,
}

/// What one line of the firmware said.
struct Line {
    variant: Variant,
    samples: u64,
    ticks: u64,
    overhead: u64,
    stack: u32,
    digest: u64,
}

/// How long one core's run may take (the slowest row, f64 refolds on the
/// Cortex-M0, takes a few seconds).
const RUN_TIMEOUT: Duration = Duration::from_secs(300);

/// Builds, runs and checks the benchmark on `core`: the variants' rows and
/// the command-handling rows.
pub fn measure(core: Core) -> Result<(Vec<Measured>, Vec<CommandRow>)> {
    let elf = build(core)?;
    let stdout = run(core, &elf)?;
    let lines = variant_lines(core, &stdout)?;
    check_digests(core, &lines)?;
    let commands = commands::measure(core, &stdout)?;
    let elf_bytes = std::fs::read(&elf)?;
    let variants = lines
        .iter()
        .map(|l| {
            let ticks = l.ticks.saturating_sub(l.overhead * BATCHES as u64);
            Ok(Measured {
                variant: l.variant,
                instructions_per_sample: ticks as f64
                    / core.ticks_per_instruction()
                    / l.samples as f64,
                flash_bytes: symbol_size(&elf_bytes, l.variant.kernel_symbol())?,
                stack_bytes: l.stack,
            })
        })
        .collect::<Result<_>>()?;
    Ok((variants, commands))
}

/// The test of `cargo xtask test`: every variant's outputs on both emulated
/// cores equal the host's, bit for bit.
pub fn check_firmware_outputs() -> Result<()> {
    for core in Core::ALL {
        let elf = build(core)?;
        let stdout = run(core, &elf)?;
        let lines = variant_lines(core, &stdout)?;
        check_digests(core, &lines)?;
        let commands = commands::measure(core, &stdout)?;
        note!(
            "xtask: bench firmware on {}: {} variants and {} commands, outputs equal the host's",
            core.name(),
            lines.len(),
            commands.len()
        );
    }
    Ok(())
}

/// `cargo SUBCOMMAND --quiet -p triad-bench --bin triad-bench` of the
/// benchmark firmware for `core` (its target, target/bench). The build and
/// clippy both run it.
pub fn bench_cargo(subcommand: &str, core: Core) -> Command {
    let mut command = cargo();
    command
        .args([subcommand, "--quiet", "-p", "triad-bench"])
        .args(["--bin", "triad-bench", "--features", "firmware"])
        .args(["--target", core.target()])
        .env(crate::cmd::EMBEDDED_PANIC.0, crate::cmd::EMBEDDED_PANIC.1)
        .env("CARGO_TARGET_DIR", bench_target_dir());
    command
}

fn bench_target_dir() -> PathBuf {
    root().join("target/bench")
}

fn build(core: Core) -> Result<PathBuf> {
    let mut command = bench_cargo("build", core);
    command.arg("--release");
    check(
        command,
        &format!("building the benchmark firmware for {}", core.name()),
    )?;
    Ok(bench_target_dir()
        .join(core.target())
        .join("release/triad-bench"))
}

/// Runs the benchmark firmware on `core`; returns what it printed.
fn run(core: Core, elf: &Path) -> Result<String> {
    let mut command = qemu::command(core.machine(), elf);
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting {}", command.get_program().to_string_lossy()))?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > RUN_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "the benchmark on {} did not finish within {RUN_TIMEOUT:?}",
                core.name()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let output = child.wait_with_output()?;
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    if !status.success() {
        bail!(
            "the benchmark on {} ended with {status}:\n{stdout}{}",
            core.name(),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    Ok(stdout)
}

/// The variants' lines of a run.
fn variant_lines(core: Core, stdout: &str) -> Result<Vec<Line>> {
    let lines: Vec<Line> = stdout
        .lines()
        .filter(|l| l.starts_with("bench "))
        .map(parse_line)
        .collect::<Result<_>>()?;
    if lines.len() != Variant::ALL.len() {
        bail!(
            "the benchmark on {} printed {} rows, expected {}:\n{stdout}",
            core.name(),
            lines.len(),
            Variant::ALL.len()
        );
    }
    Ok(lines)
}

/// The value of `key=value` in a line of the benchmark firmware.
pub(super) fn field<'a>(line: &'a str, key: &str) -> Result<&'a str> {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .with_context(|| format!("no `{key}=` in benchmark line {line:?}"))
}

/// The decimal number of `key=value` in a line of the benchmark firmware.
pub(super) fn number(line: &str, key: &str) -> Result<u64> {
    let v = field(line, key)?;
    v.parse()
        .with_context(|| format!("`{key}={v}` is not a number in {line:?}"))
}

/// The hexadecimal digest of `key=0x…` in a line of the benchmark firmware.
pub(super) fn digest(line: &str, key: &str) -> Result<u64> {
    let d = field(line, key)?;
    u64::from_str_radix(d.trim_start_matches("0x"), 16)
        .with_context(|| format!("digest {d:?} is not hexadecimal in {line:?}"))
}

fn parse_line(line: &str) -> Result<Line> {
    let field = |key: &str| field(line, key);
    let number = |key: &str| number(line, key);
    let name = field("variant")?;
    Ok(Line {
        variant: Variant::from_name(name)
            .with_context(|| format!("unknown variant {name:?} in {line:?}"))?,
        samples: number("samples")?,
        ticks: number("ticks")?,
        overhead: number("overhead")?,
        stack: number("stack")? as u32,
        digest: digest(line, "digest")?,
    })
}

/// A fast row is never a wrong row: the firmware's digest of every output
/// must equal the host's for the same variant and inputs.
fn check_digests(core: Core, lines: &[Line]) -> Result<()> {
    let bench = Bench::realistic();
    for line in lines {
        let host = bench.run(line.variant, &mut NoMeter)?;
        if host.value() != line.digest {
            bail!(
                "{} on {}: the firmware's outputs differ from the host's (digest {:#018x} vs {:#018x})",
                line.variant.name(),
                core.name(),
                line.digest,
                host.value()
            );
        }
        if line.samples != (BATCH * BATCHES) as u64 {
            bail!(
                "{} on {}: {} samples, expected {}",
                line.variant.name(),
                core.name(),
                line.samples,
                BATCH * BATCHES
            );
        }
    }
    Ok(())
}

/// The size of the kernel function `name` (in a module of triad_bench) in the ELF.
fn symbol_size(elf: &[u8], name: &str) -> Result<Option<u64>> {
    use object::{Object, ObjectSymbol};
    let file = object::File::parse(elf).context("parsing the benchmark ELF")?;
    // Legacy mangling of triad_bench::<module>::<name>:
    // _ZN11triad_bench<len><module><len><name>17h<hash>E.
    let needle = format!("{}{}17h", name.len(), name);
    Ok(file
        .symbols()
        .filter(|s| {
            s.name()
                .is_ok_and(|n| n.starts_with("_ZN11triad_bench") && n.contains(&needle))
        })
        .map(|s| s.size())
        .max())
}
