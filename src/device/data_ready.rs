//! The data-ready step as the firmware's highest-priority task runs it, on
//! any board: acknowledge, timestamp, read-correct-average-frame, queue the
//! frame for the link (counting it dropped when the queue is full), and
//! notice when the step overran into the next one. With the chip's FIFO on,
//! the same for a watermark interrupt ([`on_fifo_ready`]): every sample
//! waiting, in batch frames.

use super::board::{DataReadyLine, MicrosecondClock};
use super::frame_sink::FrameSink;
use super::framer::Outgoing;
use super::sampler::FifoStepped;
use super::{Sampler, StepOutcome};
use crate::sensor::{FifoImu, Imu};

/// What one data-ready step did, for the caller to log or to wake the sender.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stepped<E> {
    /// A frame was queued for the link.
    Queued,
    /// A frame was made but the queue was full: it is counted dropped.
    Dropped,
    /// The sample went into the running average.
    Averaging,
    /// The chip could not be read (counted as a lost step).
    ReadFailed(E),
}

/// One data-ready step. `edge` is the board's work at the line's edge once
/// the step is timestamped (nothing on hardware; the emulated board advances
/// its chip model there). `enqueue` offers a frame to the link's queue and
/// gives it back when the queue is full.
pub fn on_data_ready<L, C, I>(
    line: &mut L,
    clock: &C,
    imu: &mut I,
    sampler: &mut Sampler,
    edge: impl FnOnce(&mut I),
    enqueue: impl FnOnce(Outgoing) -> Result<(), Outgoing>,
) -> Stepped<I::Error>
where
    L: DataReadyLine,
    C: MicrosecondClock,
    I: Imu,
{
    line.acknowledge();
    let now_us = clock.now_us();
    edge(imu);
    let stepped = match sampler.step(imu, now_us) {
        StepOutcome::Frame(frame) => match enqueue(frame) {
            Ok(()) => Stepped::Queued,
            Err(frame) => {
                sampler.frame_dropped(&frame);
                Stepped::Dropped
            }
        },
        StepOutcome::Averaging => Stepped::Averaging,
        StepOutcome::ReadFailed(error) => Stepped::ReadFailed(error),
    };
    if line.next_step_pending() {
        sampler.overran();
    }
    stepped
}

/// One FIFO watermark step: acknowledge, timestamp, let the board do its
/// work at the edge (`edge`, as for [`on_data_ready`]), then drain the FIFO
/// into frames written into `sink`'s slots ([`Sampler::step_fifo_into`]). A late interrupt loses nothing
/// (the samples wait in the FIFO; an overflow is flagged and counted by the
/// sampler), so no overrun is counted here.
pub fn on_fifo_ready<L, C, I>(
    line: &mut L,
    clock: &C,
    imu: &mut I,
    sampler: &mut Sampler,
    edge: impl FnOnce(&mut I),
    sink: &mut impl FrameSink,
) -> FifoStepped<I::Error>
where
    L: DataReadyLine,
    C: MicrosecondClock,
    I: FifoImu,
{
    line.acknowledge();
    let now_us = clock.now_us();
    edge(imu);
    sampler.step_fifo_into(imu, now_us, sink)
}
