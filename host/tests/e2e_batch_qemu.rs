//! End to end on the emulated board with the chip's FIFO: the firmware built
//! with a sample rate and a watermark W (`TRIAD_SAMPLE_RATE_HZ`,
//! `TRIAD_FIFO_WATERMARK`), streaming batch frames, captured by `cargo xtask
//! test` from QEMU and checked against the host's run of the same code.
//!
//! The host builds the same chip model at the same rate, starts it with the
//! same settings, advances it W samples per watermark interrupt as the board
//! does, and runs the same `Sampler::step_fifo`. Checked:
//! - every sample arrived: no CRC error, no sequence gap, no bytes skipped,
//!   no overrun, FIFO overflow or drop reported by the device, only batch
//!   frames, one chip period between every two samples (to the µs of a
//!   batch's timestamp across a batch boundary);
//! - every batch frame equals the host's bit for bit (header, counts,
//!   temperature, flags);
//! - with the accelerometer and gyroscope at two rates, the slower triad
//!   held between its own samples (`emulated_board::slower_held`);
//! - `triad correct` on the same raw samples in SI units agrees with the
//!   decoded values within its f32 bound plus half a count of the frame's
//!   fixed point (the rounding the batch frame adds, docs/PROTOCOL.md §20).
//!
//! Ignored in a plain `cargo test`, which has no QEMU run to check.

mod emulated_board;

use std::path::PathBuf;

use emulated_board::{
    capture, host_sampler, settings_from_env, slower_held, triad_correct, HostSensor,
};
use triad::device::Outgoing;
use triad::protocol::Flags;
use triad::protocol::{BatchFrame, Packet};
use triad::sensor::{FifoImu, Imu, RawSample};

fn env_path(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var_os(name).unwrap_or_else(|| panic!("{name} is set by cargo xtask test")),
    )
}

/// The samples the capture must hold at least.
fn expected_samples() -> usize {
    std::env::var("TRIAD_E2E_FRAMES").unwrap().parse().unwrap()
}

/// The batch frames in the captured stream, with the decoder's counters checked.
fn captured_batches() -> Vec<BatchFrame> {
    let mut batches = Vec::new();
    for packet in capture::packets() {
        match packet {
            Packet::Batch(batch) => batches.push(batch),
            other => panic!("a batch-streaming firmware sent {other:?}"),
        }
    }
    let samples: usize = batches.iter().map(|b| usize::from(b.count)).sum();
    assert!(samples >= expected_samples(), "{samples} samples");
    batches
}

/// The watermark and the chip's period (ns) the firmware was built with.
fn watermark_and_period_ns(sensor: &HostSensor) -> (u16, u32) {
    let w = settings_from_env().watermark;
    assert!(
        w > 1,
        "this test checks a FIFO build (TRIAD_FIFO_WATERMARK > 1)"
    );
    (w, (1e9 / sensor.sample_rate_hz()).round() as u32)
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn every_sample_arrives_one_period_apart_in_batches_equal_to_the_hosts() {
    let device = captured_batches();
    let mut sensor = HostSensor::from_env();
    let (w, period_ns) = watermark_and_period_ns(&sensor);
    let mut sampler = host_sampler(&sensor);
    // Sample times: one chip period apart within a batch, and across every
    // batch boundary to the microsecond. A batch is dated in whole µs from
    // the board's watermark timer, which ticks every W periods rounded to
    // the whole µs (boards/qemu; the LSM6DSOX's 1666 Hz period is 600.24
    // µs, 16 of them 9603.84 µs, the timer 9604 µs): a period that is not a
    // whole number of µs leaves the boundary less than 1 µs off; a whole
    // number (the ICM-42688-P's 8 kHz: 125 µs), exact.
    let times: Vec<u64> = device
        .iter()
        .flat_map(|b| {
            (0..u64::from(b.count))
                .map(|i| u64::from(b.timestamp_us) * 1000 + i * u64::from(b.period_ns))
        })
        .collect();
    assert!(device.iter().all(|b| b.period_ns == period_ns));
    let off_at_most = if period_ns % 1000 == 0 { 0 } else { 999 };
    for (n, pair) in times.windows(2).enumerate() {
        let off = (pair[1] - pair[0]).abs_diff(u64::from(period_ns));
        assert!(
            off <= off_at_most,
            "sample {n}: {} ns after the one before, the period is {period_ns} ns",
            pair[1] - pair[0]
        );
    }
    // Replay: each interrupt's W samples, the interrupt at the newest's time.
    let mut host = Vec::new();
    let per_interrupt = usize::from(w).div_ceil(triad::protocol::MAX_BATCH);
    for interrupt in device.chunks(per_interrupt) {
        let newest_ns =
            u64::from(interrupt[0].timestamp_us) * 1000 + (u64::from(w) - 1) * u64::from(period_ns);
        sensor.advance(w);
        let stepped = sampler.step_fifo(&mut sensor, (newest_ns / 1000) as u32, |frame| {
            host.push(frame);
            true
        });
        assert_eq!(stepped.samples, w, "the FIFO held one watermark's worth");
        assert!(stepped.read_failed.is_none());
    }
    // The capture may end inside an interrupt's frames: the host's last
    // interrupt can make one more than was captured.
    assert!(host.len() >= device.len() && host.len() < device.len() + per_interrupt);
    for (n, (h, d)) in host.iter().zip(&device).enumerate() {
        let Outgoing::Batch(h) = h else {
            panic!("the host made {h:?}");
        };
        assert_eq!(h, d, "batch {n}");
        assert!(!d.flags.contains(Flags::UNCALIBRATED), "batch {n}");
    }
    println!(
        "{} batch frames ({} samples at {} Hz, W = {w}) equal the host's bit for bit",
        device.len(),
        times.len(),
        1e9 / f64::from(period_ns)
    );
}

/// The first `samples` raw samples `sensor` (started afresh) gives, `w` per
/// watermark interrupt: those the firmware read, as its batches equal the
/// host's bit for bit.
fn host_raws(sensor: &mut HostSensor, w: u16, samples: usize) -> Vec<RawSample> {
    let mut raws: Vec<RawSample> = Vec::with_capacity(samples);
    while raws.len() < samples {
        sensor.advance(w);
        let mut buffer = vec![RawSample::default(); usize::from(w)];
        let read = sensor
            .read_fifo(&mut buffer)
            .expect("the model's FIFO reads");
        raws.extend_from_slice(&buffer[..read.samples]);
    }
    raws.truncate(samples);
    raws
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn the_slower_sensor_is_held_between_its_own_samples() {
    // Only a build with one sensor slower (docs/PROTOCOL.md §22): the
    // chip's FIFO then holds the two sensors' data at their own rates.
    let Some(slower) = settings_from_env().slower else {
        return;
    };
    let device = captured_batches();
    let mut sensor = HostSensor::from_env();
    let (w, _) = watermark_and_period_ns(&sensor);
    let samples: usize = device.iter().map(|b| usize::from(b.count)).sum();
    let raws = host_raws(&mut sensor, w, samples);
    slower_held::assert_held_between_its_samples(&raws, &sensor, slower);
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn triad_correct_on_the_same_samples_agrees_within_f32_rounding_and_half_a_count() {
    let device = captured_batches();
    let mut sensor = HostSensor::from_env();
    let (w, period_ns) = watermark_and_period_ns(&sensor);
    let samples: usize = device.iter().map(|b| usize::from(b.count)).sum();
    let raws = host_raws(&mut sensor, w, samples);
    let mut times_s = Vec::with_capacity(samples);
    let mut streamed = Vec::with_capacity(samples);
    for batch in &device {
        for i in 0..usize::from(batch.count) {
            let (a, g) = batch.sample_si(i).expect("in the batch");
            streamed.push([a[0], a[1], a[2], g[0], g[1], g[2]]);
            times_s.push(
                f64::from(batch.timestamp_us) * 1e-6 + i as f64 * f64::from(period_ns) * 1e-9,
            );
        }
    }
    let quantum = [
        f64::from(device[0].accel_lsb),
        f64::from(device[0].gyro_lsb),
    ];
    let worst = triad_correct::agrees_with_firmware(
        &env_path("TRIAD_E2E_CALIBRATION"),
        &raws,
        &times_s,
        &sensor.scale(),
        &streamed,
        quantum,
    );
    println!("triad correct vs the decoded batches: worst |Δ| is {worst:.3} of the bound");
}
