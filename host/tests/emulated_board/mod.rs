//! The emulated board's sensor rebuilt on the host: the chip model the
//! firmware reads, found and started by the same driver, so a test knows
//! every raw sample the firmware read (the model moves to its next sample at
//! each data-ready step, whatever the clock). Shared by the end-to-end tests
//! on QEMU (`e2e_qemu.rs`, `device_qemu.rs`); each uses a part of it.
#![allow(dead_code)]

pub mod capture;
pub mod decoded_csv;
pub mod slower_held;
pub mod triad_correct;

use triad::sensor::interface::{I2cInterface, SpiInterface};
use triad::sensor::{AnyChip, FifoImu, FifoRead, Imu, ImuScale, RawSample, Settings, CHIP_NAMES};

use triad::device::{start_calibration, Sampler};
use triad_sim::chips::emulated_board::DESCRIPTION;

/// The emulated board's chip models: the very code the firmware builds.
use triad_sim::chips::emulated_board::{source, EmulatedChip};

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
pub enum HostSensor {
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
    /// The chip model, bus and sampling settings the firmware under test
    /// was built with (TRIAD_SAMPLE_RATE_HZ and TRIAD_FIFO_WATERMARK, as
    /// firmware/build.rs reads them).
    pub fn from_env() -> Self {
        let chip = std::env::var("TRIAD_EMULATED_CHIP").unwrap_or_else(|_| CHIP_NAMES[0].into());
        let bus = std::env::var("TRIAD_E2E_BUS").unwrap_or_else(|_| "spi".into());
        Self::with_settings(&chip, &bus, &settings_from_env())
    }

    /// The model of `chip` on `bus` (spi, i2c), found and started as the firmware does.
    pub fn new(chip: &str, bus: &str) -> Self {
        Self::with_settings(chip, bus, &Settings::DEFAULT)
    }

    /// As [`Self::new`], started with `settings` (rate and FIFO watermark).
    pub fn with_settings(chip: &str, bus: &str, settings: &Settings) -> Self {
        let model =
            EmulatedChip::named_at(chip, settings.rate_hz, model_source).unwrap_or_else(|| {
                panic!(
                    "{chip:?} at {:?} Hz: not one of {CHIP_NAMES:?} or not its rate",
                    settings.rate_hz
                )
            });
        let mut sensor = match bus {
            "spi" => Self::Spi(AnyChip::detect(SpiInterface::new(model)).expect("found on SPI")),
            "i2c" => Self::I2c(AnyChip::detect_i2c(model).expect("found on I²C")),
            other => panic!("TRIAD_E2E_BUS {other:?}: expected spi or i2c"),
        };
        assert_eq!(each_bus!(&sensor, s => s.name()), chip, "the chip found");
        each_bus!(&mut sensor, s => s.start_with(&mut NoDelay, settings).expect("the chip model starts"));
        sensor
    }

    /// The data-ready rate, Hz: the started chip's configuration's.
    pub fn sample_rate_hz(&self) -> f64 {
        each_bus!(self, s => s.sample_rate_hz())
    }

    /// The chip model.
    pub fn model(&self) -> &EmulatedChip {
        each_bus!(self, s => s.bus())
    }

    /// What the emulated board's `data_ready` does: the model's clock moves to its next sample.
    pub fn data_ready(&mut self) {
        self.advance(1)
    }

    /// The emulated board's `data_ready` with a FIFO watermark of `samples`.
    pub fn advance(&mut self, samples: u16) {
        each_bus!(self, s => (0..samples).for_each(|_| s.bus_mut().advance_one_sample()))
    }
}

/// The firmware build's sampling settings, from the variables firmware/build.rs reads.
pub fn settings_from_env() -> Settings {
    let number = |name: &str| {
        std::env::var(name)
            .ok()
            .map(|v| v.parse::<u32>().unwrap_or_else(|_| panic!("{name}={v:?}")))
    };
    let slower = match (number("TRIAD_ACCEL_RATE_HZ"), number("TRIAD_GYRO_RATE_HZ")) {
        (Some(hz), _) => Some((triad::model::Triad::Accel, hz)),
        (None, Some(hz)) => Some((triad::model::Triad::Gyro, hz)),
        (None, None) => None,
    };
    Settings {
        rate_hz: number("TRIAD_SAMPLE_RATE_HZ"),
        slower,
        watermark: number("TRIAD_FIFO_WATERMARK").map_or(1, |w| w as u16),
        high_resolution: number("TRIAD_FIFO_HIGH_RESOLUTION") == Some(1),
    }
}

impl FifoImu for HostSensor {
    fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<FifoRead, String> {
        each_bus!(self, s => s.read_fifo(out).map_err(|e| format!("{e:?}")))
    }

    fn reset_fifo(&mut self) -> Result<(), String> {
        each_bus!(self, s => s.reset_fifo().map_err(|e| format!("{e:?}")))
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

/// The raw sample behind each streamed frame, by the frame's sequence
/// number: with decimation 1, frame n is the (n+1)-th data-ready step, which
/// read the model's (n+1)-th sample. That holds while the device drops no
/// frame (a dropped frame's number is reused) and every read succeeds (a
/// failed read makes no frame); steps lost to overruns do not matter, as
/// the model advances per step taken, not per period of the clock. The
/// caller checks the device's counters for both.
pub struct Replay {
    sensor: HostSensor,
    samples: Vec<RawSample>,
}

impl Replay {
    /// The sensor of [`HostSensor::from_env`], before its first step.
    pub fn from_env() -> Self {
        Replay {
            sensor: HostSensor::from_env(),
            samples: Vec::new(),
        }
    }

    /// The chip's scale.
    pub fn scale(&self) -> ImuScale {
        self.sensor.scale()
    }

    /// The raw sample frame `sequence` was made from.
    pub fn of_frame(&mut self, sequence: u32) -> RawSample {
        let n = sequence as usize;
        while self.samples.len() <= n {
            self.sensor.data_ready();
            let raw = self.sensor.read_sample().expect("the model reads");
            self.samples.push(raw);
        }
        self.samples[n]
    }
}

/// The host's sampler for `sensor` as the firmware starts it
/// (firmware/src/start.rs): the embedded calibration (TRIAD_E2E_BLOB), the
/// board's orientation and decimation, the chip's rate.
pub fn host_sampler(sensor: &HostSensor) -> Sampler {
    let blob = std::fs::read(capture::env_path("TRIAD_E2E_BLOB")).expect("calibration blob");
    let startup = start_calibration(None, &blob, &sensor.scale(), DESCRIPTION.orientation)
        .expect("the chip's scale is valid");
    assert!(startup.rejected.is_none(), "{:?}", startup.rejected);
    let calibrated = startup.calibrated();
    Sampler::at_rate(
        startup.corrector,
        calibrated,
        DESCRIPTION.decimation,
        sensor.sample_rate_hz(),
    )
}
