//! The most each queue between the tasks has held since start: the
//! frames waiting for the line (data-ready → transmit) and the received
//! bytes waiting for the command decoder (receive → commands). Logged with
//! the load; the soak (`cargo xtask bench --soak`) reports them. Each mark
//! has one writer, the task that fills its queue.

use core::sync::atomic::{AtomicU32, Ordering};

static FRAMES: AtomicU32 = AtomicU32::new(0);
static RECEIVED: AtomicU32 = AtomicU32::new(0);

fn raise(mark: &AtomicU32, len: usize) {
    let len = len as u32;
    if len > mark.load(Ordering::Relaxed) {
        mark.store(len, Ordering::Relaxed);
    }
}

/// The frame queue holds `len` (the data-ready task, after queueing).
#[inline(always)]
pub fn frames(len: usize) {
    raise(&FRAMES, len);
}

/// The received-byte queue holds `len` (the receive interrupt).
#[inline(always)]
pub fn received(len: usize) {
    raise(&RECEIVED, len);
}

/// The marks: frames, received bytes.
pub fn marks() -> (u32, u32) {
    (
        FRAMES.load(Ordering::Relaxed),
        RECEIVED.load(Ordering::Relaxed),
    )
}
