//! Between the data-ready task and the time base that watches it (on the
//! emulated board, the sample timer's task; see
//! `triad::device::sensor_health`): whether a data-ready step ran or is
//! running, and whether the watch asked for a check of the sensor.
//!
//! Plain loads and stores: a step that begins between the watch's load and
//! its store goes unseen for one period, which is 1 of the 50 ms a stall takes.

use core::sync::atomic::{AtomicBool, Ordering};
use triad::device::StallWatch;

/// A data-ready step began since the watch's last tick.
static STEPPED: AtomicBool = AtomicBool::new(false);
/// A data-ready step is running (a self-test runs inside one for a second).
static IN_STEP: AtomicBool = AtomicBool::new(false);
/// The watch asked the data-ready task to check the sensor.
static CHECK: AtomicBool = AtomicBool::new(false);

/// A data-ready step, from its start to its end.
pub struct Step;

impl Step {
    /// The step begins.
    pub fn begin() -> Step {
        IN_STEP.store(true, Ordering::Relaxed);
        STEPPED.store(true, Ordering::Relaxed);
        Step
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        IN_STEP.store(false, Ordering::Relaxed);
    }
}

/// One tick of the watch (made at start-up with the data-ready period;
/// its task only); true when it asked for a check, which the caller then
/// pends the data-ready task for.
pub fn tick(watch: &mut StallWatch) -> bool {
    let stepped = STEPPED.load(Ordering::Relaxed) || IN_STEP.load(Ordering::Relaxed);
    STEPPED.store(false, Ordering::Relaxed);
    let check = watch.tick(stepped);
    if check {
        CHECK.store(true, Ordering::Relaxed);
    }
    check
}

/// Whether the watch asked for a check (the data-ready task; clears it).
pub fn take_check() -> bool {
    let asked = CHECK.load(Ordering::Relaxed);
    if asked {
        CHECK.store(false, Ordering::Relaxed);
    }
    asked
}
