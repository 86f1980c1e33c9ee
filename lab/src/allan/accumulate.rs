//! Streaming overlapping (and non-overlapping) Allan variance at octave
//! averaging factors m = 1, 2, 4, …, in one pass over the record.
//!
//! The accumulator keeps the last L cumulative sums S_k in a caller-provided
//! ring of L = 2^p slots; octave m needs S_{k−m} and S_{k−2m} (read before
//! S_k overwrites the slot of S_{k−L}), so the ring serves every octave with
//! 2m ≤ L. Memory is 8·L bytes plus a few hundred bytes of sums: bounded by
//! the largest τ of the grid, not by the record. Time is O(octaves) per
//! sample. The storage is generic (a borrowed slice, an array or, on the
//! host, a `Vec`) so that a caller that does not know the record's length can
//! start small and [`OctaveAccumulator::grow`] the ring while it has not
//! wrapped yet.
//!
//! Numerical stability: a rate record whose mean is much larger than its
//! noise (an accelerometer's 1 g, a gyro's bias) makes S grow linearly, and
//! the second difference S_{k} − 2S_{k−m} + S_{k−2m} then cancels most of
//! its digits. The accumulator subtracts a reference `offset` from every
//! sample first (the second difference is unchanged by any offset, in exact
//! arithmetic: it annihilates linear functions of k); with the offset equal
//! to (an estimate of) the mean, S only grows as the noise integrates. S is
//! summed with compensation, so a stored S_k is within one rounding of the
//! exact sum; the squared differences are summed in blocks of
//! [`BLOCK`] plain f64 additions (relative error ≤ BLOCK·ε ≈ 2·10⁻¹³) whose
//! totals are added with compensation.

use super::sum::CompensatedSum;

/// Most octaves the accumulator tracks (m up to 2^47: far beyond any record).
pub const MAX_OCTAVES: usize = 48;

/// Squared differences summed plainly before a compensated flush.
pub const BLOCK: u64 = 1024;

/// Why an accumulator cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AccumulatorError {
    /// The ring's length is not a power of two of at least 2 slots.
    RingLength(usize),
    /// A new ring no longer than the current one, or not a power of two.
    GrowLength {
        /// The current length.
        current: usize,
        /// The proposed length.
        proposed: usize,
    },
    /// The ring has wrapped: octaves a larger ring would add have missed terms.
    GrowAfterWrap {
        /// Samples pushed.
        samples: u64,
        /// The current length.
        current: usize,
    },
    /// The offset is not a finite number.
    Offset(f64),
}

impl core::fmt::Display for AccumulatorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            AccumulatorError::RingLength(n) => {
                write!(f, "ring of {n} slots: must be a power of two, at least 2")
            }
            AccumulatorError::GrowLength { current, proposed } => write!(
                f,
                "ring of {proposed} slots cannot replace one of {current}: must be a longer power of two"
            ),
            AccumulatorError::GrowAfterWrap { samples, current } => write!(
                f,
                "ring of {current} slots has wrapped after {samples} samples: too late to grow it"
            ),
            AccumulatorError::Offset(x) => write!(f, "offset {x} is not a finite number"),
        }
    }
}

/// The running sums of one octave.
#[derive(Clone, Copy, Debug, Default)]
struct OctaveSums {
    overlapping: CompensatedSum,
    overlapping_block: f64,
    non_overlapping: CompensatedSum,
    non_overlapping_block: f64,
}

/// The Allan variances at one averaging factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctaveResult {
    /// Averaging factor m (τ = m·τ₀).
    pub m: u64,
    /// Overlapping Allan variance, in the squared units of the samples.
    pub overlapping: f64,
    /// Number of second differences in the overlapping estimate (N − 2m + 1).
    pub overlapping_terms: u64,
    /// Non-overlapping Allan variance.
    pub non_overlapping: f64,
    /// Number of second differences in the non-overlapping estimate (⌊N/m⌋ − 1).
    pub non_overlapping_terms: u64,
}

impl OctaveResult {
    /// The estimates at m after `samples` samples from the sums of the
    /// squared second differences: `overlapping` over every k = 2m … N,
    /// `non_overlapping` over those at multiples of m (None before k = 2m).
    pub fn fully_overlapping(
        m: u64,
        samples: u64,
        overlapping: f64,
        non_overlapping: f64,
    ) -> Option<Self> {
        if samples < 2 * m {
            return None;
        }
        // Terms at k = 2m … N: N − 2m + 1 overlapping, ⌊N/m⌋ − 1 at multiples of m.
        let overlapping_terms = samples - 2 * m + 1;
        let non_overlapping_terms = samples / m - 1;
        let scale = |terms: u64| 2.0 * (m as f64) * (m as f64) * terms as f64;
        Some(OctaveResult {
            m,
            overlapping: overlapping / scale(overlapping_terms),
            overlapping_terms,
            non_overlapping: non_overlapping / scale(non_overlapping_terms),
            non_overlapping_terms,
        })
    }
}

/// Streaming Allan variance at octave m over a ring `R` of cumulative sums.
#[derive(Debug)]
pub struct OctaveAccumulator<R> {
    ring: R,
    mask: usize,
    octaves: usize,
    offset: f64,
    running: CompensatedSum,
    count: u64,
    octave: [OctaveSums; MAX_OCTAVES],
}

/// Octaves a ring of `len` slots serves: 2m ≤ len with m = 2^o ⇔ o ≤ log2(len) − 1.
fn octaves_for(len: usize) -> usize {
    (len.trailing_zeros() as usize).min(MAX_OCTAVES)
}

impl<R: AsMut<[f64]> + AsRef<[f64]>> OctaveAccumulator<R> {
    /// An accumulator over `ring` (length a power of two ≥ 2: octaves up to
    /// m = len/2) that subtracts `offset` from every sample (use the mean of
    /// the first samples; 0 is correct but loses digits when the mean is
    /// large compared with the noise).
    pub fn new(mut ring: R, offset: f64) -> Result<Self, AccumulatorError> {
        let len = ring.as_ref().len();
        if len < 2 || !len.is_power_of_two() {
            return Err(AccumulatorError::RingLength(len));
        }
        if !offset.is_finite() {
            return Err(AccumulatorError::Offset(offset));
        }
        let octaves = octaves_for(len);
        ring.as_mut()[0] = 0.0;
        Ok(Self {
            ring,
            mask: len - 1,
            octaves,
            offset,
            running: CompensatedSum::ZERO,
            count: 0,
            octave: [OctaveSums::default(); MAX_OCTAVES],
        })
    }

    /// The largest averaging factor the ring can serve.
    pub fn max_m(&self) -> u64 {
        1u64 << (self.octaves - 1)
    }

    /// The ring's length.
    pub fn ring_len(&self) -> usize {
        self.mask + 1
    }

    /// Moves the sums into a longer ring (a power of two) and returns the old
    /// one. Only before the ring wraps (fewer than `ring_len()` samples
    /// pushed): the new octaves have then had no term yet.
    pub fn grow(&mut self, mut bigger: R) -> Result<R, AccumulatorError> {
        let (current, proposed) = (self.ring_len(), bigger.as_ref().len());
        if proposed <= current || !proposed.is_power_of_two() {
            return Err(AccumulatorError::GrowLength { current, proposed });
        }
        if self.count >= current as u64 {
            return Err(AccumulatorError::GrowAfterWrap {
                samples: self.count,
                current,
            });
        }
        let n = self.count as usize + 1;
        bigger.as_mut()[..n].copy_from_slice(&self.ring.as_ref()[..n]);
        self.mask = proposed - 1;
        self.octaves = octaves_for(proposed);
        Ok(core::mem::replace(&mut self.ring, bigger))
    }

    /// The growth rule of a caller that does not know the record's length,
    /// to call before every push: when the next sample would wrap the ring
    /// and it is shorter than `cap` slots, moves the sums into
    /// `ring_of(2 · ring_len())` and returns the old ring. The ring so
    /// doubles up to the first power of two ≥ `cap`, and never too late.
    /// An error only when `ring_of` gives a ring of another length.
    pub fn grow_before_wrap(
        &mut self,
        cap: usize,
        ring_of: impl FnOnce(usize) -> R,
    ) -> Result<Option<R>, AccumulatorError> {
        let len = self.ring_len();
        if self.count + 1 != len as u64 || len >= cap {
            return Ok(None);
        }
        self.grow(ring_of(2 * len)).map(Some)
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> u64 {
        self.count
    }

    /// The offset subtracted from every sample.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// The cumulative sum S_k after the last push (k = [`Self::samples`]),
    /// the value the ring holds: what [`super::strided`] octaves take.
    pub fn cumulative(&self) -> f64 {
        self.running.value()
    }

    /// Adds one rate sample.
    #[inline]
    pub fn push(&mut self, y: f64) {
        self.running.add(y - self.offset);
        self.count += 1;
        let k = self.count;
        let s_k = self.running.value();
        let mask = self.mask;
        let ring = self.ring.as_mut();
        // Octaves with a term at k: 2·2^o ≤ k ⇔ o < ⌊log2 k⌋.
        let active = (k.ilog2() as usize).min(self.octaves);
        for (o, sums) in self.octave[..active].iter_mut().enumerate() {
            let m = 1u64 << o;
            // Read before S_k is stored: at 2m = L, S_{k−2m} shares its slot.
            let s_m = ring[((k - m) as usize) & mask];
            let s_2m = ring[((k - 2 * m) as usize) & mask];
            let d = (s_k - s_m) - (s_m - s_2m);
            let d2 = d * d;
            sums.overlapping_block += d2;
            // Branch-free: the non-overlapping terms are those with m | k.
            sums.non_overlapping_block += if k & (m - 1) == 0 { d2 } else { 0.0 };
        }
        ring[(k as usize) & mask] = s_k;
        if k.is_multiple_of(BLOCK) {
            self.flush();
        }
    }

    fn flush(&mut self) {
        for sums in self.octave[..self.octaves].iter_mut() {
            sums.overlapping.add(sums.overlapping_block);
            sums.overlapping_block = 0.0;
            sums.non_overlapping.add(sums.non_overlapping_block);
            sums.non_overlapping_block = 0.0;
        }
    }

    /// The result at octave `o` (m = 2^o), or None when it has no term yet.
    pub fn result(&self, o: usize) -> Option<OctaveResult> {
        if o >= self.octaves {
            return None;
        }
        let sums = &self.octave[o];
        let mut over = sums.overlapping;
        over.add(sums.overlapping_block);
        let mut non = sums.non_overlapping;
        non.add(sums.non_overlapping_block);
        OctaveResult::fully_overlapping(1 << o, self.count, over.value(), non.value())
    }

    /// Every octave that has at least one term, shortest τ first.
    pub fn results(&self) -> impl Iterator<Item = OctaveResult> + '_ {
        (0..self.octaves).map_while(move |o| self.result(o))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;
    use std::vec::Vec;

    #[test]
    fn a_ring_grown_before_it_wraps_gives_what_a_full_ring_gives() {
        let y: Vec<f64> = (0..1000u32)
            .map(|i| f64::from(i.wrapping_mul(2_654_435_761) % 1000) * 1e-3)
            .collect();
        let mut grown = OctaveAccumulator::new(vec![0.0; 4], 0.5).unwrap();
        let mut full = OctaveAccumulator::new(vec![0.0; 64], 0.5).unwrap();
        let mut lengths = Vec::new();
        for &v in &y {
            grown.grow_before_wrap(64, |n| vec![0.0; n]).unwrap();
            if lengths.last() != Some(&grown.ring_len()) {
                lengths.push(grown.ring_len());
            }
            grown.push(v);
            full.push(v);
        }
        assert_eq!(
            lengths,
            [4, 8, 16, 32, 64],
            "doubled up to the cap, no further"
        );
        assert!(
            grown.results().eq(full.results()),
            "the same sums, bit for bit"
        );
        // A ring of another length than asked is the caller's error, not a panic.
        let mut acc = OctaveAccumulator::new(vec![0.0; 2], 0.0).unwrap();
        acc.push(1.0);
        assert!(acc.grow_before_wrap(8, |_| vec![0.0; 3]).is_err());
    }
}
