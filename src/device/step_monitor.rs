//! Noticing sample steps that were late or never ran.
//!
//! A hardware interrupt that fires while its handler still runs is only
//! pended once: a step that overruns delays the next, and a step that overruns
//! by more than a period swallows interrupts entirely. The monitor compares
//! each step's start time with the previous one and counts the periods that
//! produced no sample, so nothing is silently lost.

/// Counts missed sample steps from step start times (µs, wrapping u32).
#[derive(Clone, Debug)]
pub struct StepMonitor {
    period_us: u32,
    last_start: Option<u32>,
}

impl StepMonitor {
    /// A monitor for steps every `period_us` microseconds (at least 1).
    pub const fn new(period_us: u32) -> Self {
        Self {
            period_us: if period_us == 0 { 1 } else { period_us },
            last_start: None,
        }
    }

    /// Records a step starting at `now_us`; returns how many whole periods
    /// passed since the previous step without a step of their own.
    ///
    /// A step is counted missed only when the gap exceeds 1.5 periods, so the
    /// jitter of interrupt entry never counts as a loss.
    pub fn step_started(&mut self, now_us: u32) -> u32 {
        let missed = match self.last_start {
            None => 0,
            Some(last) => {
                let elapsed = now_us.wrapping_sub(last);
                // Round elapsed/period to the nearest whole number of periods.
                let periods = (elapsed + self.period_us / 2) / self.period_us;
                periods.saturating_sub(1)
            }
        };
        self.last_start = Some(now_us);
        missed
    }
}
