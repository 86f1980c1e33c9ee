//! The device's counters, shared between the tasks that count and the
//! command handler that reports them.
//!
//! Each counter has one writer (the data-ready task, or the receive
//! interrupt for `rx_overflows`), which stores plain loads-plus-one: no
//! read-modify-write atomics, so the same code runs on a Cortex-M0. The
//! reader takes a snapshot; "reset counters" keeps a baseline in the
//! reader rather than writing another task's counter.

use core::sync::atomic::{AtomicU32, Ordering};

use super::load::LoadCounters;
use super::sensor_health::HealthTotals;
use crate::protocol::Counters;

/// Totals the sampling pipeline keeps (see [`super::Sampler::totals`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SamplerTotals {
    /// Frames handed to the link's queue.
    pub frames_sent: u32,
    /// Frames dropped because the queue was full.
    pub frames_dropped: u32,
    /// Sample steps lost (late, overrun or unread).
    pub overruns: u32,
    /// Sensor reads that failed.
    pub read_failures: u32,
}

/// Counters in memory every task can read.
#[derive(Debug, Default)]
pub struct SharedCounters {
    frames_sent: AtomicU32,
    frames_dropped: AtomicU32,
    overruns: AtomicU32,
    read_failures: AtomicU32,
    rx_overflows: AtomicU32,
    sensor_stalls: AtomicU32,
    sensor_restarts: AtomicU32,
    sensor_restart_failures: AtomicU32,
    flash_stalls: AtomicU32,
    uptime_ms: AtomicU32,
    /// What each task costs.
    pub load: LoadCounters,
}

impl SharedCounters {
    /// All zero.
    pub const fn new() -> Self {
        Self {
            frames_sent: AtomicU32::new(0),
            frames_dropped: AtomicU32::new(0),
            overruns: AtomicU32::new(0),
            read_failures: AtomicU32::new(0),
            rx_overflows: AtomicU32::new(0),
            sensor_stalls: AtomicU32::new(0),
            sensor_restarts: AtomicU32::new(0),
            sensor_restart_failures: AtomicU32::new(0),
            flash_stalls: AtomicU32::new(0),
            uptime_ms: AtomicU32::new(0),
            load: LoadCounters::new(),
        }
    }

    /// Publishes the sampling task's totals and the time of its latest
    /// step (its writer only).
    pub fn publish(&self, totals: &SamplerTotals, uptime_ms: u32) {
        self.uptime_ms.store(uptime_ms, Ordering::Relaxed);
        self.frames_sent
            .store(totals.frames_sent, Ordering::Relaxed);
        self.frames_dropped
            .store(totals.frames_dropped, Ordering::Relaxed);
        self.overruns.store(totals.overruns, Ordering::Relaxed);
        self.read_failures
            .store(totals.read_failures, Ordering::Relaxed);
    }

    /// Publishes the data-ready task's sensor stalls, restarts and failed
    /// restarts (its writer only).
    pub fn publish_health(&self, health: &HealthTotals) {
        self.sensor_stalls.store(health.stalls, Ordering::Relaxed);
        self.sensor_restarts
            .store(health.restarts, Ordering::Relaxed);
        self.sensor_restart_failures
            .store(health.restart_failures, Ordering::Relaxed);
    }

    /// Publishes the board's count of flash operations that stalled the
    /// CPU, as the data-ready task saw it (its writer only).
    pub fn publish_flash_stalls(&self, stalls: u32) {
        self.flash_stalls.store(stalls, Ordering::Relaxed);
    }

    /// A received byte was lost (the receive interrupt only).
    pub fn rx_overflowed(&self) {
        let n = self.rx_overflows.load(Ordering::Relaxed);
        self.rx_overflows
            .store(n.wrapping_add(1), Ordering::Relaxed);
    }

    /// Milliseconds since start at the latest sample step (wrapping every
    /// 2³² ms, 49.7 days): the stream's clock.
    pub fn uptime_ms(&self) -> u32 {
        self.uptime_ms.load(Ordering::Relaxed)
    }

    /// The counters now (the command counters are the handler's own, 0 here).
    pub fn snapshot(&self) -> Counters {
        Counters {
            frames_sent: self.frames_sent.load(Ordering::Relaxed),
            frames_dropped: self.frames_dropped.load(Ordering::Relaxed),
            overruns: self.overruns.load(Ordering::Relaxed),
            read_failures: self.read_failures.load(Ordering::Relaxed),
            commands: 0,
            command_errors: 0,
            rx_overflows: self.rx_overflows.load(Ordering::Relaxed),
            sensor_stalls: self.sensor_stalls.load(Ordering::Relaxed),
            sensor_restarts: self.sensor_restarts.load(Ordering::Relaxed),
            sensor_restart_failures: self.sensor_restart_failures.load(Ordering::Relaxed),
            flash_stalls: self.flash_stalls.load(Ordering::Relaxed),
        }
    }
}
