//! Where the sampler puts frames: the next free slot of the link's queue,
//! filled in place ([`FrameSink`]), so a frame is written once, where the
//! transmitter reads it. A queue with no room gives no slot: the frame is
//! then not built at all, only counted dropped.

use super::framer::Outgoing;
use super::slot_queue::SlotProducer;

/// Room for frames, one at a time: a slot to fill, then committed.
pub trait FrameSink {
    /// The next frame's slot, holding an earlier frame to overwrite;
    /// `None` when there is no room (the frame is counted dropped).
    fn slot(&mut self) -> Option<&mut Outgoing>;

    /// The frame written into the slot goes to the link; false when it
    /// could not (it is counted dropped, its events carried on).
    fn commit(&mut self) -> bool;
}

/// The link's queue: the firmware's sink.
impl<const N: usize> FrameSink for SlotProducer<'_, Outgoing, N> {
    #[inline]
    fn slot(&mut self) -> Option<&mut Outgoing> {
        SlotProducer::slot(self)
    }

    #[inline]
    fn commit(&mut self) -> bool {
        SlotProducer::commit(self);
        true
    }
}

/// A closure taking each frame by value (false: no room), through one
/// frame of its own: the host's tests and the end-to-end check, which
/// collect frames or refuse them.
pub struct ByValue<F> {
    frame: Outgoing,
    offer: F,
}

impl<F: FnMut(Outgoing) -> bool> ByValue<F> {
    /// Frames go to `offer`.
    pub fn new(offer: F) -> Self {
        Self {
            frame: Outgoing::EMPTY,
            offer,
        }
    }
}

impl<F: FnMut(Outgoing) -> bool> FrameSink for ByValue<F> {
    fn slot(&mut self) -> Option<&mut Outgoing> {
        Some(&mut self.frame)
    }

    fn commit(&mut self) -> bool {
        (self.offer)(self.frame)
    }
}
