//! Whether the sensor is still there and sampling, and what to do when it is
//! not: a chip whose cable came loose, that browned out and came back at its
//! power-on registers, whose output stopped, or whose data-ready line went
//! quiet. Two plain parts a host test calls:
//!
//! - [`StallWatch`], ticked once per expected data-ready period by a time
//!   base that is not the data-ready line (the emulated board's sample
//!   timer; a hardware board's watchdog does the same by resetting): after
//!   [`STALL_US`] without a data-ready step it asks the data-ready task for
//!   a check, and again every [`STALL_US`] while the stall lasts.
//! - [`SensorHealth`], in the data-ready task: counts each stall once, asks
//!   for a restart on every check of a stall and after [`STALL_US`] worth
//!   of failed reads in a row, and counts the restarts that worked and those that did not. A
//!   restart finds the chip by its identity and configures it again (the
//!   driver's `start_with`): what a chip back from a brown-out needs.
//!
//! The steps lost meanwhile are counted by the sampler's step monitor when
//! data-ready comes back (the next frame's `overruns`, with OVERRUN set).

/// How long the sensor may be silent, µs, before the firmware checks it;
/// also the wait between two checks while it stays silent.
pub const STALL_US: u32 = 50_000;

/// Fewest data-ready periods taken for a stall, however slow the rate.
const STALL_MIN_PERIODS: u32 = 4;

/// Stalls and restarts since start (wrapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HealthTotals {
    /// Times the data-ready line went silent for [`STALL_US`] or more.
    pub stalls: u32,
    /// Times the chip was found again by its identity and configured (or
    /// found after start-up, when none answered at start).
    pub restarts: u32,
    /// Restarts tried that did not work: the chip did not answer with its
    /// identity or did not take its configuration (each stops at its first
    /// failed transaction).
    pub restart_failures: u32,
}

/// Periods of `period_us` in [`STALL_US`], rounded up, at least
/// [`STALL_MIN_PERIODS`].
fn stall_periods(period_us: u32) -> u32 {
    STALL_US.div_ceil(period_us.max(1)).max(STALL_MIN_PERIODS)
}

/// Notices a data-ready line that went quiet, from a time base of its own.
#[derive(Clone, Debug)]
pub struct StallWatch {
    limit: u32,
    quiet: u32,
}

impl StallWatch {
    /// A watch ticked every `period_us` (the data-ready period).
    pub fn new(period_us: u32) -> Self {
        Self {
            limit: stall_periods(period_us),
            quiet: 0,
        }
    }

    /// One period passed; `stepped`: a data-ready step ran during it. True
    /// when the data-ready task must check the sensor now (no step for
    /// [`STALL_US`], or for [`STALL_US`] more since the last check).
    pub fn tick(&mut self, stepped: bool) -> bool {
        if stepped {
            self.quiet = 0;
            return false;
        }
        self.quiet += 1;
        if self.quiet >= self.limit {
            self.quiet = 0;
            return true;
        }
        false
    }
}

/// The data-ready task's view of the sensor.
#[derive(Clone, Debug)]
pub struct SensorHealth {
    restart_after: u32,
    failures_in_row: u32,
    stalled: bool,
    totals: HealthTotals,
}

impl SensorHealth {
    /// For a chip read every `period_us`: a restart after [`STALL_US`] of
    /// failed reads in a row.
    pub fn new(period_us: u32) -> Self {
        Self {
            restart_after: stall_periods(period_us),
            failures_in_row: 0,
            stalled: false,
            totals: HealthTotals::default(),
        }
    }

    /// A data-ready step read the chip (`ok`) or failed to. True: restart
    /// the chip now (reads have failed for [`STALL_US`]).
    pub fn read(&mut self, ok: bool) -> bool {
        self.stalled = false;
        if ok {
            self.failures_in_row = 0;
            return false;
        }
        self.failures_in_row += 1;
        if self.failures_in_row >= self.restart_after {
            self.failures_in_row = 0;
            return true;
        }
        false
    }

    /// The [`StallWatch`] asked for a check: data-ready is silent. Counts
    /// the stall (once, until a step reads the chip again) and returns
    /// true: restart the chip now.
    pub fn stalled(&mut self) -> bool {
        if !self.stalled {
            self.stalled = true;
            self.totals.stalls = self.totals.stalls.wrapping_add(1);
        }
        true
    }

    /// A restart was tried; `ok`: the chip answered with its identity and
    /// took its configuration.
    pub fn restarted(&mut self, ok: bool) {
        if ok {
            self.totals.restarts = self.totals.restarts.wrapping_add(1);
        } else {
            self.totals.restart_failures = self.totals.restart_failures.wrapping_add(1);
        }
    }

    /// Stalls and restarts since start.
    pub fn totals(&self) -> &HealthTotals {
        &self.totals
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_watch_asks_after_50_ms_of_silence_and_every_50_ms_while_it_lasts() {
        let mut w = StallWatch::new(1000);
        assert!(!w.tick(true));
        let mut asked = [0; 3];
        let mut n = 0;
        for period in 1..=150 {
            if w.tick(false) {
                asked[n] = period;
                n += 1;
            }
        }
        assert_eq!(asked, [50, 100, 150]);
        // A step ends it: the count starts again.
        assert!(!w.tick(true));
        assert!((1..50).all(|_| !w.tick(false)));
        assert!(w.tick(false));
    }

    #[test]
    fn at_a_slow_rate_a_stall_is_still_a_few_periods() {
        let mut w = StallWatch::new(40_000); // 25 Hz
        assert_eq!((1..=4).filter(|_| w.tick(false)).count(), 1);
        assert_eq!(stall_periods(125), 400); // 8 kHz
    }

    #[test]
    fn a_stall_counts_once_however_many_checks_and_a_read_ends_it() {
        let mut h = SensorHealth::new(1000);
        assert!(h.stalled());
        h.restarted(false);
        assert!(h.stalled());
        h.restarted(true);
        assert_eq!(
            *h.totals(),
            HealthTotals {
                stalls: 1,
                restarts: 1,
                restart_failures: 1
            }
        );
        assert!(!h.read(true));
        assert!(h.stalled());
        assert_eq!(h.totals().stalls, 2);
    }

    #[test]
    fn fifty_ms_of_failed_reads_in_a_row_ask_for_a_restart() {
        let mut h = SensorHealth::new(1000);
        assert!((1..50).all(|_| !h.read(false)));
        assert!(!h.read(true), "a good read starts the count again");
        assert!((1..50).all(|_| !h.read(false)));
        assert!(h.read(false));
        assert_eq!(h.totals().stalls, 0, "failed reads are not a stall");
    }
}
