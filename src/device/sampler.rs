//! One sample step, as the firmware's data-ready task runs it: read the chip,
//! correct, re-fold temperature terms at a low rate, average, frame. The RTIC
//! task calls [`Sampler::step`]; the end-to-end test calls the same function
//! on the same chip model, so the host computes exactly the device's numbers.

use super::{Decimator, Framer, StepMonitor};
use crate::model::Corrector;
use crate::sensor::Imu;
use crate::stream::Frame;

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
    Frame(Frame),
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
        Self {
            corrector,
            decimator: Decimator::new(decimation),
            framer,
            monitor: StepMonitor::new(period_us),
            refold_every,
            steps_since_refold: 0,
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
        let missed = self.monitor.step_started(now_us);
        self.framer.steps_lost(missed);
        let raw = match imu.read_sample() {
            Ok(raw) => raw,
            Err(error) => {
                self.framer.steps_lost(1);
                return StepOutcome::ReadFailed(error);
            }
        };
        let sample = self.corrector.correct(&raw);
        self.steps_since_refold += 1;
        if self.refold_every != 0 && self.steps_since_refold >= self.refold_every {
            self.steps_since_refold = 0;
            // A non-finite temperature is refused and the current fold stays.
            let _ = self.corrector.refold(f64::from(sample.temperature));
        }
        match self.decimator.push(&sample) {
            Some(average) => StepOutcome::Frame(self.framer.frame(&average, now_us)),
            None => StepOutcome::Averaging,
        }
    }

    /// The step that just ended overran: the next one is already due.
    pub fn overran(&mut self) {
        self.framer.steps_lost(1);
    }

    /// `frame` could not be queued for the link; see [`Framer::frame_dropped`].
    pub fn frame_dropped(&mut self, frame: &Frame) {
        self.framer.frame_dropped(frame);
    }

    /// The corrector in use.
    pub fn corrector(&self) -> &Corrector {
        &self.corrector
    }
}
