//! The published reference data sets of NIST SP 1065 §12 (Riley, "Handbook of
//! Frequency Stability Analysis", 2008; the same values are in allantools'
//! tests): the NBS14 9-frequency-point (10 phase points) set and the
//! 1000-point set of the SP 1065 linear congruential generator. Both are
//! fractional-frequency data, i.e. rate data, at τ₀ = 1 s.
//!
//! Tolerance: the published values have 7 significant digits; each result
//! must round to them (|x − published| ≤ half a unit of the last digit).

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_lab::allan::direct;

/// NBS14 frequency data (SP 1065 §12.1).
const NBS14: [f64; 9] = [
    892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0,
];

/// The SP 1065 §12.2 1000-point set: n(i+1) = 16807·n(i) mod (2³¹ − 1) from
/// n(0) = 1234567890, x = n/(2³¹ − 1).
fn nbs1000() -> Vec<f64> {
    let mut n: u64 = 1_234_567_890;
    let mut x = Vec::with_capacity(1000);
    for _ in 0..1000 {
        x.push(n as f64 / 2_147_483_647.0);
        n = (16_807 * n) % 2_147_483_647;
    }
    x
}

/// Asserts that `x` rounds to `published`, given with `digits` significant digits.
fn assert_published(x: f64, published: f64, digits: i32, what: &str) {
    let unit = 10f64.powi(published.abs().log10().floor() as i32 - (digits - 1));
    assert!(
        (x - published).abs() <= 0.5 * unit,
        "{what}: {x} does not round to the published {published}"
    );
}

fn sums(y: &[f64]) -> Vec<f64> {
    let mut s = vec![0.0; y.len() + 1];
    assert!(direct::cumulative_sums(y, 0.0, &mut s));
    s
}

#[test]
fn lcg_gives_the_published_first_values() {
    // SP 1065 §12.2 lists n(1..3) to check an implementation of the generator.
    let x = nbs1000();
    let n: Vec<u64> = x[..4]
        .iter()
        .map(|v| (v * 2_147_483_647.0).round() as u64)
        .collect();
    assert_eq!(n, [1_234_567_890, 395_529_916, 1_209_410_747, 633_705_974]);
}

#[test]
fn nbs14_adev_and_oadev_match_the_published_values() {
    let s = sums(&NBS14);
    let adev = |m| direct::non_overlapping(&s, m).unwrap().0.sqrt();
    let oadev = |m| direct::overlapping(&s, m).unwrap().0.sqrt();
    assert_published(adev(1), 91.22945, 7, "ADEV tau=1");
    assert_published(adev(2), 115.8082, 7, "ADEV tau=2");
    assert_published(oadev(1), 91.22945, 7, "OADEV tau=1");
    assert_published(oadev(2), 85.95287, 7, "OADEV tau=2");
}

#[test]
fn nbs14_streaming_matches_the_published_values() {
    let mut ring = [0.0; 8];
    let mut acc = OctaveAccumulator::new(&mut ring, 0.0).unwrap();
    for &y in &NBS14 {
        acc.push(y);
    }
    let r: Vec<_> = acc.results().collect();
    assert_eq!(
        r.len(),
        3,
        "m = 1, 2, 4 (2m ≤ 9 samples and 2m ≤ 8 slots); m = 8 has no term"
    );
    assert_published(r[0].overlapping.sqrt(), 91.22945, 7, "OADEV tau=1");
    assert_published(r[1].overlapping.sqrt(), 85.95287, 7, "OADEV tau=2");
    assert_published(r[0].non_overlapping.sqrt(), 91.22945, 7, "ADEV tau=1");
    assert_published(r[1].non_overlapping.sqrt(), 115.8082, 7, "ADEV tau=2");
    // Term counts: N − 2m + 1 overlapping, ⌊N/m⌋ − 1 non-overlapping.
    assert_eq!((r[1].overlapping_terms, r[1].non_overlapping_terms), (6, 3));
}

#[test]
fn nbs1000_adev_and_oadev_match_the_published_values() {
    let s = sums(&nbs1000());
    // SP 1065 Table 31 (Riley's Table III): m = 1, 10, 100.
    let adev = [2.922319e-01, 9.965736e-02, 3.897804e-02];
    let oadev = [2.922319e-01, 9.159953e-02, 3.241343e-02];
    for (i, m) in [1usize, 10, 100].into_iter().enumerate() {
        let a = direct::non_overlapping(&s, m).unwrap().0.sqrt();
        let o = direct::overlapping(&s, m).unwrap().0.sqrt();
        assert_published(a, adev[i], 7, &format!("ADEV m={m}"));
        assert_published(o, oadev[i], 7, &format!("OADEV m={m}"));
    }
}

#[test]
fn streaming_octaves_equal_the_direct_computation() {
    // Same formula, different summation order: agreement to 1e-12 relative
    // (the block sums differ from one compensated sum by ≤ 1024·ε ≈ 2e-13).
    let y = nbs1000();
    let s = sums(&y);
    // Start with a small ring and grow it before it wraps, as the host does.
    let mut acc = OctaveAccumulator::new(vec![0.0; 4], 0.5).unwrap();
    for &v in &y {
        if acc.samples() + 1 == acc.ring_len() as u64 && acc.ring_len() < 1024 {
            let len = 2 * acc.ring_len();
            acc.grow(vec![0.0; len]).unwrap();
        }
        acc.push(v);
    }
    let results: Vec<_> = acc.results().collect();
    assert_eq!(results.len(), 9, "m = 1 … 256 (2m ≤ 1000)");
    for r in results {
        let m = r.m as usize;
        let (o, on) = direct::overlapping(&s, m).unwrap();
        let (a, an) = direct::non_overlapping(&s, m).unwrap();
        assert_eq!(r.overlapping_terms, on);
        assert_eq!(r.non_overlapping_terms, an);
        assert!((r.overlapping - o).abs() <= 1e-12 * o, "m={m}");
        assert!((r.non_overlapping - a).abs() <= 1e-12 * a, "m={m}");
    }
}

#[test]
fn a_small_ring_bounds_the_octaves_not_the_record() {
    let y = nbs1000();
    let mut ring = [0.0; 16];
    let mut acc = OctaveAccumulator::new(&mut ring, 0.0).unwrap();
    for &v in &y {
        acc.push(v);
    }
    assert_eq!(acc.max_m(), 8);
    let ms: Vec<u64> = acc.results().map(|r| r.m).collect();
    assert_eq!(ms, [1, 2, 4, 8]);
    let s = sums(&y);
    let last = acc.result(3).unwrap();
    let (o, _) = direct::overlapping(&s, 8).unwrap();
    assert!((last.overlapping - o).abs() <= 1e-12 * o);
}

#[test]
fn bad_rings_and_offsets_are_errors() {
    use triad_lab::allan::accumulate::AccumulatorError;
    let mut r3 = [0.0; 3];
    let mut r1 = [0.0; 1];
    assert_eq!(
        OctaveAccumulator::new(&mut r1, 0.0).unwrap_err(),
        AccumulatorError::RingLength(1)
    );
    assert_eq!(
        OctaveAccumulator::new(&mut r3, 0.0).unwrap_err(),
        AccumulatorError::RingLength(3)
    );
    let mut r12 = [0.0; 12];
    assert_eq!(
        OctaveAccumulator::new(&mut r12, 0.0).unwrap_err(),
        AccumulatorError::RingLength(12)
    );
    let mut r8 = [0.0; 8];
    assert!(matches!(
        OctaveAccumulator::new(&mut r8, f64::NAN).unwrap_err(),
        AccumulatorError::Offset(x) if x.is_nan()
    ));
    // Growing: only longer powers of two, and only before the ring wraps.
    let mut acc = OctaveAccumulator::new(vec![0.0; 4], 0.0).unwrap();
    assert_eq!(
        acc.grow(vec![0.0; 6]).unwrap_err(),
        AccumulatorError::GrowLength {
            current: 4,
            proposed: 6
        }
    );
    for _ in 0..4 {
        acc.push(1.0);
    }
    assert_eq!(
        acc.grow(vec![0.0; 8]).unwrap_err(),
        AccumulatorError::GrowAfterWrap {
            samples: 4,
            current: 4
        }
    );
}
