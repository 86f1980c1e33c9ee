//! End to end on the emulated board: the firmware's stream, captured by
//! `cargo xtask test` from QEMU, against the host's computation of the same
//! samples.
//!
//! The firmware reads a chip model serving the documented demo motion (or,
//! when xtask sets TRIAD_E2E_SCENE, the simulator running that scene) through
//! the real driver of the chip it finds on the bus: the model of the chip the
//! build named, on SPI or I²C (xtask says which in TRIAD_EMULATED_CHIP and
//! TRIAD_E2E_BUS). The host builds the same chip model, finds and starts it
//! as the firmware does (triad_sim::emulated_board, triad::sensor::AnyChip), runs the same `Sampler::step` per data-ready tick,
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

use triad::device::{sample_period_us, start_calibration, Outgoing, Sampler, StepOutcome};
use triad::model::Corrector;
use triad::sensor::interface::{I2cInterface, SpiInterface};
use triad::sensor::{AnyChip, Imu, ImuScale, RawSample, CHIP_NAMES};
use triad::stream::{Decoder, Frame};

/// The emulated board's chip models: the very code the firmware builds.
use triad_sim::emulated_board::{source, EmulatedChip, DESCRIPTION};

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

/// The emulated board's sensor as the firmware build chose it: the chip model
/// `TRIAD_EMULATED_CHIP` names on the bus `TRIAD_E2E_BUS` (spi or i2c), each
/// the board's default (the first listed chip, SPI) when unset; found on the
/// bus and started as the firmware does.
enum HostSensor {
    Spi(AnyChip<SpiInterface<EmulatedChip>>),
    I2c(AnyChip<I2cInterface<EmulatedChip>>),
}

/// Runs `$body` with `$s` bound to the driver, whatever the bus.
macro_rules! each_bus {
    ($sensor:expr, $s:ident => $body:expr) => {
        match $sensor {
            HostSensor::Spi($s) => $body,
            HostSensor::I2c($s) => $body,
        }
    };
}

impl HostSensor {
    /// The chip model and bus the firmware under test was built with.
    fn from_env() -> Self {
        let chip = std::env::var("TRIAD_EMULATED_CHIP").unwrap_or_else(|_| CHIP_NAMES[0].into());
        let bus = std::env::var("TRIAD_E2E_BUS").unwrap_or_else(|_| "spi".into());
        Self::new(&chip, &bus)
    }

    /// The model of `chip` on `bus` (spi, i2c), found and started as the firmware does.
    fn new(chip: &str, bus: &str) -> Self {
        let model = EmulatedChip::named(chip, model_source)
            .unwrap_or_else(|| panic!("{chip:?}: not one of {CHIP_NAMES:?}"));
        let mut sensor = match bus {
            "spi" => Self::Spi(AnyChip::detect(SpiInterface::new(model)).expect("found on SPI")),
            "i2c" => Self::I2c(AnyChip::detect_i2c(model).expect("found on I²C")),
            other => panic!("TRIAD_E2E_BUS {other:?}: expected spi or i2c"),
        };
        assert_eq!(each_bus!(&sensor, s => s.name()), chip, "the chip found");
        each_bus!(&mut sensor, s => s.start(&mut NoDelay).expect("the chip model starts"));
        sensor
    }

    /// The data-ready rate, Hz: the started chip's configuration's.
    fn sample_rate_hz(&self) -> f64 {
        each_bus!(self, s => s.sample_rate_hz())
    }

    /// The chip model.
    fn model(&self) -> &EmulatedChip {
        each_bus!(self, s => s.bus())
    }

    /// What the emulated board's `data_ready` does: the model's clock moves to its next sample.
    fn data_ready(&mut self) {
        each_bus!(self, s => s.bus_mut().advance_one_sample())
    }
}

impl Imu for HostSensor {
    type Error = String;

    fn read_sample(&mut self) -> Result<RawSample, String> {
        each_bus!(self, s => s.read_sample().map_err(|e| format!("{e:?}")))
    }

    fn scale(&self) -> ImuScale {
        each_bus!(self, s => s.scale())
    }
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
