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
        // Both corrections, then the one that applies: a select rather than
        // a branch (the larger operand changes unpredictably when a running
        // sum crosses zero), and columns' sums side by side vectorise.
        let sum_larger = (self.sum - t) + x;
        let x_larger = (x - t) + self.sum;
        self.compensation += if libm::fabs(self.sum) >= libm::fabs(x) {
            sum_larger
        } else {
            x_larger
        };
        self.sum = t;
    }

    /// The sum, with its compensation applied.
    #[inline]
    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

/// `L` compensated sums side by side, lane i a [`CompensatedSum`] of its
/// own: the same operations in the same order lane by lane (so the same
/// results, bit for bit), laid out as vectors so that the lanes' additions
/// are one vector instruction each where the target has them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensatedLanes<const L: usize> {
    sum: [f64; L],
    compensation: [f64; L],
}

impl<const L: usize> CompensatedLanes<L> {
    /// The lanes holding `sums`.
    pub fn new(sums: [CompensatedSum; L]) -> Self {
        Self {
            sum: sums.map(|s| s.sum),
            compensation: sums.map(|s| s.compensation),
        }
    }

    /// Each lane as a [`CompensatedSum`].
    pub fn sums(&self) -> [CompensatedSum; L] {
        core::array::from_fn(|i| CompensatedSum {
            sum: self.sum[i],
            compensation: self.compensation[i],
        })
    }

    /// Adds `x[i]` to lane i: [`CompensatedSum::add`] of each, written a
    /// whole vector at a time (each step over every lane before the next),
    /// the form the compiler makes vector instructions of.
    #[inline(always)]
    pub fn add(&mut self, x: [f64; L]) {
        let s = self.sum;
        let t: [f64; L] = core::array::from_fn(|i| s[i] + x[i]);
        let sum_larger: [f64; L] = core::array::from_fn(|i| (s[i] - t[i]) + x[i]);
        let x_larger: [f64; L] = core::array::from_fn(|i| (x[i] - t[i]) + s[i]);
        let pick: [bool; L] = core::array::from_fn(|i| libm::fabs(s[i]) >= libm::fabs(x[i]));
        for i in 0..L {
            self.compensation[i] += if pick[i] { sum_larger[i] } else { x_larger[i] };
        }
        self.sum = t;
    }

    /// Each lane's sum, with its compensation applied.
    #[inline(always)]
    pub fn value(&self) -> [f64; L] {
        core::array::from_fn(|i| self.sum[i] + self.compensation[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lanes side by side give each lane's own compensated sum, bit for
    /// bit, through sums that cross zero (where the larger operand changes).
    #[test]
    fn lanes_are_each_lane_summed_alone() {
        let x = |i: u32, lane: u32| {
            let r = (i.wrapping_mul(2_654_435_761) ^ lane.wrapping_mul(40_503)) % 2001;
            (f64::from(r) - 1000.0) * 1e-3 * f64::from(lane + 1) + 1e-17 * f64::from(i)
        };
        let mut alone = [CompensatedSum::ZERO; 4];
        let mut lanes = CompensatedLanes::new([CompensatedSum::ZERO; 4]);
        for i in 0..100_000 {
            let values: [f64; 4] = core::array::from_fn(|l| x(i, l as u32));
            for (a, v) in alone.iter_mut().zip(values) {
                a.add(v);
            }
            lanes.add(values);
            let each: [f64; 4] = core::array::from_fn(|l| alone[l].value());
            assert_eq!(
                lanes.value().map(f64::to_bits),
                each.map(f64::to_bits),
                "{i}"
            );
        }
        assert_eq!(lanes.sums(), alone);
        assert_eq!(CompensatedLanes::new(alone), lanes);
    }
}
