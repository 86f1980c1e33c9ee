//! The whole firmware's section of docs/BENCHMARKS.md.

use std::fmt::Write;

use super::whole_firmware::{FirmwareRow, LongRun, LONG_RUN_SAMPLES};

/// The all-in target at 8 kHz with W = 32: 5 % of an 84 MHz core.
const TARGET_INSTRUCTIONS: f64 = 525.0;

/// Bauds the "highest rate" columns are given for: the firmware's link
/// (921600) and the NUCLEO's ST-LINK virtual COM port's top rate.
const BAUDS: [u32; 2] = [921_600, 2_000_000];

const METHOD: &str = "\
The real firmware (firmware/src/main.rs) on the emulated board, built for
the ICM-42688-P model on SPI at each sample rate (`TRIAD_SAMPLE_RATE_HZ`)
and FIFO watermark W (`TRIAD_FIFO_WATERMARK`; W = 1 is the chip's
data-ready interrupt and one data frame per sample, W > 1 the FIFO
watermark interrupt and batch frames of up to 16 samples; `W, 20-bit` the
FIFO in the chip's high-resolution format, `TRIAD_FIFO_HIGH_RESOLUTION=1`:
20-byte packets and one data frame per sample), streaming the
demo motion corrected by the default calibration. QEMU runs with
`-icount shift=0`, so the firmware's own load measurement (src/device/load.rs:
each task's cycles less its preemptions, on TIM4 counting virtual
nanoseconds) counts instructions; the figures are its second full
one-second window, logged over defmt, over the samples of that window.
Columns: `data-ready` the task that reads the chip (the driver's SPI
transactions), corrects (the batch kernel at W > 1), frames and queues;
`link` the async tasks (the transmitter encoding each frame to the wire,
CRC-32C and COBS, and queueing it; the command task); `TX drain` the USART2
interrupt, which on this board also moves the transmit queue into the data
register (QEMU's STM32 USART has no DMA; on the NUCLEO DMA does it, and
this column is the receive interrupt alone); `dispatch (unmeasured)` the
window less every measured task and less the idle task's own sleep (timed
around WFI with interrupts masked, so no handler is in it): RTIC's
dispatcher, the async executor's polls, channel wake-ups, exception entry
and exit; `all-in` the sum of these four. `chip model` is the emulated
chip's own cost (its SPI answers, its simulation, and the timer interrupt
that stands in for its INT1 line), counted apart and not in `all-in`; no
chip costs the MCU that. Wire bytes are the captured stream's bytes over
its samples.";

/// Where the instructions go at 8 kHz with W = 32, from a QEMU execution
/// trace of the firmware (`-d in_asm,exec,nochain`, instructions per
/// translated block × executions, by function) and the disassembly.
const WHERE: &str = "\
Where the instructions go at 8 kHz with W = 32 (a QEMU execution trace,
`-d in_asm,exec,nochain`, each block's instructions times its executions,
attributed to functions and to the call sites of the library's memcpy,
and the disassembly): the data-ready task is the FIFO read (the driver's
two SPI transactions per interrupt and about 30 instructions per sample
decoding the 16-byte packets), the batch kernel (`batch_f32_w32` above;
the default calibration's g-sensitivity adds three products per gyro
value: about 36 instructions per sample in the accelerometer's pass and
60 in the gyroscope's, whose rows also convert the raw accelerometer
sample again), and the frame written where it lies in the link queue's
slot (`device::slot_queue`: no frame built on the stack, no memcpy; the
batch's mean temperature and the sampler's counters are the rest). The
link task, per 235-byte packet: header and counts written where their
wire bytes go, then one pass that computes the CRC-32C (slicing-by-4)
and finds the zero bytes a word at a time (about 7 instructions per
byte together), writing a COBS code at each (about 2 per byte more),
all of it written straight into the emulated board's transmit ring
(`LinkTx::queue_encoded`: no copy, but for the tail that runs past the
ring's end, copied to its start once per lap); the emulated board's TX drain
loads and stores each byte with no status check (QEMU's USART takes every
byte at once and an SR read wakes QEMU's main loop: boards/qemu/src/
serial_tx.rs), work the NUCLEO's DMA does with no instruction per byte. The STM32F4's CRC unit computes the Ethernet CRC-32 (polynomial
0x04C11DB7, fixed), not the protocol's CRC-32C, so the CRC stays in
software. Not in these figures: on hardware the SPI transfer itself, 16
bytes per sample, which the driver's blocking read waits out: about 6 µs
per sample at the ICM-42688-P's 21 MHz (500 cycles at 84 MHz, more than
the whole budget), at which the NUCLEO runs SPI1 once it has found that
chip (24 µs at the LSM6DSOX's 5.25 MHz); the NUCLEO needs the read by DMA
to meet 5 % (boards/nucleo-f401re/README.md).";

/// The section.
pub fn markdown(rows: &[FirmwareRow], long: &LongRun, fusion_ported: Option<f64>) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "## The whole firmware\n\n{METHOD}\n");
    if let Some(fusion) = fusion_ported {
        md += &table_header();
        let _ = writeln!(
            md,
            "| (anchor) | – | Fusion's inertial model alone, ported (fusion_f32 above) | | | | {fusion:.1} | | | | |"
        );
        md += &table_rows(rows);
    } else {
        md += &rows_only(rows);
    }
    let _ = writeln!(md);
    if let Some(r) = rows
        .iter()
        .find(|r| r.rate_hz == 8000 && r.watermark == 32 && !r.high_resolution)
    {
        let verdict = if r.all_in() <= TARGET_INSTRUCTIONS {
            "within".to_string()
        } else {
            format!(
                "{:.0} % above",
                (r.all_in() / TARGET_INSTRUCTIONS - 1.0) * 100.0
            )
        };
        let _ = writeln!(
            md,
            "- At 8 kHz with W = 32 the firmware costs **{:.1} instructions per sample**, {verdict} the target of {TARGET_INSTRUCTIONS} (5 % of an 84 MHz Cortex-M4F at one instruction per cycle).",
            r.all_in()
        );
    }
    let _ = writeln!(md, "- {}", WHERE.replace('\n', " "));
    let _ = writeln!(
        md,
        "- The long run: {} of {LONG_RUN_SAMPLES} samples at 8 kHz with W = 32 decoded ({:.0} s of host time), {} lost on the wire (sequence gaps, CRC errors, malformed packets, bytes skipped), {} lost or dropped on the device (its overrun and drop counters). QEMU's USART and socket ignore the baud rate: on hardware this stream needs {:.0} baud.",
        long.samples,
        long.host_seconds,
        long.wire_losses,
        long.device_losses,
        rows.iter()
            .find(|r| r.rate_hz == 8000 && r.watermark == 32 && !r.high_resolution)
            .map_or(0.0, |r| r.wire_bytes_per_sample * 8000.0 * 10.0)
    );
    md
}

/// The table's header lines.
fn table_header() -> String {
    let mut md = String::new();
    let _ = write!(
        md,
        "| rate | W | data-ready | link | TX drain | dispatch (unmeasured) | all-in instr. / sample | chip model | wire bytes / sample |"
    );
    for baud in BAUDS {
        let _ = write!(md, " highest rate at {baud} baud |");
    }
    let _ = writeln!(md);
    let _ = writeln!(
        md,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    md
}

/// The table's lines of `rows`.
fn table_rows(rows: &[FirmwareRow]) -> String {
    let mut md = String::new();
    for r in rows {
        let _ = write!(
            md,
            "| {} Hz | {}{} | {:.1} | {:.1} | {:.1} | {:.1} | **{:.1}** | {:.0} | {:.2} |",
            r.rate_hz,
            r.watermark,
            if r.high_resolution { ", 20-bit" } else { "" },
            r.per_sample[0],
            r.per_sample[1],
            r.per_sample[2],
            r.per_sample[4],
            r.all_in(),
            r.per_sample[3],
            r.wire_bytes_per_sample
        );
        for baud in BAUDS {
            // 10 bits per byte on the wire (8N1).
            let _ = write!(
                md,
                " {:.0} Hz |",
                f64::from(baud) / 10.0 / r.wire_bytes_per_sample
            );
        }
        let _ = writeln!(md);
    }
    md
}

/// The table of `rows` alone, header included.
pub fn rows_only(rows: &[FirmwareRow]) -> String {
    table_header() + &table_rows(rows)
}
