//! The whole firmware's cost: the real firmware on the emulated board
//! (`-icount shift=0`: one instruction per virtual nanosecond), built at
//! each sample rate and FIFO watermark, its own load measurement read from
//! its log (each task's cycles in its second full one-second window, the
//! chip model's apart), and the bytes it put on the wire per sample.
//! Then the long run: 10⁶ samples at 8 kHz with W = 32, decoded, counting
//! every loss the stream can show.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use triad::protocol::Decoder;
use triad::protocol::Packet;

use crate::board::{Firmware, Sampling};
use crate::{cmd, qemu};

/// The sample rates measured, Hz.
pub const RATES_HZ: [u32; 4] = [1000, 2000, 4000, 8000];
/// The watermarks measured (1: FIFO off, one data frame per sample).
pub const WATERMARKS: [u16; 3] = [1, 8, 32];
/// The builds with the ICM-42688-P's high-resolution FIFO measured, (rate,
/// W): beside the 16-bit FIFO's rows at the same rate and W.
pub const HIGH_RESOLUTION: [(u32, u16); 3] = [(1000, 8), (1000, 32), (8000, 32)];
/// Stream time per run, s: the load line of the second window comes at 2 s.
const SECONDS: f64 = 2.5;
/// Samples of the long run.
pub const LONG_RUN_SAMPLES: u64 = 1_000_000;

/// One build's figures.
#[derive(Clone, Debug)]
pub struct FirmwareRow {
    /// The chip's sample rate, Hz.
    pub rate_hz: u32,
    /// Samples per interrupt.
    pub watermark: u16,
    /// Built with the high-resolution FIFO (20-bit packets, data frames).
    pub high_resolution: bool,
    /// Instructions per sample: data-ready task, link tasks (commands,
    /// framing, CRC, stuffing, queueing), receive interrupt (on this board
    /// also the transmitter's drain), chip model, and what no task measured
    /// (the window less the tasks and the idle task's sleep: RTIC's
    /// dispatch, the async executor, interrupt entry and exit).
    pub per_sample: [f64; 5],
    /// Bytes on the wire per sample, framing included.
    pub wire_bytes_per_sample: f64,
}

impl FirmwareRow {
    /// The firmware's own instructions per sample (the chip model's left out).
    pub fn all_in(&self) -> f64 {
        self.per_sample[..3].iter().sum::<f64>() + self.per_sample[4]
    }
}

/// What the long run showed.
#[derive(Clone, Debug)]
pub struct LongRun {
    /// Samples decoded.
    pub samples: u64,
    /// Sequence gaps, CRC errors, malformed packets, bytes skipped.
    pub wire_losses: u64,
    /// Overruns (samples lost before the link) and frames dropped, as the device reported.
    pub device_losses: u64,
    /// Host seconds the run took.
    pub host_seconds: f64,
}

/// The firmware built for `rate_hz` and `watermark` (with the
/// high-resolution FIFO when `high_resolution`) on the default emulated chip.
fn firmware(rate_hz: u32, watermark: u16, high_resolution: bool) -> Firmware {
    Firmware {
        sampling: Sampling {
            rate_hz: Some(rate_hz),
            watermark: (watermark > 1).then_some(watermark),
            high_resolution,
            ..Sampling::default()
        },
        ..Firmware::default_emulated()
    }
}

/// Builds and runs every rate and watermark, then the high-resolution builds.
pub fn measure(triad: &Path, calibration: &Path) -> Result<Vec<FirmwareRow>> {
    let mut rows = Vec::new();
    for rate_hz in RATES_HZ {
        for watermark in WATERMARKS {
            rows.push(measure_one(triad, calibration, rate_hz, watermark, false)?);
        }
    }
    for (rate_hz, watermark) in HIGH_RESOLUTION {
        rows.push(measure_one(triad, calibration, rate_hz, watermark, true)?);
    }
    Ok(rows)
}

/// One build's figures alone (`cargo xtask bench --whole-firmware --rate R
/// --watermark W [--high-resolution]`): the quick look while working on the hot path.
pub fn measure_single(
    triad: &Path,
    calibration: &Path,
    rate_hz: u32,
    watermark: u16,
    high_resolution: bool,
) -> Result<FirmwareRow> {
    measure_one(triad, calibration, rate_hz, watermark, high_resolution)
}

fn run_dir(firmware: Firmware) -> Result<PathBuf> {
    let dir = cmd::root()
        .join("target/bench-firmware")
        .join(firmware.stem());
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

fn measure_one(
    triad: &Path,
    calibration: &Path,
    rate_hz: u32,
    watermark: u16,
    high_resolution: bool,
) -> Result<FirmwareRow> {
    let firmware = firmware(rate_hz, watermark, high_resolution);
    note!("xtask: whole firmware, {}", firmware.label());
    let elf = cmd::build_firmware(firmware, calibration)?;
    let dir = run_dir(firmware)?;
    let (raw, csv) = (dir.join("stream.bin"), dir.join("decoded.csv"));
    let sink = qemu::Sink::Files {
        raw: raw.clone(),
        csv: csv.clone(),
    };
    let (status, log) = qemu::stream_with_log(&elf, triad, qemu::Stop::Seconds(SECONDS), sink)?;
    if !status.success() {
        bail!("triad decode of {} exited with {status}", firmware.label());
    }
    let load = log
        .iter()
        .find_map(|line| LoadLine::parse(line))
        .with_context(|| format!("{}: no load line in the firmware's log", firmware.label()))?;
    let samples = f64::from(rate_hz) * f64::from(load.window) / f64::from(load.hz);
    let bytes = std::fs::metadata(&raw)?.len() as f64;
    let rows = std::fs::read_to_string(&csv)?
        .lines()
        .count()
        .saturating_sub(1) as f64;
    Ok(FirmwareRow {
        rate_hz,
        watermark,
        high_resolution,
        per_sample: load.per_sample(samples),
        wire_bytes_per_sample: bytes / rows.max(1.0),
    })
}

/// The firmware's load line: `load cycles in W at H Hz: data-ready A, link
/// B, receive C, chip model D, asleep E` (firmware/src/main.rs).
struct LoadLine {
    window: u32,
    hz: u32,
    busy: [u32; 4],
    asleep: u32,
}

impl LoadLine {
    fn parse(line: &str) -> Option<LoadLine> {
        let rest = line.split("load cycles in ").nth(1)?;
        let numbers: Vec<u32> = rest
            .split(|c: char| !c.is_ascii_digit())
            .filter(|s| !s.is_empty())
            .filter_map(|s| s.parse().ok())
            .collect();
        match numbers[..] {
            [window, hz, a, b, c, d, asleep] => Some(LoadLine {
                window,
                hz,
                busy: [a, b, c, d],
                asleep,
            }),
            _ => None,
        }
    }

    /// Per sample: each task's cycles, then what none of them measured.
    fn per_sample(&self, samples: f64) -> [f64; 5] {
        let measured: u32 = self.busy.iter().sum::<u32>().saturating_add(self.asleep);
        let unmeasured = self.window.saturating_sub(measured);
        let [a, b, c, d] = self.busy;
        [a, b, c, d, unmeasured].map(|cycles| f64::from(cycles) / samples)
    }
}

/// 10⁶ samples at 8 kHz, W = 32, decoded: every loss counted.
pub fn long_run(triad: &Path, calibration: &Path) -> Result<LongRun> {
    let firmware = firmware(8000, 32, false);
    let elf = cmd::build_firmware(firmware, calibration)?;
    let dir = run_dir(firmware)?;
    // The CSV of 10⁶ rows is not kept: the raw bytes are decoded below.
    let (raw, csv) = (dir.join("long.bin"), PathBuf::from("/dev/null"));
    note!(
        "xtask: whole firmware, {}: {LONG_RUN_SAMPLES} samples",
        firmware.label()
    );
    let started = std::time::Instant::now();
    let sink = qemu::Sink::Files {
        raw: raw.clone(),
        csv,
    };
    let status = qemu::stream_to_decoder(&elf, triad, qemu::Stop::Frames(LONG_RUN_SAMPLES), sink)?;
    let host_seconds = started.elapsed().as_secs_f64();
    if !status.success() {
        bail!("triad decode of the long run exited with {status}");
    }
    let bytes = std::fs::read(&raw).with_context(|| format!("reading {}", raw.display()))?;
    let mut decoder = Decoder::new();
    let mut samples = 0u64;
    for packet in decoder.feed_packets(&bytes).flatten() {
        if let Packet::Batch(batch) = packet {
            samples += u64::from(batch.count);
        }
    }
    let s = decoder.stats();
    Ok(LongRun {
        samples,
        wire_losses: s.sequence_gaps + s.crc_errors + s.malformed + s.bytes_skipped,
        device_losses: s.device_overruns + s.device_dropped,
        host_seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_load_line_reads_back() {
        let line = "INFO load cycles in 1000123 at 1000000000 Hz: data-ready 41000, link 9000, receive 7000, chip model 180000, asleep 760000";
        let load = LoadLine::parse(line).unwrap();
        assert_eq!(load.window, 1_000_123);
        assert_eq!(load.hz, 1_000_000_000);
        assert_eq!(load.busy, [41_000, 9_000, 7_000, 180_000]);
        assert_eq!(load.asleep, 760_000);
        // 1000123 − (41000 + 9000 + 7000 + 180000) − 760000 = 3123 unmeasured.
        assert_eq!(load.per_sample(1000.0), [41.0, 9.0, 7.0, 180.0, 3.123]);
        assert!(LoadLine::parse("INFO load ‰: data-ready 1, link 2").is_none());
    }
}
