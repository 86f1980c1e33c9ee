//! Angle (gyro) or velocity (accelerometer) quantisation: the sensor counts
//! whole increments of its integrated output — the fringes of a ring laser
//! gyro, the pulses of a pulse-rebalanced or V/F-converted accelerometer —
//! and the rate a sample reports is the count over the period times the
//! step: θ_k = ∫y dt is quantised to floor(θ_k/S)·S and differenced.
//!
//! The error is in the angle, not the rate: e_k = θ_k − S·floor(θ_k/S) is
//! bounded, so the sample's error (e_{k−1} − e_k)/Ts telescopes and no
//! angle is lost however long the record. When the angle moves irregularly
//! by a step or more per sample, e_k is uniform and white and the Allan
//! variance gains IEEE Std 952's quantisation term 3Q²/τ² with
//! Q = S/√12 (Annex C.1; white angle noise of variance S²/12). On a steady
//! input that moves less than a step per sample the error is a sawtooth,
//! not white. This is distinct from the output register's rounding of each
//! rate sample ([`super::output_lsb`]), which is white *rate* noise.
//!
//! The angle is kept as its fraction of a step (the whole steps go out as
//! counts), so its precision does not decay as the angle grows.

/// The quantiser of one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IncrementQuantiser {
    /// The step S (rad or m/s); 0: no quantisation.
    step: f64,
    /// The angle's part of a step not yet counted, in steps: [0, 1).
    fraction: f64,
}

impl IncrementQuantiser {
    /// A quantiser of step `step`, its angle starting half a step in (so
    /// that an input of either sign crosses a step only after half a step).
    pub fn new(step: f64) -> Self {
        Self {
            step,
            fraction: 0.5,
        }
    }

    /// The whole steps counted over one period of `ts` seconds in which the
    /// input's mean is `rate`, and the reported rate: counts·S/Ts.
    pub fn step(&mut self, rate: f64, ts: f64) -> (f64, f64) {
        if !self.step.is_finite() || self.step <= 0.0 {
            return (0.0, rate);
        }
        let moved = self.fraction + rate * ts / self.step;
        let counts = libm::floor(moved);
        self.fraction = moved - counts;
        (counts, counts * self.step / ts)
    }
}
