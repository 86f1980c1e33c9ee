//! The transmitter's waits: for something to send (a frame queued by the
//! data-ready task, a reply sent by the command task: each wakes
//! [`OUTGOING`] after), and for room in the board's transmit ring, which
//! takes a packet whole or not at all (its transmit interrupt wakes
//! [`TX_ROOM`] when it frees some).

use core::future::poll_fn;
use core::task::Poll;
use rtic_common::waker_registration::CriticalSectionWakerRegistration;
use rtic_sync::channel::Receiver;
use triad::device::board::LinkTx;
use triad::device::{Outgoing, SlotConsumer};
use triad::protocol::{Reply, MAX_WIRE_LEN};

/// Woken when a frame or a reply is waiting.
pub static OUTGOING: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// Woken by the board's transmit interrupt when the ring frees room.
pub static TX_ROOM: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// Returns once a frame or a reply is waiting.
pub async fn something_to_send<const F: usize, const N: usize>(
    frames: &SlotConsumer<'static, Outgoing, F>,
    replies: &Receiver<'static, Reply, N>,
) {
    let waiting = || frames.ready() || !replies.is_empty();
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

/// Encodes `reply` (CRC, COBS) into `out`, where its bytes go; the bytes
/// used (0 for a reply too long for a packet, which the handler never makes).
pub fn reply_to_wire(reply: &Reply, out: &mut [u8; MAX_WIRE_LEN]) -> usize {
    reply.to_wire(out).unwrap_or(0)
}

/// Queues `bytes` whole into the board's transmit ring, awaiting room.
pub async fn queue<T: LinkTx>(serial: &mut T, bytes: &[u8]) {
    poll_fn(|cx| {
        if serial.queue(bytes) {
            return Poll::Ready(());
        }
        TX_ROOM.register(cx.waker());
        // Room freed between the try and the registration woke no one.
        match serial.queue(bytes) {
            true => Poll::Ready(()),
            false => Poll::Pending,
        }
    })
    .await
}
