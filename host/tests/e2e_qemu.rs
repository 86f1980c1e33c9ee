//! End to end on the emulated board: the firmware's stream, captured by
//! `cargo xtask test` from QEMU, against the host's computation of the same
//! samples.
//!
//! The firmware reads a chip model serving the documented demo motion (or,
//! when xtask sets TRIAD_E2E_SCENE, the simulator running that scene) through
//! the real driver of the chip it finds on the bus: the model of the chip the
//! build named, on SPI or I²C (xtask says which in TRIAD_EMULATED_CHIP and
//! TRIAD_E2E_BUS). The host builds the same chip model, finds and starts it
//! as the firmware does (triad_sim::chips::emulated_board, triad::sensor::AnyChip), runs the same `Sampler::step` per data-ready tick,
//! and so knows every raw sample the firmware read. Checked:
//! - at least 1000 frames, no CRC error, no sequence gap, no bytes skipped,
//!   no overrun or drop reported by the device;
//! - every frame's values equal the host's f32 hot path bit for bit;
//! - `triad correct` on the same samples in SI units agrees within the f32
//!   rounding bound derived in `emulated_board::triad_correct`;
//! - the CSV of `triad decode` carries the frames' values exactly.
//!
//! Run by `cargo xtask test` (it sets the TRIAD_E2E_* variables); ignored in a
//! plain `cargo test`, which has no QEMU run to check.

mod emulated_board;

use std::path::PathBuf;

use emulated_board::{capture, decoded_csv, slower_held, triad_correct, HostSensor};
use triad::device::{sample_period_us, start_calibration, Outgoing, Sampler, StepOutcome};
use triad::model::Corrector;
use triad::protocol::{Decoder, Frame};
use triad::sensor::{Imu, RawSample, CHIP_NAMES};
use triad_sim::chips::emulated_board::DESCRIPTION;

fn env_path(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var_os(name).unwrap_or_else(|| panic!("{name} is set by cargo xtask test")),
    )
}

#[test]
fn every_emulated_data_ready_brings_exactly_one_new_sample() {
    // 200 000 ticks: 4 min of LSM6DSOX time at 833 Hz. Each tick's step is
    // ⌈(n+1)·P⌉ − ⌈n·P⌉ ns, so the count is exact at any length (a fixed
    // ⌈P⌉ step would gain one sample per 1.49 million ticks; ⌊P⌋ would miss
    // the very first).
    const TICKS: u64 = 200_000;
    for (chip, bus) in CHIP_NAMES.iter().zip(["spi", "i2c"].iter().cycle()) {
        let mut sensor = HostSensor::new(chip, bus);
        for tick in 1..=TICKS {
            sensor.data_ready();
            assert_eq!(sensor.model().samples_produced(), tick, "{chip} on {bus}");
        }
    }
}

#[test]
fn the_chip_models_sample_at_their_configured_rate() {
    // 1000 ticks of each chip model's clock span 1000 of its configured periods.
    for chip in CHIP_NAMES {
        let mut sensor = HostSensor::new(chip, "spi");
        let period_ns = 1e9 / sensor.sample_rate_hz();
        let mut elapsed_ns = 0u64;
        for _ in 0..1000 {
            elapsed_ns += sensor.model().next_sample_ns().expect("the chip runs");
            sensor.data_ready();
        }
        let drift = elapsed_ns as f64 - 1000.0 * period_ns;
        // Each tick lands on the whole nanosecond at or after the exact instant.
        assert!((0.0..1.0).contains(&drift), "{chip}: {drift} ns");
    }
}

/// The frames in the captured stream, with the decoder's statistics checked.
fn captured_frames() -> Vec<Frame> {
    let bytes = std::fs::read(env_path("TRIAD_E2E_STREAM")).expect("stream capture");
    let mut decoder = Decoder::new();
    let mut frames = Vec::new();
    for result in decoder.feed(&bytes) {
        frames.push(result.expect("no frame of the capture fails to decode"));
    }
    let stats = decoder.stats();
    assert_eq!(stats.crc_errors, 0, "{stats:?}");
    assert_eq!(stats.malformed, 0, "{stats:?}");
    assert_eq!(stats.sequence_gaps, 0, "{stats:?}");
    assert_eq!(stats.bytes_skipped, 0, "{stats:?}");
    assert_eq!(
        stats.device_overruns, 0,
        "the firmware kept its data-ready steps: {stats:?}"
    );
    assert_eq!(stats.device_dropped, 0, "the link kept up: {stats:?}");
    frames
}

/// The emulated board's sensor and pipeline, on the host: the firmware's
/// start-up decision and sampler (firmware/src/main.rs calls the same two).
fn host_board() -> (HostSensor, Sampler) {
    let sensor = HostSensor::from_env();
    let blob_bytes = std::fs::read(env_path("TRIAD_E2E_BLOB")).expect("calibration blob");
    let startup = start_calibration(None, &blob_bytes, &sensor.scale(), DESCRIPTION.orientation)
        .expect("the chip's scale is valid");
    assert!(
        startup.rejected.is_none(),
        "the embedded calibration is valid: {:?}",
        startup.rejected
    );
    let calibrated = startup.calibrated();
    let sampler = Sampler::at_rate(
        startup.corrector,
        calibrated,
        DESCRIPTION.decimation,
        sensor.sample_rate_hz(),
    );
    (sensor, sampler)
}

/// The host's frames for the same data-ready ticks, and the raw samples read.
fn host_frames(count: usize, timestamps: &[u32]) -> (Vec<Frame>, Vec<RawSample>, Corrector) {
    // One step per captured frame: the emulated board streams every sample.
    assert_eq!(
        DESCRIPTION.decimation, 1,
        "replaying decimated steps needs their timestamps"
    );
    let (mut sensor, mut sampler) = host_board();
    let mut frames = Vec::with_capacity(count);
    let mut raws = Vec::with_capacity(count);
    for &now in timestamps.iter().take(count) {
        sensor.data_ready();
        raws.push(sensor.read_sample().expect("the model reads"));
        // The same step as the firmware's (the second read returns the same
        // latest registers: the model only changes on advance).
        match sampler.step(&mut sensor, now) {
            StepOutcome::Frame(Outgoing::Data(frame)) => frames.push(frame),
            other => panic!("decimation 1 frames every step, got {other:?}"),
        }
    }
    (frames, raws, sampler.corrector().clone())
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn the_slower_sensor_is_held_between_its_own_samples() {
    // Only a build with one sensor slower (docs/PROTOCOL.md §22).
    let Some(slower) = emulated_board::settings_from_env().slower else {
        return;
    };
    let device = captured_frames();
    let timestamps: Vec<u32> = device.iter().map(|f| f.timestamp_us).collect();
    // The samples the firmware read (its frames equal the host's bit for bit).
    let (_, raws, _) = host_frames(device.len(), &timestamps);
    let sensor = HostSensor::from_env();
    slower_held::assert_held_between_its_samples(&raws, &sensor, slower);
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn firmware_frames_equal_host_computation_bit_for_bit() {
    let device = captured_frames();
    let expected: usize = std::env::var("TRIAD_E2E_FRAMES").unwrap().parse().unwrap();
    assert!(
        device.len() >= expected && expected >= 1000,
        "{} frames",
        device.len()
    );
    let timestamps: Vec<u32> = device.iter().map(|f| f.timestamp_us).collect();
    let (host, _, _) = host_frames(device.len(), &timestamps);
    // One streamed frame per `decimation` data-ready periods, to the microsecond.
    let period_us = sample_period_us(HostSensor::from_env().sample_rate_hz())
        * u32::from(DESCRIPTION.decimation);
    for (n, (d, h)) in device.iter().zip(&host).enumerate() {
        assert_eq!(d.sequence, n as u32);
        // Timestamps: one data-ready period apart on the emulated clock.
        if n > 0 {
            assert_eq!(
                d.timestamp_us - device[n - 1].timestamp_us,
                period_us,
                "frame {n}"
            );
        }
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&d.accel), bits(&h.accel), "accel of frame {n}");
        assert_eq!(bits(&d.gyro), bits(&h.gyro), "gyro of frame {n}");
        assert_eq!(
            d.temperature.to_bits(),
            h.temperature.to_bits(),
            "temperature of frame {n}"
        );
        assert_eq!(d.flags, h.flags, "flags of frame {n}");
        assert_eq!(
            d.calibration_id, h.calibration_id,
            "calibration id of frame {n}"
        );
    }
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn triad_correct_on_the_same_samples_agrees_within_f32_rounding() {
    let device = captured_frames();
    let timestamps: Vec<u32> = device.iter().map(|f| f.timestamp_us).collect();
    let (_, raws, _) = host_frames(device.len(), &timestamps);
    let (sensor, _) = host_board();
    let times_s: Vec<f64> = timestamps.iter().map(|&t| f64::from(t) * 1e-6).collect();
    let streamed: Vec<[f32; 6]> = device.iter().map(capture::six_axes).collect();
    // The default calibration's (I+Σ)⁻¹ has absolute row sums below 1.004
    // and |b| below 0.1 SI units: the bound's premise holds.
    let worst = triad_correct::agrees_with_firmware(
        &env_path("TRIAD_E2E_CALIBRATION"),
        &raws,
        &times_s,
        &sensor.scale(),
        &streamed,
        [0.0; 2],
    );
    println!("triad correct vs firmware: worst |Δ| is {worst:.3} of the bound");
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn decoded_csv_carries_the_frames_exactly() {
    let device = captured_frames();
    let csv = std::fs::read_to_string(env_path("TRIAD_E2E_CSV")).expect("decoded CSV");
    let rows = decoded_csv::rows(&csv);
    let expected: usize = std::env::var("TRIAD_E2E_FRAMES").unwrap().parse().unwrap();
    assert_eq!(rows.len(), expected, "triad decode stops at --max-frames");
    for (row, frame) in rows.iter().zip(&device) {
        assert_eq!(row.sequence, frame.sequence);
        assert_eq!(row.values, decoded_csv::frame_values(frame), "{row:?}");
        assert_eq!(row.flags, frame.flags, "{row:?}");
    }
}
