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
}

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
        }
    }
}
