//! The received byte stream, from the link's receive interrupt to the
//! command task: a lock-free single-producer queue (no critical section per
//! byte, where rtic-sync's channel would take one, and would hold at most
//! 255 entries), and a waker the interrupt wakes after a burst.

use core::future::poll_fn;
use core::task::Poll;
use heapless::spsc::Consumer;
use rtic_common::waker_registration::CriticalSectionWakerRegistration;

/// Woken by the receive interrupt when bytes arrived.
pub static RX_WAKER: CriticalSectionWakerRegistration = CriticalSectionWakerRegistration::new();

/// The next received byte, awaiting one when none is waiting.
pub async fn next_byte(rx: &mut Consumer<'static, u8>) -> u8 {
    poll_fn(|cx| {
        if let Some(byte) = rx.dequeue() {
            return Poll::Ready(byte);
        }
        RX_WAKER.register(cx.waker());
        // A byte that came between the look and the registration woke no
        // one: look once more now that the waker is in place.
        match rx.dequeue() {
            Some(byte) => Poll::Ready(byte),
            None => Poll::Pending,
        }
    })
    .await
}
