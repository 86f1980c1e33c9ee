//! End to end on the emulated board: the firmware's stream, captured by
//! `cargo xtask test` from QEMU, against the host's computation of the same
//! samples.
//!
//! The firmware reads a chip model serving the documented demo motion (or,
//! when xtask sets TRIAD_E2E_SCENE, the simulator running that scene) through
//! the real driver: the ICM-42688-P or the LSM6DSOX, on SPI or I²C, as the
//! build chose (xtask says which in TRIAD_E2E_SENSOR and TRIAD_E2E_BUS). The
//! host builds the same chip model and driver from the board's own files
//! (triad_sim::emulated_board), runs the same `Sampler::step` per data-ready tick,
//! and so knows every raw sample the firmware read. Checked:
//! - at least 1000 frames, no CRC error, no sequence gap, no bytes skipped,
//!   no overrun or drop reported by the device;
//! - every frame's values equal the host's f32 hot path bit for bit;
//! - `triad correct` on the same samples in SI units agrees within the f32
//!   rounding bound derived in `correct_bound`;
//! - the CSV of `triad decode` carries the frames' values exactly.
//!
//! Run by `cargo xtask test` (it sets the TRIAD_E2E_* variables); ignored in a
//! plain `cargo test`, which has no QEMU run to check.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use triad::device::{sample_period_us, start_calibration, Sampler, StepOutcome};
use triad::model::Corrector;
use triad::sensor::interface::{I2cInterface, SpiInterface};
use triad::sensor::{Imu, ImuScale, RawSample};
use triad::stream::{Decoder, Frame};

/// The emulated board's chips: the very code the firmware builds.
use triad_sim::emulated_board::{icm42688, lsm6dsox, source, DESCRIPTION};

const TRIAD: &str = env!("CARGO_BIN_EXE_triad");

fn env_path(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var_os(name).unwrap_or_else(|| panic!("{name} is set by cargo xtask test")),
    )
}

/// What the firmware's chip model served: the scene of TRIAD_E2E_SCENE (the
/// blob the firmware embedded) when xtask ran a simulated scene, else the
/// demo motion; at the chip's rate, as boards/qemu/board.rs builds it.
fn model_source(rate_hz: f64) -> source::Source {
    match std::env::var_os("TRIAD_E2E_SCENE") {
        Some(path) => {
            let blob = std::fs::read(&path).expect("the scene blob of the run");
            source::scene(rate_hz, &blob).expect("the embedded scene runs")
        }
        None => source::demo(rate_hz),
    }
}

struct NoDelay;
impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _: u32) {}
}

/// The emulated board's sensor as the firmware build chose it: chip
/// (`TRIAD_E2E_SENSOR`: icm42688 or lsm6dsox) and bus (`TRIAD_E2E_BUS`: spi or
/// i2c), each the board's default (ICM-42688-P, SPI) when unset.
enum HostSensor {
    IcmSpi(icm42688::Driver<SpiInterface<icm42688::Model>>),
    IcmI2c(icm42688::Driver<I2cInterface<icm42688::Model>>),
    LsmSpi(lsm6dsox::Driver<SpiInterface<lsm6dsox::Model>>),
    LsmI2c(lsm6dsox::Driver<I2cInterface<lsm6dsox::Model>>),
}

/// Runs `$body` with `$s` bound to the driver, whatever chip and bus.
macro_rules! each_sensor {
    ($sensor:expr, $s:ident => $body:expr) => {
        match $sensor {
            HostSensor::IcmSpi($s) => $body,
            HostSensor::IcmI2c($s) => $body,
            HostSensor::LsmSpi($s) => $body,
            HostSensor::LsmI2c($s) => $body,
        }
    };
}

impl HostSensor {
    /// The chip and bus the firmware under test was built with, initialised
    /// as the firmware does (the board's configuration).
    fn from_env() -> Self {
        let chip = std::env::var("TRIAD_E2E_SENSOR").unwrap_or_else(|_| "icm42688".into());
        let bus = std::env::var("TRIAD_E2E_BUS").unwrap_or_else(|_| "spi".into());
        Self::new(&chip, &bus)
    }

    /// `chip` (icm42688, lsm6dsox) on `bus` (spi, i2c), initialised with the board's configuration.
    fn new(chip: &str, bus: &str) -> Self {
        let icm = || icm42688::model(model_source(icm42688::sensor_config().sample_rate_hz()));
        let lsm = || lsm6dsox::model(model_source(lsm6dsox::sensor_config().sample_rate_hz()));
        let mut sensor = match (chip, bus) {
            ("icm42688", "spi") => Self::IcmSpi(icm42688::Driver::new_spi(icm())),
            ("icm42688", "i2c") => {
                Self::IcmI2c(icm42688::Driver::new_i2c(icm(), icm42688::I2C_ADDRESS))
            }
            ("lsm6dsox", "spi") => Self::LsmSpi(lsm6dsox::Driver::new_spi(lsm())),
            ("lsm6dsox", "i2c") => {
                Self::LsmI2c(lsm6dsox::Driver::new_i2c(lsm(), lsm6dsox::I2C_ADDRESS))
            }
            other => panic!(
                "TRIAD_E2E_SENSOR/TRIAD_E2E_BUS {other:?}: expected icm42688 or lsm6dsox on spi or i2c"
            ),
        };
        let debug = |e: &dyn std::fmt::Debug| format!("{e:?}");
        let initialised = match &mut sensor {
            Self::IcmSpi(s) => s
                .init(&mut NoDelay, &icm42688::sensor_config())
                .map_err(|e| debug(&e)),
            Self::IcmI2c(s) => s
                .init(&mut NoDelay, &icm42688::sensor_config())
                .map_err(|e| debug(&e)),
            Self::LsmSpi(s) => s
                .init(&mut NoDelay, &lsm6dsox::sensor_config())
                .map_err(|e| debug(&e)),
            Self::LsmI2c(s) => s
                .init(&mut NoDelay, &lsm6dsox::sensor_config())
                .map_err(|e| debug(&e)),
        };
        initialised.expect("the chip model initialises");
        sensor
    }

    /// The data-ready rate, Hz: the board's chip configuration's.
    fn sample_rate_hz(&self) -> f64 {
        match self {
            Self::IcmSpi(_) | Self::IcmI2c(_) => icm42688::sensor_config().sample_rate_hz(),
            Self::LsmSpi(_) | Self::LsmI2c(_) => lsm6dsox::sensor_config().sample_rate_hz(),
        }
    }

    /// Samples the chip model has produced.
    fn samples_produced(&self) -> u64 {
        each_sensor!(self, s => s.bus().samples_produced())
    }

    /// What the emulated board's `data_ready` does: the model's clock moves to its next sample.
    fn data_ready(&mut self) {
        match self {
            Self::IcmSpi(s) => advance_icm(s.bus_mut()),
            Self::IcmI2c(s) => advance_icm(s.bus_mut()),
            Self::LsmSpi(s) => advance_lsm(s.bus_mut()),
            Self::LsmI2c(s) => advance_lsm(s.bus_mut()),
        }
    }
}

fn advance_icm(model: &mut icm42688::Model) {
    model.advance(icm42688::next_sample_ns(model));
}

fn advance_lsm(model: &mut lsm6dsox::Model) {
    model.advance(lsm6dsox::next_sample_ns(model));
}

impl Imu for HostSensor {
    type Error = String;

    fn read_sample(&mut self) -> Result<RawSample, String> {
        each_sensor!(self, s => s.read_sample().map_err(|e| format!("{e:?}")))
    }

    fn scale(&self) -> ImuScale {
        each_sensor!(self, s => s.scale())
    }
}

#[test]
fn every_emulated_data_ready_brings_exactly_one_new_sample() {
    // 200 000 ticks: 4 min of LSM6DSOX time at 833 Hz. Each tick's step is
    // ⌈(n+1)·P⌉ − ⌈n·P⌉ ns, so the count is exact at any length (a fixed
    // ⌈P⌉ step would gain one sample per 1.49 million ticks; ⌊P⌋ would miss
    // the very first).
    const TICKS: u64 = 200_000;
    for (chip, bus) in [("icm42688", "spi"), ("lsm6dsox", "i2c")] {
        let mut sensor = HostSensor::new(chip, bus);
        for tick in 1..=TICKS {
            sensor.data_ready();
            assert_eq!(sensor.samples_produced(), tick, "{chip} on {bus}");
        }
    }
}

#[test]
fn the_chip_models_sample_at_their_configured_rate() {
    // 1000 ticks of each chip model's clock span 1000 of its configured periods.
    for (chip, bus) in [("icm42688", "spi"), ("lsm6dsox", "spi")] {
        let mut sensor = HostSensor::new(chip, bus);
        let period_ns = 1e9 / sensor.sample_rate_hz();
        let mut elapsed_ns = 0u64;
        for _ in 0..1000 {
            elapsed_ns += match &sensor {
                HostSensor::IcmSpi(s) => icm42688::next_sample_ns(s.bus()),
                HostSensor::LsmSpi(s) => lsm6dsox::next_sample_ns(s.bus()),
                _ => unreachable!("SPI builds only"),
            };
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
    let startup = start_calibration(&blob_bytes, &sensor.scale(), DESCRIPTION.orientation)
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
            StepOutcome::Frame(frame) => frames.push(frame),
            other => panic!("decimation 1 frames every step, got {other:?}"),
        }
    }
    (frames, raws, sampler.corrector().clone())
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

/// |Δ| allowed between the firmware (K = f32((I+Σ)⁻¹·s), input raw exact) and
/// `triad correct` (K' = f32((I+Σ)⁻¹), input f32(raw·s)) for output axis i.
///
/// Each path rounds: its coefficients (≤ 2⁻²⁴ relative each), the SI input in
/// `triad correct` (≤ 2⁻²⁴ relative), three products and three additions
/// (≤ 2⁻²⁴ relative of the running magnitude each). Summed over both paths
/// that is under 8·2⁻²⁴·(Σ_j |K_ij·m̂_j| + |k_i|) in SI units, where
/// `magnitude` bounds the bracket.
fn correct_bound(magnitude: f64) -> f64 {
    8.0 * f64::powi(2.0, -24) * magnitude
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn triad_correct_on_the_same_samples_agrees_within_f32_rounding() {
    let device = captured_frames();
    let timestamps: Vec<u32> = device.iter().map(|f| f.timestamp_us).collect();
    let (_, raws, _) = host_frames(device.len(), &timestamps);
    let (sensor, _) = host_board();
    let scale = sensor.scale();

    // The raw samples in SI units, as a user's measured CSV would hold them.
    let mut csv = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    let mut v_in = Vec::with_capacity(raws.len());
    for (n, raw) in raws.iter().enumerate() {
        let a = raw.accel.map(|x| f64::from(x) * scale.accel.si_per_lsb);
        let g = raw.gyro.map(|x| f64::from(x) * scale.gyro.si_per_lsb);
        v_in.push([a[0], a[1], a[2], g[0], g[1], g[2]]);
        let t = scale.temperature_c(raw.temperature);
        csv.push_str(&format!(
            "{},{:?},{:?},{:?},{:?},{:?},{:?},{:?}\n",
            f64::from(timestamps[n]) * 1e-6,
            a[0],
            a[1],
            a[2],
            g[0],
            g[1],
            g[2],
            t
        ));
    }
    let mut child = Command::new(TRIAD)
        .args(["correct", "--calib"])
        .arg(env_path("TRIAD_E2E_CALIBRATION"))
        .arg("-")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Written from a thread: `triad correct` streams its output, so writing
    // all input before reading would deadlock once both pipes are full.
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(csv.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut rows = text.lines();
    assert_eq!(rows.next(), Some("t,ax,ay,az,gx,gy,gz,temp"));
    let mut worst = 0.0f64;
    for (n, (row, frame)) in rows.zip(&device).enumerate() {
        let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        let firmware = frame.accel.iter().chain(&frame.gyro).map(|&x| f64::from(x));
        // Σ_j |K_ij·m̂_j| + |k_i| ≤ 1.1·Σ_j |m̂_j| + 1: the default calibration's
        // (I+Σ)⁻¹ has absolute row sums below 1.004 and |b| below 0.1 SI units.
        let input_sum = |x: &[f64]| 1.1 * x.iter().map(|v| v.abs()).sum::<f64>() + 1.0;
        let (accel_in, gyro_in) = (input_sum(&v_in[n][0..3]), input_sum(&v_in[n][3..6]));
        let magnitudes = [accel_in, accel_in, accel_in, gyro_in, gyro_in, gyro_in];
        for (axis, ((host, fw), magnitude)) in
            v[1..7].iter().zip(firmware).zip(magnitudes).enumerate()
        {
            let bound = correct_bound(magnitude);
            let diff = (host - fw).abs();
            worst = worst.max(diff / bound);
            assert!(diff <= bound, "frame {n} axis {axis}: triad correct {host} vs firmware {fw}, |Δ| {diff:e} > {bound:e}");
        }
    }
    println!(
        "triad correct vs firmware: worst |Δ| is {:.3} of the bound",
        worst
    );
}

#[test]
#[ignore = "needs the QEMU capture made by `cargo xtask test`"]
fn decoded_csv_carries_the_frames_exactly() {
    let device = captured_frames();
    let csv = std::fs::read_to_string(env_path("TRIAD_E2E_CSV")).expect("decoded CSV");
    let mut rows = csv.lines();
    assert_eq!(rows.next(), Some("seq,t,ax,ay,az,gx,gy,gz,temp,flags"));
    let rows: Vec<&str> = rows.collect();
    let expected: usize = std::env::var("TRIAD_E2E_FRAMES").unwrap().parse().unwrap();
    assert_eq!(rows.len(), expected, "triad decode stops at --max-frames");
    for (row, frame) in rows.iter().zip(&device) {
        let f: Vec<&str> = row.split(',').collect();
        assert_eq!(f[0].parse::<u32>().unwrap(), frame.sequence);
        let values: Vec<f32> = f[2..9].iter().map(|x| x.parse().unwrap()).collect();
        let want: Vec<f32> = frame
            .accel
            .iter()
            .chain(&frame.gyro)
            .chain([&frame.temperature])
            .copied()
            .collect();
        assert_eq!(values, want, "row {row}");
        assert_eq!(f[9].parse::<u16>().unwrap(), frame.flags.bits());
    }
}
