//! The sample clock of a chip with an accelerometer and a gyroscope at
//! independent output data rates, both counted from one chip oscillator:
//! each sensor samples on its own grid, and a sensor turned on while the
//! other runs joins the running grid. Shared by every chip model.

/// A sensor's rate as the clock counts it: a sample every
/// `counts_per_sample`, time adding `counts_per_ns` each ns (ns and 1 for a
/// period in whole ns; ns·mHz and the rate in mHz for rates like 833 Hz).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rate {
    /// Counts per sample.
    pub counts_per_sample: u128,
    /// Counts per ns.
    pub counts_per_ns: u128,
}

impl Rate {
    /// A period of `ns` whole nanoseconds.
    pub const fn period_ns(ns: u64) -> Self {
        Self {
            counts_per_sample: ns as u128,
            counts_per_ns: 1,
        }
    }

    /// A rate of `millihertz`, exact (counted in ns·mHz).
    pub const fn millihertz(millihertz: u32) -> Self {
        Self {
            counts_per_sample: 1_000_000_000_000,
            counts_per_ns: millihertz as u128,
        }
    }
}

/// The sensors' rates, accelerometer then gyroscope; `None` for a sensor off.
pub type Rates = [Option<Rate>; 2];

/// One step of the clock: the time it took and which sensors sampled at its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// ns elapsed.
    pub ns: u64,
    /// Whether the accelerometer and the gyroscope sampled.
    pub fired: [bool; 2],
}

/// Progress of each sensor through its period, and the time the clock has run.
#[derive(Clone, Copy, Debug, Default)]
pub struct SensorClock {
    phase: [u128; 2],
    running_ns: u64,
}

impl SensorClock {
    /// Stops both sensors' grids (reset).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Whole ns until the next sample of either sensor; `None` when both are off.
    pub fn ns_to_next(&self, rates: Rates) -> Option<u64> {
        let to_next = |phase: u128, rate: Option<Rate>| {
            rate.map(|r| {
                let counts = r.counts_per_sample.saturating_sub(phase);
                // A rate given by its period counts nanoseconds: no
                // division (a u128 one is a long software routine on the
                // emulated board's 32-bit core, and this runs per sample).
                let ns = match r.counts_per_ns {
                    1 => counts,
                    per_ns => counts.div_ceil(per_ns),
                };
                // At most one period: fits in u64.
                u64::try_from(ns).unwrap_or(u64::MAX)
            })
        };
        match (
            to_next(self.phase[0], rates[0]),
            to_next(self.phase[1], rates[1]),
        ) {
            (Some(a), Some(g)) => Some(a.min(g)),
            (a, g) => a.or(g),
        }
    }

    /// Runs to the next sample instant or until `remaining` is used up,
    /// whichever comes first; `None` (and the grid restarted) when both
    /// sensors are off.
    pub fn step(&mut self, remaining: &mut u64, rates: Rates) -> Option<Step> {
        let Some(to_next) = self.ns_to_next(rates) else {
            self.reset();
            return None;
        };
        let ns = to_next.min(*remaining);
        *remaining -= ns;
        self.running_ns += ns;
        let mut fired = [false; 2];
        for (sensor, rate) in rates.iter().enumerate() {
            let Some(rate) = rate else { continue };
            let phase = &mut self.phase[sensor];
            *phase += u128::from(ns) * rate.counts_per_ns;
            if *phase >= rate.counts_per_sample {
                *phase -= rate.counts_per_sample;
                fired[sensor] = true;
            }
        }
        Some(Step { ns, fired })
    }

    /// After a rate or power change from `before` to `after`: a sensor turned
    /// on joins the running sensor's grid (or starts the clock when none
    /// ran); a sensor turned off forgets its phase; a sensor whose rate
    /// changed keeps its phase.
    pub fn rates_changed(&mut self, before: Rates, after: Rates) {
        if before.iter().all(Option::is_none) {
            self.running_ns = 0;
        }
        for sensor in 0..2 {
            match (before[sensor], after[sensor]) {
                (None, Some(r)) => {
                    self.phase[sensor] =
                        u128::from(self.running_ns) * r.counts_per_ns % r.counts_per_sample;
                }
                (_, None) => self.phase[sensor] = 0,
                _ => {}
            }
        }
    }
}
