//! Each task's own run time, for the load report (`triad::device::load`):
//! the cycles from its entry to its exit, less the cycles of the tasks that
//! preempted it (they add theirs to `NESTED` as they finish).

use crate::{B, COUNTERS};
use core::sync::atomic::{AtomicU32, Ordering};
use triad::device::board::Board as _;
use triad::device::Task;

/// The sum of every finished run's own cycles, wrapping.
static NESTED: AtomicU32 = AtomicU32::new(0);

/// The idle task's cycles asleep, wrapping (its one writer: the idle task).
static SLEPT: AtomicU32 = AtomicU32::new(0);

/// The idle task slept `cycles`.
#[inline(always)]
pub fn slept(cycles: u32) {
    SLEPT.store(
        SLEPT.load(Ordering::Relaxed).wrapping_add(cycles),
        Ordering::Relaxed,
    );
}

/// The cycles asleep since start, wrapping.
pub fn slept_total() -> u32 {
    SLEPT.load(Ordering::Relaxed)
}

/// A run in progress.
pub struct Run {
    start: u32,
    nested: u32,
}

impl Run {
    /// The cycle counter at the task's entry.
    pub fn start(&self) -> u32 {
        self.start
    }
}

/// At a task's entry.
#[inline(always)]
pub fn begin() -> Run {
    Run {
        start: B::cycles(),
        nested: NESTED.load(Ordering::Relaxed),
    }
}

/// At a task's exit: records its own cycles.
#[inline(always)]
pub fn end(run: Run, task: Task) {
    end_with_model(run, task, 0);
}

/// At a task's exit, `model` of its cycles having been the emulated chip
/// model's: records its own cycles and the model's apart. Interrupts are
/// masked for these few instructions, so that a task finishing in between
/// is counted either inside this run or not at all, never half.
#[inline(always)]
pub fn end_with_model(run: Run, task: Task, model: u32) {
    cortex_m::interrupt::free(|_| {
        let gross = B::cycles().wrapping_sub(run.start);
        let inner = NESTED.load(Ordering::Relaxed).wrapping_sub(run.nested);
        let own = gross.wrapping_sub(inner).wrapping_sub(model);
        let nested = NESTED
            .load(Ordering::Relaxed)
            .wrapping_add(own)
            .wrapping_add(model);
        NESTED.store(nested, Ordering::Relaxed);
        COUNTERS.load.record(task, own);
        if model != 0 {
            COUNTERS.load.record(Task::ChipModel, model);
        }
    });
}
