//! Allan variance at any averaging factor on a record held in memory: the
//! every-τ mode and the published reference sets. O(N) per m.

use super::sum::CompensatedSum;

/// Fills `sums` (length `y.len() + 1`) with the cumulative sums
/// S_k = Σ_{i<k} (y_i − offset), compensated; returns false (and writes
/// nothing) when the lengths do not match.
pub fn cumulative_sums(y: &[f64], offset: f64, sums: &mut [f64]) -> bool {
    if sums.len() != y.len() + 1 {
        return false;
    }
    let mut s = CompensatedSum::ZERO;
    sums[0] = 0.0;
    for (out, &x) in sums[1..].iter_mut().zip(y) {
        s.add(x - offset);
        *out = s.value();
    }
    true
}

/// The Allan variance at averaging factor `m` from cumulative sums `s`
/// (N + 1 values for N samples), taking every `stride`-th second difference:
/// stride 1 is the overlapping estimator, stride m the non-overlapping one.
/// Returns (variance, number of terms), or None when m or stride is 0 or
/// there is no term (N < 2m).
pub fn allan_variance(s: &[f64], m: usize, stride: usize) -> Option<(f64, u64)> {
    if m == 0 || stride == 0 || s.len() < 2 * m + 1 {
        return None;
    }
    let mut total = CompensatedSum::ZERO;
    let mut terms = 0u64;
    let mut j = 0;
    while j + 2 * m < s.len() {
        let d = (s[j + 2 * m] - s[j + m]) - (s[j + m] - s[j]);
        total.add(d * d);
        terms += 1;
        j += stride;
    }
    let mf = m as f64;
    Some((total.value() / (2.0 * mf * mf * terms as f64), terms))
}

/// The overlapping Allan variance at `m` (see [`allan_variance`]).
pub fn overlapping(s: &[f64], m: usize) -> Option<(f64, u64)> {
    allan_variance(s, m, 1)
}

/// The non-overlapping Allan variance at `m` (see [`allan_variance`]).
pub fn non_overlapping(s: &[f64], m: usize) -> Option<(f64, u64)> {
    allan_variance(s, m, m)
}
