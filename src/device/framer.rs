//! Turning corrected samples into stream frames, with the counters and flags
//! of everything that went wrong since the previous frame.

use crate::model::{BatchKernel, Sample};
use crate::protocol::{encode, Flags, Frame, MAX_ENCODED_LEN};
use crate::protocol::{BatchFrame, RawFrame, RawScale, MAX_WIRE_LEN};
use crate::sensor::RawSample;

/// A frame for the link: corrected (calibrated mode) or raw.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outgoing {
    /// A data frame (version-1 layout).
    Data(Frame),
    /// A raw frame (version 2).
    Raw(RawFrame),
    /// W corrected samples in fixed point (version 2).
    Batch(BatchFrame),
}

/// What a frame carries of the framer's numbering and counters: what must
/// move to the next frame when it is dropped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Events {
    /// Its sequence number (given back to the next frame).
    pub sequence: u32,
    /// Frames dropped before it.
    pub dropped: u16,
    /// Steps lost before it.
    pub overruns: u16,
    /// Its flags.
    pub flags: Flags,
}

impl Outgoing {
    /// A batch of no samples: what a queue's slots hold before their first
    /// frame (a batch, so that the firmware's frames, batches at W > 1,
    /// are written into slots already of their kind).
    pub const EMPTY: Outgoing = Outgoing::Batch(BatchFrame::new(0.0, 0.0));

    /// The numbering and counters the frame carries.
    pub fn events(&self) -> Events {
        let (sequence, dropped, overruns, flags) = match self {
            Outgoing::Data(f) => (f.sequence, f.dropped, f.overruns, f.flags),
            Outgoing::Raw(f) => (f.sequence, f.dropped, f.overruns, f.flags),
            Outgoing::Batch(f) => (f.sequence, f.dropped, f.overruns, f.flags),
        };
        Events {
            sequence,
            dropped,
            overruns,
            flags,
        }
    }

    /// The frame's sequence number.
    pub fn sequence(&self) -> u32 {
        match self {
            Outgoing::Data(f) => f.sequence,
            Outgoing::Raw(f) => f.sequence,
            Outgoing::Batch(f) => f.sequence,
        }
    }

    /// The frame on the wire (stuffed, delimited) into `out`; returns its
    /// length (53 bytes for a data frame, 64 for a raw one, 53 + 12·W for a
    /// batch of W).
    pub fn to_wire(&self, out: &mut [u8; MAX_WIRE_LEN]) -> usize {
        match self {
            // Encoded in place: the wire buffer's first 53 bytes.
            Outgoing::Data(frame) => match out.first_chunk_mut::<MAX_ENCODED_LEN>() {
                Some(wire) => encode(frame, wire),
                None => 0,
            },
            // Written where they go: no packet built apart and copied.
            Outgoing::Raw(frame) => frame.to_wire(out).unwrap_or(0),
            Outgoing::Batch(frame) => frame.to_wire(out).unwrap_or(0),
        }
    }
}

/// Numbers the frames and carries the pending events into the next frame.
///
/// Sequence numbers count the frames handed to the link (docs/PROTOCOL.md): a
/// frame the firmware drops because the link is full gives its number back
/// and is counted in the next frame's `dropped`, so a sequence gap on the host
/// means loss on the wire, and `dropped` means loss at the source.
#[derive(Clone, Debug)]
pub struct Framer {
    sequence: u32,
    calibration_id: u32,
    calibrated: bool,
    overruns: u16,
    dropped: u16,
    fifo_overflow: bool,
    self_test: bool,
    flash_stall: bool,
}

impl Framer {
    /// A framer whose frames carry `calibration_id`; `calibrated` false sets
    /// the UNCALIBRATED flag on every frame (the embedded calibration was
    /// rejected and the identity is applied).
    pub const fn new(calibration_id: u32, calibrated: bool) -> Self {
        Self {
            sequence: 0,
            calibration_id,
            calibrated,
            overruns: 0,
            dropped: 0,
            fifo_overflow: false,
            self_test: false,
            flash_stall: false,
        }
    }

    /// From the next frame on, frames carry `calibration_id`, and
    /// `calibrated` false flags them UNCALIBRATED.
    pub fn set_calibration(&mut self, calibration_id: u32, calibrated: bool) {
        self.calibration_id = calibration_id;
        self.calibrated = calibrated;
    }

    /// `count` sample steps were late or produced no sample (the previous
    /// step overran, or the read failed): the next frame's `overruns`.
    pub fn steps_lost(&mut self, count: u32) {
        let count = u16::try_from(count).unwrap_or(u16::MAX);
        self.overruns = self.overruns.saturating_add(count);
    }

    /// The sensor reported samples lost in its FIFO.
    pub fn fifo_overflowed(&mut self) {
        self.fifo_overflow = true;
    }

    /// The chip ran its self-test: `count` samples were not measured (the
    /// next frame's `overruns`, with SELF_TEST).
    pub fn self_test_ran(&mut self, count: u32) {
        self.steps_lost(count);
        self.self_test = true;
    }

    /// The board's flash stalled the CPU (the next frame says FLASH_STALL).
    pub fn flash_stalled(&mut self) {
        self.flash_stall = true;
    }

    /// `frame` (returned by [`Framer::frame`]) could not be queued: it is
    /// counted as dropped, and the events it carried move to the next frame
    /// so that no count is lost with it.
    pub fn frame_dropped(&mut self, frame: &Outgoing) {
        self.events_dropped(frame.events());
    }

    /// A frame that carried `events` could not be queued (see
    /// [`Framer::frame_dropped`]).
    pub fn events_dropped(&mut self, events: Events) {
        self.sequence = events.sequence;
        self.dropped = self
            .dropped
            .saturating_add(events.dropped)
            .saturating_add(1);
        self.overruns = self.overruns.saturating_add(events.overruns);
        self.fifo_overflow |= events.flags.contains(Flags::FIFO_OVERFLOW);
        self.self_test |= events.flags.contains(Flags::SELF_TEST);
        self.flash_stall |= events.flags.contains(Flags::FLASH_STALL);
    }

    /// The next frame: `sample` at `timestamp_us`, with the events pending
    /// since the previous frame, which are then cleared.
    pub fn frame(&mut self, sample: &Sample, timestamp_us: u32) -> Frame {
        let mut flags = self.pending_flags(sample);
        flags.set(Flags::UNCALIBRATED, !self.calibrated);
        let frame = Frame {
            sequence: self.sequence,
            timestamp_us,
            flags,
            overruns: self.overruns,
            dropped: self.dropped,
            calibration_id: self.calibration_id,
            accel: sample.accel,
            gyro: sample.gyro,
            temperature: sample.temperature,
        };
        self.next();
        frame
    }

    /// The next frame in raw mode: `counts` (the chip's counts as `f32`,
    /// averaged) at `timestamp_us`, with the chip's `scale` and the events
    /// pending since the previous frame, which are then cleared.
    pub fn raw_frame(&mut self, counts: &Sample, timestamp_us: u32, scale: RawScale) -> RawFrame {
        let flags = self.pending_flags(counts) | Flags::RAW | Flags::UNCALIBRATED;
        let frame = RawFrame {
            sequence: self.sequence,
            timestamp_us,
            flags,
            overruns: self.overruns,
            dropped: self.dropped,
            accel: counts.accel,
            gyro: counts.gyro,
            temperature: counts.temperature,
            scale,
        };
        self.next();
        frame
    }

    /// The next batch: `raw` (at most [`crate::protocol::batch_frame::MAX_BATCH`]
    /// samples; the rest are left out) corrected by `kernel`, the first at
    /// `timestamp_us` and the others `period_ns` apart, at
    /// `temperature` °C, with the events pending since the previous frame,
    /// which are then cleared.
    pub fn batch_frame(
        &mut self,
        kernel: &BatchKernel,
        raw: &[RawSample],
        timestamp_us: u32,
        period_ns: u32,
        temperature: f32,
    ) -> BatchFrame {
        let mut frame = BatchFrame::new(0.0, 0.0);
        self.fill_batch(
            &mut frame,
            kernel,
            raw,
            timestamp_us,
            period_ns,
            temperature,
        );
        frame
    }

    /// [`Framer::batch_frame`] written into `slot`, where it lies when the
    /// slot holds a batch already (the link queue's slots do): no frame is
    /// built apart and copied.
    #[inline]
    pub fn batch_frame_into(
        &mut self,
        slot: &mut Outgoing,
        kernel: &BatchKernel,
        raw: &[RawSample],
        timestamp_us: u32,
        period_ns: u32,
        temperature: f32,
    ) {
        match slot {
            Outgoing::Batch(frame) => {
                self.fill_batch(frame, kernel, raw, timestamp_us, period_ns, temperature)
            }
            other => {
                *other = Outgoing::Batch(self.batch_frame(
                    kernel,
                    raw,
                    timestamp_us,
                    period_ns,
                    temperature,
                ))
            }
        }
    }

    /// A frame was due but the link's queue had no room, so it was not
    /// built: what [`Framer::events_dropped`] does for a frame built then
    /// refused (its number given back, its events carried on), without
    /// the frame.
    pub fn frame_skipped(&mut self) {
        self.dropped = self.dropped.saturating_add(1);
    }

    /// `frame` emptied and filled as [`Framer::batch_frame`] describes.
    #[inline(always)]
    fn fill_batch(
        &mut self,
        frame: &mut BatchFrame,
        kernel: &BatchKernel,
        raw: &[RawSample],
        timestamp_us: u32,
        period_ns: u32,
        temperature: f32,
    ) {
        frame.clear(kernel.accel_lsb(), kernel.gyro_lsb());
        frame.push_raw(kernel, raw);
        let mut flags = self.pending_flags(&Sample::default()) | frame.flags;
        flags.set(Flags::UNCALIBRATED, !self.calibrated);
        frame.sequence = self.sequence;
        frame.timestamp_us = timestamp_us;
        frame.period_ns = period_ns;
        frame.flags = flags;
        frame.overruns = self.overruns;
        frame.dropped = self.dropped;
        frame.calibration_id = self.calibration_id;
        frame.temperature = temperature;
        self.next();
    }

    /// The flags of the sample and of the events pending.
    fn pending_flags(&self, sample: &Sample) -> Flags {
        let mut flags = Flags::empty();
        flags.set(Flags::ACCEL_CLIPPED, sample.clip.accel);
        flags.set(Flags::GYRO_CLIPPED, sample.clip.gyro);
        flags.set(Flags::OVERRUN, self.overruns > 0);
        flags.set(Flags::DROPPED, self.dropped > 0);
        flags.set(Flags::FIFO_OVERFLOW, self.fifo_overflow);
        flags.set(Flags::SELF_TEST, self.self_test);
        flags.set(Flags::FLASH_STALL, self.flash_stall);
        flags
    }

    /// Numbers the next frame and clears the events carried.
    fn next(&mut self) {
        self.sequence = self.sequence.wrapping_add(1);
        self.overruns = 0;
        self.dropped = 0;
        self.fifo_overflow = false;
        self.self_test = false;
        self.flash_stall = false;
    }
}
