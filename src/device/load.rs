//! What the firmware's tasks cost: each task measures its own run in the
//! board's cycles, less the runs of the tasks that preempted it, and records
//! it ([`LoadCounters::record`]; the firmware's `run_time` does the
//! measuring), and once a second
//! the data-ready task turns the sums into the share of the core each task
//! took over that second ([`LoadWindow::tick`]); the rest is idle (the idle
//! task sleeps). `identify` reports the shares and each task's longest run.
//!
//! The cycle counter is the DWT's CYCCNT on hardware (the core clock) and,
//! on the emulated board, a timer counting QEMU's virtual nanoseconds, which
//! under `-icount shift=0` are instructions. Sums are wrapping `u32`s: a
//! one-second difference never wraps below 4.29 GHz.
//!
//! Each counter has one writer (its task), as in [`super::counters`].

use core::sync::atomic::{AtomicU32, Ordering};

pub use crate::protocol::Load;

/// The tasks measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Task {
    /// The data-ready step (the firmware's top task but the board's own).
    DataReady = 0,
    /// Commands and sending (the async tasks, priority 1).
    Link = 1,
    /// The receive interrupt (below data-ready).
    Receive = 2,
    /// The emulated board's chip model, which runs inside the data-ready
    /// task (its SPI or I²C transactions and its clock): apart, so that the
    /// data-ready share is the firmware's own. Never on hardware.
    ChipModel = 3,
}

/// Number of [`Task`]s.
pub const TASKS: usize = crate::protocol::device_info::TASKS;

/// The running sums every task writes and the window's result.
#[derive(Debug, Default)]
pub struct LoadCounters {
    busy: [AtomicU32; TASKS],
    max_run: [AtomicU32; TASKS],
    window_busy: [AtomicU32; TASKS],
    window_cycles: AtomicU32,
}

impl LoadCounters {
    /// All zero.
    pub const fn new() -> Self {
        Self {
            busy: [const { AtomicU32::new(0) }; TASKS],
            max_run: [const { AtomicU32::new(0) }; TASKS],
            window_busy: [const { AtomicU32::new(0) }; TASKS],
            window_cycles: AtomicU32::new(0),
        }
    }

    /// `task` ran for `run` cycles, preemptions excluded (its own writer only).
    #[inline]
    pub fn record(&self, task: Task, run: u32) {
        let i = task as usize;
        let busy = self.busy[i].load(Ordering::Relaxed);
        self.busy[i].store(busy.wrapping_add(run), Ordering::Relaxed);
        if run > self.max_run[i].load(Ordering::Relaxed) {
            self.max_run[i].store(run, Ordering::Relaxed);
        }
    }

    /// The last full window's cycles and the longest runs (in µs at `hz`).
    pub fn load(&self, hz: u32) -> Load {
        Load {
            busy_cycles: core::array::from_fn(|i| self.window_busy[i].load(Ordering::Relaxed)),
            window_cycles: self.window_cycles.load(Ordering::Relaxed),
            cycles_hz: hz,
            max_run_us: core::array::from_fn(|i| {
                cycles_to_us(self.max_run[i].load(Ordering::Relaxed), hz)
            }),
        }
    }
}

/// Cycles at `hz` → µs, rounded up (a run is never reported shorter).
pub fn cycles_to_us(cycles: u32, hz: u32) -> u32 {
    let hz = u64::from(hz.max(1));
    u32::try_from((u64::from(cycles) * 1_000_000).div_ceil(hz)).unwrap_or(u32::MAX)
}

/// The data-ready task's view: closes a window every second.
#[derive(Clone, Debug, Default)]
pub struct LoadWindow {
    started: Option<(u32, [u32; TASKS])>,
}

impl LoadWindow {
    /// A window not started yet.
    pub const fn new() -> Self {
        Self { started: None }
    }

    /// At cycle `now` (counter at `hz`): when a second has passed since the
    /// window began, publishes each task's cycles in it and starts the next.
    /// Returns each task's share published, in ‰, if any (for the log).
    pub fn tick(&mut self, now: u32, hz: u32, counters: &LoadCounters) -> Option<[u16; TASKS]> {
        let busy: [u32; TASKS] = core::array::from_fn(|i| counters.busy[i].load(Ordering::Relaxed));
        let Some((start, busy_then)) = self.started else {
            self.started = Some((now, busy));
            return None;
        };
        let elapsed = now.wrapping_sub(start);
        if elapsed < hz {
            return None;
        }
        let mut shares = [0u16; TASKS];
        for i in 0..TASKS {
            let spent = busy[i].wrapping_sub(busy_then[i]);
            counters.window_busy[i].store(spent, Ordering::Relaxed);
            shares[i] = (u64::from(spent) * 1000 / u64::from(elapsed)).min(1000) as u16;
        }
        counters.window_cycles.store(elapsed, Ordering::Relaxed);
        self.started = Some((now, busy));
        Some(shares)
    }
}
