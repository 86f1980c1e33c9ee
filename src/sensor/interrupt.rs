//! The electrical behaviour of a chip's interrupt (data-ready) pin.

/// How the interrupt pin signals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InterruptPin {
    /// Active high (true) or low.
    pub active_high: bool,
    /// Push-pull (true) or open drain.
    pub push_pull: bool,
    /// Latched until the status is read (true) or pulsed.
    pub latched: bool,
}

impl InterruptPin {
    /// Active-high push-pull pulses: what an MCU's rising-edge EXTI expects.
    pub const DEFAULT: InterruptPin = InterruptPin {
        active_high: true,
        push_pull: true,
        latched: false,
    };
}

impl Default for InterruptPin {
    /// [`InterruptPin::DEFAULT`].
    fn default() -> Self {
        Self::DEFAULT
    }
}
