//! One sample step, as the firmware's data-ready task runs it: read the chip,
//! correct, re-fold temperature terms at a low rate, average, frame. The RTIC
//! task calls [`Sampler::step`]; the end-to-end test calls the same function
//! on the same chip model, so the host computes exactly the device's numbers.

use super::counters::SamplerTotals;
use super::frame_sink::{ByValue, FrameSink};
use super::framer::{Events, Outgoing};
use super::{Control, Decimator, Framer, StepMonitor};
use crate::model::corrector::counts_f32;
use crate::model::{BatchKernel, ClipFlags, Corrector, Sample};
use crate::protocol::TimestampUnwrapper;
use crate::protocol::{Mode, RawScale, MAX_BATCH};
use crate::sensor::{FifoImu, Imu, ImuScale, RawSample};

/// Temperature terms change slower than this: re-folding ten times a second
/// keeps the fold within 0.1 s of the die temperature.
const REFOLDS_PER_SECOND: f64 = 10.0;

/// The data-ready period of a chip sampling at `rate_hz`, to the whole
/// microsecond: what the step monitor expects, the emulated board's timer
/// runs at, and the stream's timestamps step by.
pub fn sample_period_us(rate_hz: f64) -> u32 {
    libm::round(1e6 / rate_hz) as u32
}

/// Most samples one FIFO read takes: the largest watermark the firmware
/// offers. More waiting are read by a further read in the same step.
pub const FIFO_READ_MAX: usize = 32;

/// FIFO reads one step makes at most: a step that finds the FIFO still not
/// empty after them leaves the rest for the next interrupt, so a stuck chip
/// cannot hold the task.
const FIFO_READS_PER_STEP: usize = 4;

/// What a FIFO step did: frames queued and dropped, and a read that failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FifoStepped<E> {
    /// Frames handed to the link.
    pub queued: u16,
    /// Frames the link's queue had no room for (counted in the next frame).
    pub dropped: u16,
    /// Samples read from the FIFO.
    pub samples: u16,
    /// The FIFO could not be read: the error (counted as a read failure).
    pub read_failed: Option<E>,
}

impl<E> FifoStepped<E> {
    /// One frame offered: queued, or dropped.
    fn count(&mut self, queued: bool) {
        match queued {
            true => self.queued = self.queued.saturating_add(1),
            false => self.dropped = self.dropped.saturating_add(1),
        }
    }
}

/// What a step produced.
// A frame is moved into the link's queue at once, never kept: its size
// (a batch's 232 bytes) is what the queue's slots hold anyway.
#[allow(clippy::large_enum_variant)]
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
    kernel: BatchKernel,
    period_ns: u32,
    /// When the chip was handed to its self-test (µs), while it is away.
    self_test_from: Option<u32>,
    /// FIFO mode: the time of the newest sample read (µs).
    last_sample_us: u32,
    /// FIFO mode: the chip was restarted (or went silent) since the sample
    /// at this time (µs), the newest read before; see [`Sampler::chip_restarted`].
    restart_from: Option<u32>,
    /// Whether batch frames carry the chip's resolution ([`batch_frames_fit`]).
    batch_frames: bool,
}

/// Whether a batch frame's 16-bit counts (1.5 chip LSBs, docs/PROTOCOL.md
/// §20) carry the resolution of a chip of `scale`: a 16-bit chip's, yes;
/// the ICM-42688-P's 20-bit FIFO values (4 and 8 times finer) go out in
/// data frames, whose f32 values hold them, so the extra bits reach the
/// host (one frame per sample: the link's rate limits apply).
pub fn batch_frames_fit(scale: &ImuScale) -> bool {
    let sixteen_bit = crate::sensor::CodeRange::I16.magnitude;
    scale.accel.codes.magnitude <= sixteen_bit && scale.gyro.codes.magnitude <= sixteen_bit
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
        let kernel = BatchKernel::new(&corrector);
        let batch_frames = batch_frames_fit(corrector.scale());
        Self {
            batch_frames,
            kernel,
            period_ns: period_us.saturating_mul(1000),
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
            self_test_from: None,
            last_sample_us: 0,
            restart_from: None,
        }
    }

    /// A sampler for a chip sampling at `rate_hz`: steps expected every
    /// period (to the microsecond), temperature terms re-folded ten times a
    /// second. The firmware and the end-to-end test both build it this way.
    pub fn at_rate(corrector: Corrector, calibrated: bool, decimation: u16, rate_hz: f64) -> Self {
        let period_us = sample_period_us(rate_hz);
        let refold_every = libm::round(rate_hz / REFOLDS_PER_SECOND) as u32;
        let mut sampler = Self::new(corrector, calibrated, decimation, period_us, refold_every);
        sampler.period_ns = libm::round(1e9 / rate_hz) as u32;
        sampler
    }

    /// One step that started at `now_us`: reads `imu`, corrects, averages and
    /// frames.
    #[inline]
    pub fn step<I: Imu>(&mut self, imu: &mut I, now_us: u32) -> StepOutcome<I::Error> {
        self.uptime_us = self.clock.unwrap(now_us);
        let missed = self.monitor.step_started(now_us);
        // The step monitor counts a restart's gap here, by the steps' times.
        self.restart_from = None;
        match self.self_test_from.take() {
            // The gap is the self-test's, counted once.
            Some(from) => self.self_test_ended(from, now_us),
            None => self.steps_lost(missed),
        }
        let raw = match imu.read_sample() {
            Ok(raw) => raw,
            Err(error) => {
                self.steps_lost(1);
                self.totals.read_failures = self.totals.read_failures.wrapping_add(1);
                return StepOutcome::ReadFailed(error);
            }
        };
        match self.process(&raw, now_us) {
            Some(frame) => StepOutcome::Frame(frame),
            None => StepOutcome::Averaging,
        }
    }

    /// One sample through the per-sample pipeline: corrected (or counted in
    /// raw mode), the temperature terms re-folded when due, averaged, and
    /// framed at `timestamp_us` when the average is complete.
    fn process(&mut self, raw: &RawSample, timestamp_us: u32) -> Option<Outgoing> {
        let sample = match self.mode {
            Mode::Calibrated => self.corrector.correct(raw),
            Mode::Raw => counts(raw, self.corrector.scale()),
        };
        if self.refold_due(1) {
            let temperature_c = match self.mode {
                Mode::Calibrated => f64::from(sample.temperature),
                Mode::Raw => self.corrector.scale().temperature_c(raw.temperature),
            };
            self.refold(temperature_c);
        }
        let average = self.decimator.push(&sample)?;
        self.totals.frames_sent = self.totals.frames_sent.wrapping_add(1);
        Some(match self.mode {
            Mode::Calibrated => Outgoing::Data(self.framer.frame(&average, timestamp_us)),
            Mode::Raw => Outgoing::Raw(self.framer.raw_frame(
                &average,
                timestamp_us,
                self.raw_scale,
            )),
        })
    }

    /// Counts `samples` toward the next re-fold of the temperature terms;
    /// true when one is due (the count then restarts). Never without
    /// temperature terms: the refold (f64 in software on the Cortex-M4F,
    /// and the batch kernel remade) would give the coefficients already
    /// folded.
    fn refold_due(&mut self, samples: u32) -> bool {
        if !self.corrector.has_temperature_terms() {
            return false;
        }
        self.steps_since_refold += samples;
        let due = self.refold_every != 0 && self.steps_since_refold >= self.refold_every;
        if due {
            self.steps_since_refold = 0;
        }
        due
    }

    /// Re-folds the temperature terms at `temperature_c`, the batch kernel
    /// with them. A non-finite temperature is refused and the fold stays.
    /// Out of line: the new kernel is built in this function's frame, not
    /// in that of every step (a low-rate call).
    #[inline(never)]
    fn refold(&mut self, temperature_c: f64) {
        if self.corrector.refold(temperature_c).is_ok() {
            self.kernel = BatchKernel::new(&self.corrector);
        }
    }

    /// One FIFO watermark interrupt at `now_us`: drains the FIFO and frames
    /// every sample, offering each frame to `enqueue` (false when the link's
    /// queue is full: the frame is then counted dropped). In
    /// calibrated mode without averaging the samples go out in batch frames
    /// of up to [`MAX_BATCH`] where those carry the chip's resolution
    /// ([`batch_frames_fit`]); otherwise each goes through the per-sample
    /// pipeline (raw frames, or data frames: averages, or each sample).
    ///
    /// Timestamps: the newest sample in the FIFO is taken to have arrived at
    /// `now_us` and the others one chip period apart before it (the
    /// interrupt's time and the ODR, not the chip's FIFO timestamps). The
    /// error is the interrupt's latency (the task's entry, and any
    /// higher-priority work before it) plus at most one period when a
    /// sample arrived between the interrupt and the FIFO count's read, and
    /// the chip's clock error over one batch. A FIFO overflow sets
    /// FIFO_OVERFLOW and counts the samples lost as overruns.
    pub fn step_fifo<I: FifoImu>(
        &mut self,
        imu: &mut I,
        now_us: u32,
        enqueue: impl FnMut(Outgoing) -> bool,
    ) -> FifoStepped<I::Error> {
        self.step_fifo_into(imu, now_us, &mut ByValue::new(enqueue))
    }

    /// [`Sampler::step_fifo`] with each frame written into the next slot
    /// of `sink` (the firmware's link queue): a batch is built where the
    /// transmitter reads it, and a frame the sink has no room for is not
    /// built, only counted dropped.
    pub fn step_fifo_into<I: FifoImu>(
        &mut self,
        imu: &mut I,
        now_us: u32,
        sink: &mut impl FrameSink,
    ) -> FifoStepped<I::Error> {
        self.uptime_us = self.clock.unwrap(now_us);
        let mut stepped = FifoStepped {
            queued: 0,
            dropped: 0,
            samples: 0,
            read_failed: None,
        };
        let mut buffer = [RawSample::default(); FIFO_READ_MAX];
        // Back from a self-test: its FIFO, flushed by the procedure's end,
        // may report an overflow; those samples are inside the gap the
        // self-test's count covers, so an overflow before the first sample
        // read is not counted again (nor flagged: the chip lost nothing in
        // sampling).
        let mut self_test_from = self.self_test_from.take();
        // Likewise after a restart: the gap since the newest sample read
        // before it holds whatever the FIFO lost.
        let mut restart_from = self.restart_from.take();
        for _ in 0..FIFO_READS_PER_STEP {
            let read = match imu.read_fifo(&mut buffer) {
                Ok(read) => read,
                Err(error) => {
                    self.totals.read_failures = self.totals.read_failures.wrapping_add(1);
                    stepped.read_failed = Some(error);
                    break;
                }
            };
            if read.overflowed && self_test_from.is_none() && restart_from.is_none() {
                self.framer.fifo_overflowed();
                self.steps_lost(read.lost);
            }
            let samples = &buffer[..read.samples.min(FIFO_READ_MAX)];
            stepped.samples = stepped.samples.saturating_add(samples.len() as u16);
            // Samples before the newest, which arrived at now_us.
            let behind = (samples.len() + usize::from(read.remaining)).saturating_sub(1);
            let first_us = now_us.wrapping_sub(self.span_us(behind));
            // The first sample read after the self-test dates its end.
            if !samples.is_empty() {
                if let Some(from) = self_test_from.take() {
                    self.self_test_ended(from, first_us);
                }
                if let Some(from) = restart_from.take() {
                    let lost = periods_between(from, first_us, self.period_ns).saturating_sub(1);
                    self.steps_lost(lost);
                }
                self.last_sample_us = first_us.wrapping_add(self.span_us(samples.len() - 1));
            }
            if self.mode == Mode::Calibrated && self.decimator.factor() == 1 && self.batch_frames {
                for (i, chunk) in samples.chunks(MAX_BATCH).enumerate() {
                    let timestamp = first_us.wrapping_add(self.span_us(i * MAX_BATCH));
                    let queued = self.batch_into(sink, chunk, timestamp);
                    stepped.count(queued);
                }
            } else {
                for (i, raw) in samples.iter().enumerate() {
                    let timestamp = first_us.wrapping_add(self.span_us(i));
                    if let Some(frame) = self.process(raw, timestamp) {
                        let queued = self.offer(sink, frame);
                        stepped.count(queued);
                    }
                }
            }
            if read.remaining == 0 {
                break;
            }
        }
        // No sample yet: the next step dates the self-test's end (or the
        // restart's).
        self.self_test_from = self_test_from;
        self.restart_from = restart_from;
        stepped
    }

    /// `samples` chip periods, µs (rounded down).
    fn span_us(&self, samples: usize) -> u32 {
        span_us(samples, self.period_ns)
    }

    /// One batch frame of `chunk` (≤ [`MAX_BATCH`] samples) at
    /// `timestamp_us`, written into `sink`'s next slot; true when queued.
    /// Without room it is not built but counted dropped (the temperature
    /// terms are re-folded on schedule all the same).
    #[inline]
    fn batch_into(
        &mut self,
        sink: &mut impl FrameSink,
        chunk: &[RawSample],
        timestamp_us: u32,
    ) -> bool {
        // The mean in f32, converted as the per-sample path converts (f64
        // would be library calls on the Cortex-M4F).
        let sum: i32 = chunk.iter().map(|r| i32::from(r.temperature)).sum();
        let mean_counts = sum as f32 / chunk.len().max(1) as f32;
        let temperature_c = self.corrector.temperature_c(mean_counts);
        if self.refold_due(chunk.len() as u32) {
            self.refold(f64::from(temperature_c));
        }
        let Some(slot) = sink.slot() else {
            self.frame_skipped();
            return false;
        };
        self.totals.frames_sent = self.totals.frames_sent.wrapping_add(1);
        self.framer.batch_frame_into(
            slot,
            &self.kernel,
            chunk,
            timestamp_us,
            self.period_ns,
            temperature_c,
        );
        let events = slot.events();
        self.committed(sink, events)
    }

    /// `frame`, made already, copied into `sink`'s next slot; true when
    /// queued, else counted dropped.
    fn offer(&mut self, sink: &mut impl FrameSink, frame: Outgoing) -> bool {
        let Some(slot) = sink.slot() else {
            // Made and counted sent: given back as a frame refused.
            self.events_dropped(frame.events());
            return false;
        };
        *slot = frame;
        self.committed(sink, frame.events())
    }

    /// Commits the frame written into `sink`'s slot, which carries
    /// `events`; true when queued, else counted dropped.
    #[inline(always)]
    fn committed(&mut self, sink: &mut impl FrameSink, events: Events) -> bool {
        let queued = sink.commit();
        if !queued {
            self.events_dropped(events);
        }
        queued
    }

    /// A frame was due and the link had no room: not built, counted dropped.
    fn frame_skipped(&mut self) {
        self.framer.frame_skipped();
        self.totals.frames_dropped = self.totals.frames_dropped.wrapping_add(1);
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
                self.kernel = BatchKernel::new(&corrector);
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
        div_1000(self.uptime_us) as u32
    }

    fn steps_lost(&mut self, count: u32) {
        self.framer.steps_lost(count);
        self.totals.overruns = self.totals.overruns.wrapping_add(count);
    }

    /// The step that just ended overran: the next one is already due.
    pub fn overran(&mut self) {
        self.steps_lost(1);
    }

    /// The chip goes to its self-test after the step just made (whose
    /// samples were read): it measures nothing for the stream until it is
    /// back. The first step after counts the chip's sample periods from
    /// the last sample read before to the first read after (those two
    /// excluded) as not measured: that step's first frame says SELF_TEST
    /// with them in `overruns`, and the step monitor does not count the gap
    /// again. Exact to the frames' own timestamps: the periods between the
    /// two samples' times, rounded to the nearest whole one.
    pub fn self_test_began(&mut self) {
        self.self_test_from = Some(self.uptime_us as u32);
    }

    /// The chip went silent and was restarted (or is being: a stall, or
    /// failed reads): in FIFO mode the samples it held and those it did not
    /// make are gone. The first FIFO step that reads a sample again counts
    /// the chip's periods from the newest sample read before to the first
    /// read after (those two excluded) as lost (`overruns`, OVERRUN), as
    /// [`Sampler::self_test_began`] does, and not again as an overflow.
    /// Per sample ([`Sampler::step`]) the step monitor counts the gap.
    pub fn chip_restarted(&mut self) {
        if self.restart_from.is_none() {
            self.restart_from = Some(self.last_sample_us);
        }
    }

    /// The chip is back: `first_us` is the time of the first sample read
    /// since the self-test began (see [`Sampler::self_test_began`]).
    #[cold]
    fn self_test_ended(&mut self, from: u32, first_us: u32) {
        let lost = periods_between(from, first_us, self.period_ns).saturating_sub(1);
        self.framer.self_test_ran(lost);
        self.totals.overruns = self.totals.overruns.wrapping_add(lost);
    }

    /// The board's flash stalled the CPU since the previous step (see
    /// [`crate::device::board::Board::flash_stalls`]): the next frame, which
    /// carries the samples missed meanwhile, says FLASH_STALL.
    pub fn flash_stalled(&mut self) {
        self.framer.flash_stalled();
    }

    /// True while the chip is in its self-test.
    pub fn in_self_test(&self) -> bool {
        self.self_test_from.is_some()
    }

    /// `frame` could not be queued for the link; see [`Framer::frame_dropped`].
    pub fn frame_dropped(&mut self, frame: &Outgoing) {
        self.events_dropped(frame.events());
    }

    /// A frame carrying `events` could not be queued for the link.
    fn events_dropped(&mut self, events: Events) {
        self.framer.events_dropped(events);
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
fn counts(raw: &RawSample, scale: &ImuScale) -> Sample {
    Sample {
        accel: counts_f32(&raw.accel),
        gyro: counts_f32(&raw.gyro),
        temperature: f32::from(raw.temperature),
        clip: ClipFlags::of(raw, scale),
    }
}

/// `samples` periods of `period_ns`, in µs rounded down (wrapping at 2³²
/// µs): n·p/1000 as n·(p div 1000) + n·(p mod 1000) div 1000, the same
/// quotient, in 32-bit operations while n·(p mod 1000) fits (every FIFO's
/// n), where the 64-bit division is a library call of a few hundred
/// instructions on the Cortex-M4F, twice per data-ready step.
fn span_us(samples: usize, period_ns: u32) -> u32 {
    let (whole_us, part_ns) = (period_ns / 1000, period_ns % 1000);
    match u32::try_from(samples)
        .ok()
        .filter(|&n| n <= u32::MAX / 1000)
    {
        Some(n) => n.wrapping_mul(whole_us).wrapping_add(n * part_ns / 1000),
        None => (samples as u64 * u64::from(period_ns) / 1000) as u32,
    }
}

/// `x / 1000`, by long division in 16-bit digits: each step divides a
/// number below 1000·2¹⁶ in 32 bits, one instruction on the Cortex-M4F,
/// where a 64-bit division is a library call of a few hundred (the task
/// publishes the uptime at every step).
fn div_1000(x: u64) -> u64 {
    let mut quotient = 0u64;
    let mut remainder = 0u32;
    for shift in [48, 32, 16, 0] {
        let digit = ((x >> shift) & 0xFFFF) as u32;
        let partial = (remainder << 16) | digit;
        quotient = (quotient << 16) | u64::from(partial / 1000);
        remainder = partial % 1000;
    }
    quotient
}

/// Whole chip periods of `period_ns` from `from_us` to `to_us` (wrapping
/// µs), rounded to the nearest: exact to the frames' own timestamps.
fn periods_between(from_us: u32, to_us: u32, period_ns: u32) -> u32 {
    let elapsed_ns = u64::from(to_us.wrapping_sub(from_us)) * 1000;
    let period_ns = u64::from(period_ns.max(1));
    u32::try_from((elapsed_ns + period_ns / 2) / period_ns).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::{div_1000, span_us};

    #[test]
    fn a_span_in_32_bits_is_the_64_bit_quotient() {
        for period_ns in [1, 999, 1000, 125_000, 1_000_000 / 3, 20_833_333, u32::MAX] {
            for samples in [
                0usize,
                1,
                2,
                15,
                16,
                31,
                32,
                511,
                4_294_967,
                4_294_968,
                1 << 31,
            ] {
                let expected = (samples as u128 * u128::from(period_ns) / 1000) as u32;
                assert_eq!(
                    span_us(samples, period_ns),
                    expected,
                    "{samples} × {period_ns} ns"
                );
            }
        }
    }

    #[test]
    fn the_long_division_by_1000_is_the_division() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let edges = [
            0,
            1,
            999,
            1000,
            65_535_999,
            1 << 32,
            u64::from(u32::MAX) * 1000 + 999,
            u64::MAX,
        ];
        for v in edges.into_iter().chain((0..10_000).map(|_| {
            // xorshift64: values of every magnitude.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x >> (x % 64)
        })) {
            assert_eq!(div_1000(v), v / 1000, "{v}");
        }
    }
}
