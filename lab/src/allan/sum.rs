//! Compensated (Kahan–Babuška–Neumaier) summation: the running error of a
//! long sum stays at one rounding of the result instead of growing with the
//! number of terms.

/// A sum with its running compensation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CompensatedSum {
    sum: f64,
    compensation: f64,
}

impl CompensatedSum {
    /// Zero.
    pub const ZERO: Self = Self {
        sum: 0.0,
        compensation: 0.0,
    };

    /// Adds `x` (Neumaier's variant: correct when |x| > |sum| as well).
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if libm::fabs(self.sum) >= libm::fabs(x) {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// The sum, with its compensation applied.
    #[inline]
    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}
