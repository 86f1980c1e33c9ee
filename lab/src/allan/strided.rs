//! Octaves beyond the ring: the overlapping Allan variance with its second
//! differences taken every d = m/M samples instead of every sample.
//!
//! Why: the fully overlapping estimator at τ = m·τ₀ needs the last 2m
//! cumulative sums, 16·m bytes per column (256 MiB at m = 2^24). Above a
//! base factor M the estimate here keeps only the terms at k ≡ 0 (mod d),
//! d = m/M, so it needs the cumulative sums at multiples of d only: a ring
//! of 2M slots whatever m is. The overlap ratio m/d stays M (2^17 in
//! `triad allan`): each second difference still overlaps M − 1 of its
//! neighbours on either side.
//!
//! The estimate, for N samples and S_k the cumulative sums of
//! [`super::accumulate`], is
//!
//!   σ̂²(m) = Σ_{k ∈ {2m, 2m+d, …} ≤ N} (S_k − 2S_{k−m} + S_{k−2m})² / (2m²n),
//!   n = ⌊(N − 2m)/d⌋ + 1,
//!
//! unbiased like the fully overlapping one (each term has the same
//! expectation). Its variance: for the noises whose second differences are
//! correlated over lags of order m (white rate N, flicker B, random walk K)
//! the sum over every d-th lag is a Riemann sum of the same integral, and the
//! variance is that of the fully overlapping estimator to O(d/m) = O(1/M);
//! its EDF is therefore the fully overlapping one's (SP 1065 Table 5). White
//! phase noise (quantisation Q) is correlated only at lags 0, ±m, ±2m: a
//! d-th of the terms carry d times its variance
//! ([`super::covariance::OctaveCovariance::with_strides`] counts it), and
//! its EDF is ≈ (N/2)/d, still far above white FM's 3N/(2m) (M ≫ 3) so the
//! capped EDF of [`super::edf::edf_conservative`] is unchanged.
//! The non-overlapping estimate (terms at multiples of m, a multiple of d)
//! is exactly the usual one.

use super::accumulate::{OctaveResult, BLOCK};
use super::sum::CompensatedSum;

/// The base M of `triad allan`: fully overlapping octaves up to m = 2^17
/// (a ring of 2^18 sums, 2 MiB per column), strided ones above, each with
/// its own ring of 2^18 sums.
pub const BASE: u64 = 1 << 17;

/// The stride of octave `m` over a base factor `base` (both powers of two):
/// 1 up to the base, m/base above it.
pub fn stride(m: u64, base: u64) -> u64 {
    (m / base.max(1)).max(1)
}

/// Why a strided octave cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StridedError {
    /// The factor is not a power of two above the base.
    Factor {
        /// The averaging factor.
        m: u64,
        /// The base factor M.
        base: u64,
    },
    /// The ring does not hold 2M slots.
    RingLength {
        /// Its length.
        len: usize,
        /// The length needed.
        needed: u64,
    },
}

impl core::fmt::Display for StridedError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StridedError::Factor { m, base } => write!(
                f,
                "averaging factor {m}: a strided octave needs a power of two above the base {base} (itself a power of two)"
            ),
            StridedError::RingLength { len, needed } => {
                write!(f, "ring of {len} slots: a strided octave needs {needed}")
            }
        }
    }
}

/// One octave m > M, fed the cumulative sums at multiples of its stride.
#[derive(Debug)]
pub struct StridedOctave<R> {
    ring: R,
    /// 2M − 1.
    mask: u64,
    base: u64,
    m: u64,
    stride: u64,
    /// Samples seen (the k of the last sum pushed).
    samples: u64,
    terms: u64,
    overlapping: CompensatedSum,
    overlapping_block: f64,
    non_overlapping: CompensatedSum,
}

impl<R: AsMut<[f64]> + AsRef<[f64]>> StridedOctave<R> {
    /// Octave `m` (a power of two above `base`, itself a power of two) over
    /// `ring` of 2·base slots.
    pub fn new(m: u64, base: u64, mut ring: R) -> Result<Self, StridedError> {
        if !(base.is_power_of_two() && m.is_power_of_two() && m > base) {
            return Err(StridedError::Factor { m, base });
        }
        let len = ring.as_ref().len();
        if len as u64 != 2 * base {
            return Err(StridedError::RingLength {
                len,
                needed: 2 * base,
            });
        }
        ring.as_mut()[0] = 0.0;
        Ok(Self {
            ring,
            mask: 2 * base - 1,
            base,
            m,
            stride: m / base,
            samples: 0,
            terms: 0,
            overlapping: CompensatedSum::ZERO,
            overlapping_block: 0.0,
            non_overlapping: CompensatedSum::ZERO,
        })
    }

    /// The averaging factor.
    pub fn m(&self) -> u64 {
        self.m
    }

    /// The stride d = m/M.
    pub fn stride(&self) -> u64 {
        self.stride
    }

    /// Tells the octave that `k` samples have been pushed, the cumulative
    /// sum being then `s_k` (as [`super::accumulate::OctaveAccumulator::cumulative`]
    /// gives it); only sums at multiples of the stride are used, so a caller
    /// may call it for those k alone. Calls must come in increasing k.
    #[inline]
    pub fn push(&mut self, k: u64, s_k: f64) {
        self.samples = k;
        if k & (self.stride - 1) != 0 {
            return;
        }
        let p = k / self.stride;
        let ring = self.ring.as_mut();
        if p >= 2 * self.base {
            // Read before S_k is stored: S_{k−2m} shares its slot.
            let s_m = ring[((p - self.base) & self.mask) as usize];
            let s_2m = ring[((p - 2 * self.base) & self.mask) as usize];
            let d = (s_k - s_m) - (s_m - s_2m);
            self.overlapping_block += d * d;
            self.terms += 1;
            if k & (self.m - 1) == 0 {
                self.non_overlapping.add(d * d);
            }
            if self.terms.is_multiple_of(BLOCK) {
                self.overlapping.add(self.overlapping_block);
                self.overlapping_block = 0.0;
            }
        }
        ring[(p & self.mask) as usize] = s_k;
    }

    /// The estimates after `samples` pushed, or None without a term.
    pub fn result(&self) -> Option<OctaveResult> {
        if self.terms == 0 {
            return None;
        }
        let m = self.m;
        let non_overlapping_terms = self.samples / m - 1;
        let mut over = self.overlapping;
        over.add(self.overlapping_block);
        let scale = |terms: u64| 2.0 * (m as f64) * (m as f64) * terms as f64;
        Some(OctaveResult {
            m,
            overlapping: over.value() / scale(self.terms),
            overlapping_terms: self.terms,
            non_overlapping: self.non_overlapping.value() / scale(non_overlapping_terms),
            non_overlapping_terms,
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::allan::accumulate::OctaveAccumulator;
    use crate::allan::direct;
    use std::string::ToString;
    use std::vec;
    use std::vec::Vec;

    fn record(n: u32) -> Vec<f64> {
        (0..n)
            .map(|i| f64::from(i.wrapping_mul(2_654_435_761) % 1000) * 1e-3 + 1e-6 * f64::from(i))
            .collect()
    }

    #[test]
    fn the_terms_are_the_full_ones_at_multiples_of_the_stride() {
        let y = record(3000);
        let offset = 0.5;
        let base = 8;
        let mut acc = OctaveAccumulator::new(vec![0.0; 16], offset).unwrap();
        let mut octaves: Vec<StridedOctave<Vec<f64>>> = [16u64, 32, 64, 1024]
            .iter()
            .map(|&m| StridedOctave::new(m, base, vec![0.0; 16]).unwrap())
            .collect();
        for &v in &y {
            acc.push(v);
            for o in octaves.iter_mut() {
                o.push(acc.samples(), acc.cumulative());
            }
        }
        let mut s = vec![0.0; y.len() + 1];
        direct::cumulative_sums(&y, offset, &mut s);
        for o in &octaves {
            let (m, d) = (o.m() as usize, o.stride() as usize);
            let r = o.result().unwrap();
            // Every d-th second difference from k = 2m: the in-memory stride d.
            let (want, terms) = direct::allan_variance(&s, m, d).unwrap();
            assert_eq!(r.overlapping_terms, terms, "m = {m}");
            assert!(
                (r.overlapping - want).abs() <= 1e-12 * want,
                "m = {m}: {} against {want}",
                r.overlapping
            );
            let (non, non_terms) = direct::non_overlapping(&s, m).unwrap();
            assert_eq!(r.non_overlapping_terms, non_terms);
            assert!((r.non_overlapping - non).abs() <= 1e-12 * non);
        }
        // 1024: 2m = 2048 ≤ 3000, terms at 2048, 2048 + 128, … ≤ 3000.
        assert_eq!(octaves[3].result().unwrap().overlapping_terms, 8);
    }

    #[test]
    fn bad_factors_and_rings_are_refused() {
        assert!(StridedOctave::new(8, 8, vec![0.0; 16]).is_err());
        assert!(StridedOctave::new(24, 8, vec![0.0; 16]).is_err());
        let e = StridedOctave::new(32, 8, vec![0.0; 8]).unwrap_err();
        assert_eq!(e.to_string(), "ring of 8 slots: a strided octave needs 16");
        assert_eq!((stride(4, 8), stride(64, 8)), (1, 8));
        let o = StridedOctave::new(32, 8, vec![0.0; 16]).unwrap();
        assert!(o.result().is_none());
    }
}
