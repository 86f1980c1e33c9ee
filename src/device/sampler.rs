//! One sample step, as the firmware's data-ready task runs it: read the chip,
//! correct, re-fold temperature terms at a low rate, average, frame. The RTIC
//! task calls [`Sampler::step`]; the end-to-end test calls the same function
//! on the same chip model, so the host computes exactly the device's numbers.

use super::counters::SamplerTotals;
use super::framer::Outgoing;
use super::{Control, Decimator, Framer, StepMonitor};
use crate::link::{Mode, RawScale};
use crate::model::{ClipFlags, Corrector, Sample};
use crate::sensor::{Imu, RawSample};
use crate::stream::TimestampUnwrapper;

/// Temperature terms change slower than this: re-folding ten times a second
/// keeps the fold within 0.1 s of the die temperature.
const REFOLDS_PER_SECOND: f64 = 10.0;

/// The data-ready period of a chip sampling at `rate_hz`, to the whole
/// microsecond: what the step monitor expects, the emulated board's timer
/// runs at, and the stream's timestamps step by.
pub fn sample_period_us(rate_hz: f64) -> u32 {
    libm::round(1e6 / rate_hz) as u32
}

/// What a step produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepOutcome<E> {
    /// A frame to stream.
    Frame(Outgoing),
    /// A sample went into the running average; nothing to stream yet.
    Averaging,
    /// The chip could not be read: the step is counted lost in the next frame.
    ReadFailed(E),
}

/// The state of the per-sample pipeline.
#[derive(Clone, Debug)]
pub struct Sampler {
    corrector: Corrector,
    decimator: Decimator,
    framer: Framer,
    monitor: StepMonitor,
    refold_every: u32,
    steps_since_refold: u32,
    mode: Mode,
    raw_scale: RawScale,
    totals: SamplerTotals,
    clock: TimestampUnwrapper,
    uptime_us: u64,
}

impl Sampler {
    /// A sampler streaming every `decimation`-th averaged sample, with steps
    /// expected every `period_us`, re-folding temperature terms every
    /// `refold_every` steps (0: never). `calibrated` false marks every frame
    /// UNCALIBRATED (the corrector holds the identity).
    pub fn new(
        corrector: Corrector,
        calibrated: bool,
        decimation: u16,
        period_us: u32,
        refold_every: u32,
    ) -> Self {
        let framer = Framer::new(corrector.calibration_id(), calibrated);
        let raw_scale = RawScale::of(corrector.scale());
        Self {
            corrector,
            decimator: Decimator::new(decimation),
            framer,
            monitor: StepMonitor::new(period_us),
            refold_every,
            steps_since_refold: 0,
            mode: Mode::Calibrated,
            raw_scale,
            totals: SamplerTotals::default(),
            clock: TimestampUnwrapper::new(),
            uptime_us: 0,
        }
    }

    /// A sampler for a chip sampling at `rate_hz`: steps expected every
    /// period (to the microsecond), temperature terms re-folded ten times a
    /// second. The firmware and the end-to-end test both build it this way.
    pub fn at_rate(corrector: Corrector, calibrated: bool, decimation: u16, rate_hz: f64) -> Self {
        let period_us = sample_period_us(rate_hz);
        let refold_every = libm::round(rate_hz / REFOLDS_PER_SECOND) as u32;
        Self::new(corrector, calibrated, decimation, period_us, refold_every)
    }

    /// One step that started at `now_us`: reads `imu`, corrects, averages and
    /// frames.
    #[inline]
    pub fn step<I: Imu>(&mut self, imu: &mut I, now_us: u32) -> StepOutcome<I::Error> {
        self.uptime_us = self.clock.unwrap(now_us);
        let missed = self.monitor.step_started(now_us);
        self.steps_lost(missed);
        let raw = match imu.read_sample() {
            Ok(raw) => raw,
            Err(error) => {
                self.steps_lost(1);
                self.totals.read_failures = self.totals.read_failures.wrapping_add(1);
                return StepOutcome::ReadFailed(error);
            }
        };
        let sample = match self.mode {
            Mode::Calibrated => self.corrector.correct(&raw),
            Mode::Raw => counts(&raw),
        };
        self.steps_since_refold += 1;
        if self.refold_every != 0 && self.steps_since_refold >= self.refold_every {
            self.steps_since_refold = 0;
            let temperature_c = match self.mode {
                Mode::Calibrated => f64::from(sample.temperature),
                Mode::Raw => self.corrector.scale().temperature_c(raw.temperature),
            };
            // A non-finite temperature is refused and the current fold stays.
            let _ = self.corrector.refold(temperature_c);
        }
        let Some(average) = self.decimator.push(&sample) else {
            return StepOutcome::Averaging;
        };
        self.totals.frames_sent = self.totals.frames_sent.wrapping_add(1);
        StepOutcome::Frame(match self.mode {
            Mode::Calibrated => Outgoing::Data(self.framer.frame(&average, now_us)),
            Mode::Raw => Outgoing::Raw(self.framer.raw_frame(&average, now_us, self.raw_scale)),
        })
    }

    /// Applies a change from the command handler; call it between two
    /// steps. A running average is restarted (its samples, at most
    /// decimation − 1, are not streamed), so no frame mixes two
    /// calibrations, modes or decimations.
    pub fn apply(&mut self, control: Control) {
        match control {
            Control::Calibrate(corrector) => {
                self.framer
                    .set_calibration(corrector.calibration_id(), true);
                self.corrector = corrector;
                self.steps_since_refold = self.refold_every;
                self.decimator = Decimator::new(self.decimator.factor());
            }
            Control::SetMode(mode) => {
                self.mode = mode;
                self.decimator = Decimator::new(self.decimator.factor());
            }
            Control::SetDecimation(factor) => self.decimator = Decimator::new(factor),
        }
    }

    /// What is streamed.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Samples averaged per frame.
    pub fn decimation(&self) -> u16 {
        self.decimator.factor()
    }

    /// Frames, drops, lost steps and read failures since start (wrapping).
    pub fn totals(&self) -> &SamplerTotals {
        &self.totals
    }

    /// Milliseconds since start at the latest step, by the step timestamps
    /// extended past their 71.6-minute wrap (wrapping every 2³² ms).
    pub fn uptime_ms(&self) -> u32 {
        (self.uptime_us / 1000) as u32
    }

    fn steps_lost(&mut self, count: u32) {
        self.framer.steps_lost(count);
        self.totals.overruns = self.totals.overruns.wrapping_add(count);
    }

    /// The step that just ended overran: the next one is already due.
    pub fn overran(&mut self) {
        self.steps_lost(1);
    }

    /// `frame` could not be queued for the link; see [`Framer::frame_dropped`].
    pub fn frame_dropped(&mut self, frame: &Outgoing) {
        self.framer.frame_dropped(frame);
        self.totals.frames_sent = self.totals.frames_sent.wrapping_sub(1);
        self.totals.frames_dropped = self.totals.frames_dropped.wrapping_add(1);
    }

    /// The corrector in use.
    pub fn corrector(&self) -> &Corrector {
        &self.corrector
    }
}

/// A raw reading as `f32` counts, chip axes, with its clip flags: what raw
/// mode averages and streams.
fn counts(raw: &RawSample) -> Sample {
    Sample {
        accel: raw.accel.map(f32::from),
        gyro: raw.gyro.map(f32::from),
        temperature: f32::from(raw.temperature),
        clip: ClipFlags::of(raw),
    }
}
