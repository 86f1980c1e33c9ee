//! The truth a chip model quantises: true specific force, angular rate and
//! temperature, one sample per output-data-rate tick.

/// What the sensor would ideally measure at one instant, in SI units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrueSample {
    /// Specific force in m/s² (what an accelerometer measures: a − g).
    pub specific_force: [f64; 3],
    /// Angular rate in rad/s.
    pub angular_rate: [f64; 3],
    /// Temperature in °C.
    pub temperature: f64,
}

/// A stream of true samples at a fixed rate; a chip model pulls one per ODR tick.
pub trait SampleSource {
    /// The next sample.
    fn next_sample(&mut self) -> TrueSample;
}
