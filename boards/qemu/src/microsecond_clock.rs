//! TIM5 (32 bit) free-running at 1 MHz: the stream's timestamps.

use super::pac;

/// Microseconds since start, from TIM5.
pub struct MicrosecondClock(pac::TIM5);

impl MicrosecondClock {
    /// Starts TIM5 counting microseconds from a `timer_clock_hz` input clock.
    pub fn new(tim: pac::TIM5, timer_clock_hz: u32) -> Self {
        tim.psc()
            .write(|w| w.psc().set((timer_clock_hz / 1_000_000 - 1) as u16));
        tim.arr().write(|w| w.arr().set(u32::MAX));
        tim.egr().write(|w| w.ug().set_bit());
        tim.cr1().modify(|_, w| w.cen().set_bit());
        Self(tim)
    }
}

impl triad::device::board::MicrosecondClock for MicrosecondClock {
    fn now_us(&self) -> u32 {
        self.0.cnt().read().bits()
    }
}
