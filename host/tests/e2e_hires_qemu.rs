//! End to end on the emulated board with the ICM-42688-P's high-resolution
//! FIFO: the firmware built with a watermark W and
//! `TRIAD_FIFO_HIGH_RESOLUTION=1` reads 20-byte packets 4 (DS-000347 §6.1,
//! 20-bit values) and streams one data frame per sample (f32: a batch
//! frame's 16-bit counts would drop the extra bits), captured by `cargo
//! xtask test` from QEMU and checked against the host's run of the same code.
//!
//! The host builds the same chip model, starts it with the same settings,
//! advances it W samples per watermark interrupt as the board does, and runs
//! the same `Sampler::step_fifo`. Checked:
//! - every sample arrived: no CRC error, no sequence gap, no bytes skipped,
//!   no overrun, FIFO overflow or drop reported by the device, only data
//!   frames, one chip period apart;
//! - every frame equals the host's bit for bit;
//! - the extra bits reach the stream: the raw samples carry bits below the
//!   16-bit code, and the frames differ from what the same samples cut to
//!   16 bits would give;
//! - with the accelerometer and gyroscope at two rates, the slower triad
//!   held between its own samples (`emulated_board::slower_held`);
//! - `triad correct` on the same raw samples in SI units agrees within its
//!   f32 bound.
//!
//! Ignored in a plain `cargo test`, which has no QEMU run to check.

mod emulated_board;

use emulated_board::capture::{self, env_path};
use emulated_board::{host_sampler, settings_from_env, slower_held, triad_correct, HostSensor};
use triad::device::{Outgoing, Sampler};
use triad::protocol::{Frame, Packet};
use triad::sensor::{Imu, RawSample};

/// The data frames in the captured stream, with the decoder's counters checked.
fn captured_frames() -> Vec<Frame> {
    let mut frames = Vec::new();
    for packet in capture::packets() {
        match packet {
            Packet::Data(frame) => frames.push(frame),
            other => panic!("a high-resolution FIFO build sent {other:?}"),
        }
    }
    let expected: usize = std::env::var("TRIAD_E2E_FRAMES").unwrap().parse().unwrap();
    assert!(frames.len() >= expected, "{} frames", frames.len());
    frames
}

/// The host's frames for `count` samples, W per interrupt at the device's
/// times, and the raw samples they were made from.
fn host_frames(device: &[Frame]) -> (Vec<Frame>, Vec<RawSample>, Sampler) {
    let settings = settings_from_env();
    assert!(
        settings.high_resolution && settings.watermark > 1,
        "this test checks a high-resolution FIFO build"
    );
    let w = usize::from(settings.watermark);
    let mut sensor = HostSensor::from_env();
    let mut sampler = host_sampler(&sensor);
    let mut frames = Vec::with_capacity(device.len());
    for interrupt in device.chunks(w) {
        // The firmware dates the newest sample at the interrupt: the last of the W.
        let newest_us = interrupt[0].timestamp_us
            + (w as u32 - 1) * triad::device::sample_period_us(sensor.sample_rate_hz());
        sensor.advance(settings.watermark);
        let stepped = sampler.step_fifo(&mut sensor, newest_us, |frame| {
            match frame {
                Outgoing::Data(f) => frames.push(f),
                other => panic!("the host made {other:?}"),
            }
            true
        });
        assert_eq!(usize::from(stepped.samples), w, "one watermark's worth");
        assert!(stepped.read_failed.is_none());
    }
    // The same samples again, for the checks on raw values.
    let mut replay = HostSensor::from_env();
    let mut raws = Vec::with_capacity(frames.len());
    while raws.len() < frames.len() {
        replay.advance(settings.watermark);
        let mut buffer = vec![RawSample::default(); w];
        let read = triad::sensor::FifoImu::read_fifo(&mut replay, &mut buffer)
            .expect("the model's FIFO reads");
        raws.extend_from_slice(&buffer[..read.samples]);
    }
    (frames, raws, sampler)
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn high_resolution_frames_equal_the_hosts_and_carry_the_extra_bits() {
    let device = captured_frames();
    let period_us = triad::device::sample_period_us(HostSensor::from_env().sample_rate_hz());
    let (host, raws, sampler) = host_frames(&device);
    assert!(host.len() >= device.len());
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for (n, (d, h)) in device.iter().zip(&host).enumerate() {
        if n > 0 {
            assert_eq!(
                d.timestamp_us - device[n - 1].timestamp_us,
                period_us,
                "frame {n}"
            );
        }
        assert_eq!(bits(&d.accel), bits(&h.accel), "accel of frame {n}");
        assert_eq!(bits(&d.gyro), bits(&h.gyro), "gyro of frame {n}");
        assert_eq!(
            d.temperature.to_bits(),
            h.temperature.to_bits(),
            "frame {n}"
        );
        assert_eq!(d.flags, h.flags, "flags of frame {n}");
    }
    // Bits below the 16-bit code: the accelerometer's bits 3:2 and the
    // gyroscope's 3:1 of the 20-bit value (§6.1).
    let finer = raws
        .iter()
        .filter(|r| r.accel.iter().any(|a| a & 0xC != 0) || r.gyro.iter().any(|g| g & 0xE != 0))
        .count();
    // The same samples cut to their top 16 bits, corrected the same way.
    let corrector = sampler.corrector();
    let differs = device
        .iter()
        .zip(&raws)
        .filter(|(d, r)| {
            let cut = RawSample {
                accel: r.accel.map(|a| a >> 4 << 4),
                gyro: r.gyro.map(|g| g >> 4 << 4),
                temperature: r.temperature,
            };
            let c = corrector.correct(&cut);
            bits(&c.accel) != bits(&d.accel) || bits(&c.gyro) != bits(&d.gyro)
        })
        .count();
    let n = device.len();
    assert!(
        finer * 10 > n * 9,
        "{finer} of {n} samples with bits below 16"
    );
    assert!(
        differs * 10 > n * 9,
        "{differs} of {n} frames differ from 16 bits'"
    );
    println!(
        "{n} data frames equal the host's bit for bit; {finer} samples carry bits below \
         the 16-bit code, {differs} frames differ from the same samples cut to 16 bits"
    );
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn the_slower_sensor_is_held_between_its_own_samples() {
    // Only a build with one sensor slower (docs/PROTOCOL.md §22): packets
    // 4 then carry the slower sensor's data only at its own rate (§6.1).
    let Some(slower) = settings_from_env().slower else {
        return;
    };
    let device = captured_frames();
    let (_, raws, _) = host_frames(&device);
    let sensor = HostSensor::from_env();
    slower_held::assert_held_between_its_samples(&raws[..device.len()], &sensor, slower);
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn triad_correct_on_the_same_samples_agrees_within_f32_rounding() {
    let device = captured_frames();
    let (_, raws, _) = host_frames(&device);
    let sensor = HostSensor::from_env();
    let times_s: Vec<f64> = device
        .iter()
        .map(|f| f64::from(f.timestamp_us) * 1e-6)
        .collect();
    let streamed: Vec<[f32; 6]> = device.iter().map(capture::six_axes).collect();
    let worst = triad_correct::agrees_with_firmware(
        &env_path("TRIAD_E2E_CALIBRATION"),
        &raws[..device.len()],
        &times_s,
        &sensor.scale(),
        &streamed,
        [0.0; 2],
    );
    println!("triad correct vs firmware: worst |Δ| is {worst:.3} of the bound");
}
