//! The temperature the sensor sits at during a scene.

/// Temperature over time.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub enum TemperatureProfile {
    /// Constant, °C.
    Constant(f64),
    /// `from` until `start`, then linear to `to` over `duration` seconds, then held.
    Ramp {
        /// Initial temperature, °C.
        from: f64,
        /// Final temperature, °C.
        to: f64,
        /// Start of the ramp, seconds.
        start: f64,
        /// Length of the ramp, seconds.
        duration: f64,
    },
    /// Soaks: the first `count` of `levels` in turn, each held for `hold`
    /// seconds (a chamber stepped between them; the settling between soaks
    /// is not part of the record), the last held after.
    Soak {
        /// The soak temperatures, °C (the first `count` are used).
        levels: [f64; MAX_SOAK_LEVELS],
        /// How many levels: 2 ..= [`MAX_SOAK_LEVELS`].
        count: u8,
        /// Each soak's length, seconds.
        hold: f64,
    },
}

/// The most soak levels of [`TemperatureProfile::Soak`].
pub const MAX_SOAK_LEVELS: usize = 4;

impl TemperatureProfile {
    /// The temperature at time `t`, °C.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            TemperatureProfile::Constant(c) => c,
            TemperatureProfile::Ramp {
                from,
                to,
                start,
                duration,
            } => {
                if t <= start {
                    from
                } else if duration <= 0.0 || t >= start + duration {
                    to
                } else {
                    from + (to - from) * ((t - start) / duration)
                }
            }
            TemperatureProfile::Soak {
                levels,
                count,
                hold,
            } => {
                let last = (count as usize).clamp(1, MAX_SOAK_LEVELS) - 1;
                let i = if hold > 0.0 && t > 0.0 {
                    ((t / hold) as usize).min(last)
                } else {
                    0
                };
                levels[i]
            }
        }
    }
}
