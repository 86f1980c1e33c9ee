//! The transmitter's waits: for something to send (a frame queued by the
//! data-ready task, a reply written by the command task: each wakes
//! [`OUTGOING`] after), and for room in the board's transmit ring, which
//! takes a packet whole or not at all (its transmit interrupt wakes
//! [`TX_ROOM`] when it frees some). And the command task's wait for the
//! reply slot: a reply is encoded straight to wire bytes in that slot
//! (one, in a [`SlotQueue`]), where the transmitter reads it; no reply is
//! copied between the tasks.

use core::future::poll_fn;
use core::task::Poll;
use rtic_common::waker_registration::CriticalSectionWakerRegistration;
use triad::device::board::LinkTx;
use triad::device::{Outgoing, SlotConsumer, SlotProducer, Task};
use triad::protocol::{Flags, Frame, Reply, MAX_WIRE_LEN};

/// Woken when a frame or a reply is waiting.
pub static OUTGOING: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// Woken by the board's transmit interrupt when the ring frees room.
pub static TX_ROOM: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// Woken by the transmitter when the reply slot is free again.
pub static REPLY_ROOM: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// What the frame queue's slots hold before their first frame: all zero
/// bits, so that the queue (7.4 KiB) is zeroed at start-up (`.bss`), not
/// copied from an image in flash (`.data`). The first frame written into
/// each slot is a batch built apart and copied in; every later one is
/// written in place.
pub const NO_FRAME: Outgoing = Outgoing::Data(Frame {
    sequence: 0,
    timestamp_us: 0,
    flags: Flags::empty(),
    overruns: 0,
    dropped: 0,
    calibration_id: 0,
    accel: [0.0; 3],
    gyro: [0.0; 3],
    temperature: 0.0,
});

/// A reply on the wire: stuffed, delimited.
#[derive(Clone, Copy)]
pub struct ReplyWire {
    bytes: [u8; MAX_WIRE_LEN],
    len: usize,
}

impl ReplyWire {
    /// No bytes: what the slot holds before the first reply.
    pub const EMPTY: ReplyWire = ReplyWire {
        bytes: [0; MAX_WIRE_LEN],
        len: 0,
    };

    /// The bytes to send.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len.min(MAX_WIRE_LEN)]
    }
}

/// The slot's ends.
pub type ReplyOut = SlotProducer<'static, ReplyWire, 1>;
pub type ReplyIn = SlotConsumer<'static, ReplyWire, 1>;

/// Returns once a frame or a reply is waiting.
pub async fn something_to_send<const F: usize>(
    frames: &SlotConsumer<'static, Outgoing, F>,
    replies: &ReplyIn,
) {
    let waiting = || frames.ready() || replies.ready();
    poll_fn(|cx| {
        if waiting() {
            return Poll::Ready(());
        }
        OUTGOING.register(cx.waker());
        // One queued between the look and the registration woke no one:
        // look once more now that the waker is in place.
        match waiting() {
            true => Poll::Ready(()),
            false => Poll::Pending,
        }
    })
    .await
}

/// Encodes `reply` (CRC, COBS) into the reply slot, awaiting the slot
/// while the transmitter still sends the previous reply, then hands it to
/// the transmitter. A reply too long for a packet, which the handler never
/// makes, goes out as no bytes.
pub async fn send_reply(slot: &mut ReplyOut, reply: &Reply) {
    let room = poll_fn(|cx| {
        if slot.slot().is_some() {
            return Poll::Ready(());
        }
        REPLY_ROOM.register(cx.waker());
        // Freed between the look and the registration: look once more.
        match slot.slot().is_some() {
            true => Poll::Ready(()),
            false => Poll::Pending,
        }
    });
    room.await;
    let run = crate::run_time::begin();
    if let Some(wire) = slot.slot() {
        wire.len = reply.to_wire(&mut wire.bytes).unwrap_or(0);
        slot.commit();
        OUTGOING.wake();
    }
    crate::run_time::end(run, Task::Link);
}

/// Queues `bytes` whole into the board's transmit ring, awaiting room.
pub async fn queue<T: LinkTx>(serial: &mut T, bytes: &[u8]) {
    room(serial, bytes.len()).await;
    // The room awaited is still there: only this task queues.
    serial.queue(bytes);
}

/// Returns once the board's transmit ring has `bytes` free.
pub async fn room<T: LinkTx>(serial: &T, bytes: usize) {
    poll_fn(|cx| {
        if serial.room() >= bytes {
            return Poll::Ready(());
        }
        TX_ROOM.register(cx.waker());
        // Room freed between the look and the registration woke no one.
        match serial.room() >= bytes {
            true => Poll::Ready(()),
            false => Poll::Pending,
        }
    })
    .await
}
