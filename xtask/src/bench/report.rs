//! The benchmark's outputs: a table for the terminal, JSON rows, and
//! docs/BENCHMARKS.md.

use super::accuracy::Accuracy;
use super::command_report;
use super::commands::CommandRow;
use super::{Core, Row};
use anyhow::Result;
use std::fmt::Write;
use std::process::Command;
use triad_bench::Variant;

/// The reference harness of the benchmark issue: xioTechnologies Fusion's
/// `FusionModelInertial` compiled with arm-none-eabi-gcc 12.2 -O2, same
/// harness, instructions per 6-axis sample.
fn fusion_c_reference(core: Core) -> f64 {
    match core {
        Core::CortexM4F => 74.0,
        Core::CortexM0 => 4050.0,
    }
}

fn accuracy_cells(a: &Option<Accuracy>) -> (String, String, String) {
    match a {
        Some(a) => (
            format!("{:.3}", a.max_lsb),
            format!("{:.3}", a.rms_lsb),
            format!("{:.2}", a.max_ppm_full_scale),
        ),
        None => ("–".into(), "–".into(), "–".into()),
    }
}

fn flash(row: &Row) -> String {
    row.flash_bytes.map_or("–".into(), |b| b.to_string())
}

/// A plain-text table.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<11} {:<20} {:>10} {:>10} {:>10} {:>7} {:>6}",
        "core", "variant", "instr/smp", "max LSB", "rms LSB", "flash", "stack"
    );
    for r in rows {
        let (max, rms, _) = accuracy_cells(&r.realistic);
        let _ = writeln!(
            out,
            "{:<11} {:<20} {:>10.1} {:>10} {:>10} {:>7} {:>6}",
            r.core.name(),
            r.variant.name(),
            r.instructions_per_sample,
            max,
            rms,
            flash(r),
            r.stack_bytes
        );
    }
    out
}

/// The rows as a JSON array (accuracy with the realistic calibration in
/// `max_error_lsb` and `rms_error_lsb`; null where not applicable).
pub fn json(rows: &[Row]) -> String {
    let num = |x: Option<f64>| x.map_or(serde_json::Value::Null, |v| serde_json::json!(v));
    let values: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            serde_json::json!({
                "core": r.core.name(),
                "variant": r.variant.name(),
                "instructions_per_sample": r.instructions_per_sample,
                "max_error_lsb": num(r.realistic.map(|a| a.max_lsb)),
                "rms_error_lsb": num(r.realistic.map(|a| a.rms_lsb)),
                "max_error_ppm_full_scale": num(r.realistic.map(|a| a.max_ppm_full_scale)),
                "extreme_max_error_lsb": num(r.extreme.map(|a| a.max_lsb)),
                "extreme_rms_error_lsb": num(r.extreme.map(|a| a.rms_lsb)),
                "flash_bytes": r.flash_bytes,
                "stack_bytes": r.stack_bytes,
            })
        })
        .collect();
    serde_json::to_string_pretty(&values).unwrap_or_else(|e| format!("\"{e}\""))
}

fn version(program: &str, arg: &str) -> String {
    Command::new(program)
        .arg(arg)
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.lines().next().map(str::to_owned))
        .unwrap_or_else(|| format!("{program}: unknown"))
}

fn find(rows: &[Row], core: Core, variant: Variant) -> Option<&Row> {
    rows.iter().find(|r| r.core == core && r.variant == variant)
}

/// docs/BENCHMARKS.md.
pub fn markdown(rows: &[Row], commands: &[CommandRow], host: &[(Variant, f64)]) -> Result<String> {
    let mut md = String::new();
    let date = version("date", "-u");
    writeln!(md, "# What accuracy costs in time\n")?;
    writeln!(
        md,
        "Written by `cargo xtask bench` on {date}, with {} and {}. Do not edit: rerun.\n",
        version("rustc", "-V"),
        version(&crate::setup::qemu().to_string_lossy(), "--version")
    )?;
    writeln!(md, "{}", METHOD)?;
    for core in Core::ALL {
        writeln!(md, "## {}\n", core.name())?;
        writeln!(
            md,
            "| variant | instructions / sample | max error LSB | RMS error LSB | max error ppm FS | extreme cal.: max LSB | extreme cal.: RMS LSB | flash bytes | stack bytes |"
        )?;
        writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|")?;
        for r in rows.iter().filter(|r| r.core == core) {
            let (max, rms, ppm) = accuracy_cells(&r.realistic);
            let (emax, erms, _) = accuracy_cells(&r.extreme);
            writeln!(
                md,
                "| {} | {:.1} | {max} | {rms} | {ppm} | {emax} | {erms} | {} | {} |",
                r.variant.name(),
                r.instructions_per_sample,
                flash(r),
                r.stack_bytes
            )?;
        }
        writeln!(md)?;
    }
    writeln!(
        md,
        "![max error against instructions per sample](benchmarks.svg)\n"
    )?;
    sensor_reads(&mut md, rows)?;
    command_report::section(&mut md, commands)?;
    writeln!(md, "## Host\n")?;
    writeln!(
        md,
        "The same functions on the machine that ran this, by criterion (`cargo bench -p triad-host --bench model`: mean of its samples, kernel only, 1000 samples per iteration). Indicative: a shared machine, not the device.\n"
    )?;
    writeln!(md, "| variant | ns / sample | samples / s |")?;
    writeln!(md, "|---|---:|---:|")?;
    for (v, ns) in host {
        writeln!(md, "| {} | {ns:.2} | {:.3e} |", v.name(), 1e9 / ns)?;
    }
    writeln!(md)?;
    stream_budget(&mut md)?;
    writeln!(md, "## Against the targets\n")?;
    let m4_full = find(rows, Core::CortexM4F, Variant::FullF32);
    let m4_fusion = find(rows, Core::CortexM4F, Variant::FusionF32);
    let m0_f32 = find(rows, Core::CortexM0, Variant::FullF32);
    let m0_fixed = find(rows, Core::CortexM0, Variant::FullFixed);
    let m4_pipe = find(rows, Core::CortexM4F, Variant::Pipeline);
    if let (Some(full), Some(fusion)) = (m4_full, m4_fusion) {
        writeln!(
            md,
            "- Full (I+Σ)⁻¹ + bias, f32 folded, with clip flags and the temperature channel, Cortex-M4F: **{:.1}** instructions per sample (target ≤ 64; Fusion in C, gcc -O2: {:.1}; the same Fusion model in Rust here: {:.1}).",
            full.instructions_per_sample,
            fusion_c_reference(Core::CortexM4F),
            fusion.instructions_per_sample
        )?;
    }
    if let Some(per_call) = find(rows, Core::CortexM4F, Variant::FullF32PerCall) {
        writeln!(
            md,
            "- The same correction called once per sample, as the firmware's data-ready task calls it (coefficients loaded from memory at each call, the call itself): **{:.1}** instructions on the Cortex-M4F.",
            per_call.instructions_per_sample
        )?;
    }
    for v in [Variant::BatchF32W8, Variant::BatchF32W32] {
        if let Some(batch) = find(rows, Core::CortexM4F, v) {
            writeln!(
                md,
                "- The firmware's batch correction (`BatchKernel::correct`, raw FIFO samples to a batch frame's counts with clip flags) at W = {}, Cortex-M4F: **{:.1}** instructions per sample (target ≤ 64).",
                v.batch_watermark().unwrap_or(1),
                batch.instructions_per_sample
            )?;
        }
    }
    for (with_g, without) in [
        (Variant::FullF32G, Variant::FullF32),
        (Variant::FullFixedG, Variant::FullFixed),
        (Variant::BatchF32W32G, Variant::BatchF32W32),
    ] {
        for core in Core::ALL {
            if let (Some(g), Some(plain)) = (find(rows, core, with_g), find(rows, core, without)) {
                writeln!(
                    md,
                    "- The gyroscope's g-sensitivity G (the gyro's row reads the raw accelerometer sample too, a 3×6 map), `{}` on the {}: **{:.1}** instructions per sample, {:+.1} against `{}` without G ({:.1}).",
                    with_g.name(),
                    core.name(),
                    g.instructions_per_sample,
                    g.instructions_per_sample - plain.instructions_per_sample,
                    without.name(),
                    plain.instructions_per_sample
                )?;
            }
        }
    }
    if let (Some(f32_row), Some(fixed)) = (m0_f32, m0_fixed) {
        writeln!(
            md,
            "- Fixed point on Cortex-M0: **{:.1}** instructions per sample, 1/{:.1} of the soft-float f32 row ({:.1}; target ≤ 1/20), max error {} LSB (target ≤ 0.5).",
            fixed.instructions_per_sample,
            f32_row.instructions_per_sample / fixed.instructions_per_sample,
            f32_row.instructions_per_sample,
            accuracy_cells(&fixed.realistic).0
        )?;
    }
    if let Some(pipe) = m4_pipe {
        writeln!(
            md,
            "- The whole per-sample pipeline, Cortex-M4F: **{:.1}** instructions per sample; at 8 kHz that is {:.2} % of an 84 MHz core (target ≤ 5 %, ≤ 525 instructions).",
            pipe.instructions_per_sample,
            pipe.instructions_per_sample * 8000.0 / 84e6 * 100.0
        )?;
    }
    writeln!(md, "{WHY}")?;
    Ok(md)
}

/// Where the instructions go, read from the disassembly
/// (`llvm-objdump -d` of `target/bench/<target>/release/triad-bench`).
const WHY: &str = "
Why the targets are not all met:

- `full_f32` on the Cortex-M4F: per sample the loop is 18 multiply-adds, 6
  loads, conversions and stores of the axes, 4 accumulator starts, then 6
  coefficients reloaded from the stack (the 24 of K and k and the 2 of the
  temperature channel, with the converted inputs and the accumulators, do not
  fit the 32 single-precision registers), about 20 instructions of clip
  flags (a 16-bit chip's test, chosen once per batch: an `eor` with
  shifted operand and an `add` per axis, two ORs, a bit extract and a byte
  store per triad; a chip's other code ranges take an `rsb` more per
  axis), about 5 for the temperature channel and 4 of loop. Without clip
  flags and temperature the same loop is the `fusion_f32` row.
- `batch_f32_w*` on the Cortex-M4F (src/model/fused_pass.rs, within the
  target): one loop of inline assembly corrects both triads of a sample, its
  18 coefficients in s12-s29 for the whole batch. Per sample: 9 to load and
  convert the six raw axes (a `vldm`, an `ldm` of the same words for the
  flags, the pointer, 6 `vcvt`), one `vldm` of the six offsets as the rows'
  starting sums, 18 `vmla` (the f32 kernel's order, so its bits), 6 `vcvtr`
  (to the nearest count, ties to even; the count is the low half), 3 paired
  `vmov` and 6 `strh`, 15 of raw limit-code flags (the accelerometer's 2
  per axis into the sticky Q flag, an `add` with shifted operand and a
  `qdadd`, src/model/limit_codes.rs; the gyroscope's 3 per axis into a
  bit, as Q holds one flag) and 2 of loop: 60; the call, the flags' setup
  and reading are the rest. With G (`batch_f32_w32_g`, 27 coefficients)
  the gyroscope's K stays in registers and one `vldm` per sample loads
  each triad's offsets with K_a or C: 71 in the loop. A kernel whose values
  could clip, or a chip with 20-bit codes, runs the portable passes (one
  per triad, 37 instructions per triad and sample before the range test).
- `full_fixed` on the Cortex-M0 (src/model/fixed_narrow.rs): only 32-bit
  `MULS`, two per term (a coefficient's high and low halves), and each row
  is 22 instructions of ARMv6-M assembly (LLVM keeps the coefficients as
  loop invariants, spills them and copies an input before every multiply:
  about 30 instructions more per sample); the clip flags (4 per axis) and
  the temperature channel are most of the rest.
- `pipeline` on the Cortex-M4F: after the correction, the frame's
  serialisation, CRC-32C (slicing-by-4, 47 bytes) and COBS stuffing (one copy
  and one test per byte, 51 bytes) dominate, with the driver's transaction
  and the sampler's bookkeeping. Word-at-a-time stuffing and a CRC unit (the
  STM32F4's computes CRC-32/MPEG-2, not the stream's CRC-32C) are the next
  steps.
";

const METHOD: &str = "\
## Method

No transcendental function runs per sample, so there is no micromath-vs-libm
row: the hot path is products and sums, the refold is Gaussian elimination
(no square root), and `libm` is called only when a calibration is loaded
(`sqrt` in the validation of temperature terms, `round` and `ldexp` when the
fixed-point coefficients are made).

Each row corrects 1000 6-axis samples of i16 raw data held in RAM into RAM
(10 batches of 100: the Cortex-M0 has 16 KiB of RAM), as the reference
harness of the benchmark issue does. The raw values are uniform over the
whole i16 range on every axis (`bench/src/inputs.rs`), with a limit code in
every batch; the chip scale is the ICM-42688-P at ±16 g and ±2000 °/s.

Instructions are counted, not timed: QEMU runs with `-icount shift=0`, so
each instruction advances virtual time by 1 ns, and SysTick on the core
clock counts 0.168 ticks per instruction on `netduinoplus2` (STM32F405,
Cortex-M4F, 168 MHz) and 0.016 on `microbit` (nRF51822, Cortex-M0, 16 MHz).
Instructions are not cycles: loads, divides, flash wait states and the FPU
differ on silicon.

Every row's outputs are checked against the host's computation of the same
variant on the same inputs (a 64-bit digest of every output bit): a fast row
is never a wrong row. `cargo xtask test` runs the same check.

Accuracy is against the f64 reference (Gaussian elimination on (I+Σ), in the
sensor's LSB and in ppm of full scale), with the realistic calibration of
`bench/src/inputs.rs` (scale and misalignment within 0.2 %) and an extreme
valid one (scale factors 0.52..1.45, misalignments up to 0.095). The simple
rows (bias only, diagonal) are judged against the full model: their error is
what they leave uncorrected. The refold rows are judged against the model at
each sample's own temperature, so the low-rate row's staleness is in its
error. Flash is the size of the variant's kernel function (the loop over a
batch, with what the compiler inlined into it: on the Cortex-M0 it keeps
`Corrector::correct` and the refold out of line, so those rows count the loop
only; `–` where LLVM merged two identical kernels, as bias_only_f32 and
diagonal_f32 are); stack is the kernel's high-water mark, from stack
painting.

Rows: `bias_only_f32` m = s·raw − b; `diagonal_f32` the diagonal of (I+Σ)
and b; `fusion_f32` Fusion's M·((u − b)⊙s) once per triad, ported to Rust;
`full_f32` the firmware's hot path m = K·raw + k with clip flags and the
temperature channel; `full_f32_per_call` the same called out of line once per
sample (its flash is the called function); `full_fixed` the integer-only form
(`FixedCorrector::correct_batch`); `batch_f32_w8` and `batch_f32_w32` the
firmware's batch path, `BatchKernel::correct` over FIFO batches of 8 and 32
raw samples into a batch frame's i16 counts with the batch's clip flags (100
samples per timed call, so a shorter last FIFO batch; accuracy includes the
rounding to the frame's counts, up to 1.5 chip LSBs); `full_f64` K·raw +
k in f64 (software floating point on both cores); `refold_every_sample` and
`refold_low_rate` the temperature terms refolded (f64 inversion) before every
sample or once per 100 samples; `pipeline` the whole data-ready step (the
driver's burst read from a bus that only copies 14 canned bytes, so no chip
model's instructions are counted; correction, averaging, framing, CRC-32C,
COBS); `full_f32_g`, `full_fixed_g` and `batch_f32_w32_g` the rows of the same
names without `_g` on the realistic calibration with a gyroscope
g-sensitivity G (about 0.1 °/s per g, `inputs::with_g_sensitivity`): the
gyro's row adds C·raw_a, three more products per axis (their flash is the
same kernel function's as the row without G: one function serves both).
";

/// Bytes per streamed sample, the highest frame rate per baud rate, and the
/// averaging factor each sensor ODR needs to fit the link.
fn stream_budget(md: &mut String) -> Result<()> {
    use triad::protocol::{max_frame_rate, MAX_ENCODED_LEN};
    const BAUDS: [u32; 3] = [115_200, 921_600, 2_000_000];
    writeln!(md, "## Stream budget\n")?;
    writeln!(
        md,
        "Every frame is {MAX_ENCODED_LEN} bytes on the wire (51-byte frame, one COBS byte, the delimiter): {} bit times at 8N1. Highest sustainable frame rate and the averaging factor N (frames = ODR / N) that each sensor ODR needs:\n",
        MAX_ENCODED_LEN * 10
    )?;
    write!(md, "| | ")?;
    for b in BAUDS {
        write!(md, "{b} baud | ")?;
    }
    writeln!(md, "\n|---|---:|---:|---:|")?;
    write!(md, "| frames / s | ")?;
    for b in BAUDS {
        write!(md, "{} | ", max_frame_rate(b))?;
    }
    writeln!(md)?;
    for odr in [1_000u32, 2_000, 4_000, 8_000, 16_000, 32_000] {
        write!(md, "| N at {} kHz | ", odr / 1000)?;
        for b in BAUDS {
            write!(md, "{} | ", odr.div_ceil(max_frame_rate(b)))?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// The sensor-read rows with the bus bytes each sample costs.
fn sensor_reads(md: &mut String, rows: &[Row]) -> Result<()> {
    use triad_bench::kernels::bus_bytes_per_sample;
    writeln!(md, "## Sensor reads\n")?;
    writeln!(
        md,
        "The ICM-42688-P driver reading 6-axis samples (and temperature) over SPI from a bus that only hands back canned bytes: one 14-byte burst per sample, or FIFO drains of W 16-byte packets (INT_STATUS and FIFO_COUNT in one 3-byte read, then the packets in one FIFO_DATA read). Bus bytes count the address bytes too; on I²C add the device address and the restart per transaction.\n"
    )?;
    writeln!(
        md,
        "| read | bus bytes / sample | Cortex-M4F instr. / sample | Cortex-M0 instr. / sample |"
    )?;
    writeln!(md, "|---|---:|---:|---:|")?;
    for v in [
        Variant::ReadBurst,
        Variant::ReadFifo1,
        Variant::ReadFifo8,
        Variant::ReadFifo32,
    ] {
        let instr = |core| {
            find(rows, core, v).map_or("–".into(), |r| {
                format!("{:.1}", r.instructions_per_sample)
            })
        };
        writeln!(
            md,
            "| {} | {} | {} | {} |",
            v.name(),
            bus_bytes_per_sample(v).map_or("–".into(), |b| format!("{b:.2}")),
            instr(Core::CortexM4F),
            instr(Core::CortexM0)
        )?;
    }
    writeln!(md)?;
    Ok(())
}
