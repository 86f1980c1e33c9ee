//! The random streams: the generator matches the reference xoshiro256++ and
//! SplitMix64, the normal deviates have the right moments, and distinct
//! (triad, axis, effect) keys give distinct streams.

use triad::model::Triad;
use triad_sim::effects::rng::{EffectId, Rng};

#[test]
fn xoshiro256plusplus_matches_reference_test_vector() {
    // Blackman & Vigna's reference xoshiro256plusplus.c from state {1, 2, 3, 4}
    // (the same vector rand's Xoshiro256PlusPlus tests against).
    let mut rng = Rng::from_state([1, 2, 3, 4]);
    let expected: [u64; 10] = [
        41943041,
        58720359,
        3588806011781223,
        3591011842654386,
        9228616714210784205,
        9973669472204895162,
        14011001112246962877,
        12406186145184390807,
        15849039046786891736,
        10450023813501588000,
    ];
    for e in expected {
        assert_eq!(rng.next_u64(), e);
    }
}

#[cfg(target_pointer_width = "64")]
#[test]
fn splitmix_seeding_matches_rand_small_rng() {
    // rand 0.9's SmallRng on 64-bit targets is xoshiro256++ seeded by
    // SplitMix64 from a u64: an independent implementation of from_seed.
    use rand::{rngs::SmallRng, RngCore, SeedableRng};
    for seed in [0u64, 1, 42, u64::MAX] {
        let mut ours = Rng::from_seed(seed);
        let mut theirs = SmallRng::seed_from_u64(seed);
        for _ in 0..100 {
            assert_eq!(ours.next_u64(), theirs.next_u64());
        }
    }
}

#[test]
fn gaussian_has_zero_mean_unit_variance_and_normal_tails() {
    // n = 10⁶ deviates: the sample mean has SE 1/√n = 0.001 and the sample
    // variance SE √(2/n) = 0.0014; 5 SE bounds. P(|z| > 2) = 0.0455 with
    // binomial SE √(p(1−p)/n) = 0.0002; 5 SE = 0.001.
    let mut rng = Rng::from_seed(7);
    let n = 1_000_000;
    let (mut sum, mut sum2, mut beyond2) = (0.0, 0.0, 0usize);
    for _ in 0..n {
        let z = rng.gaussian();
        sum += z;
        sum2 += z * z;
        if z.abs() > 2.0 {
            beyond2 += 1;
        }
    }
    let mean = sum / n as f64;
    let var = sum2 / n as f64 - mean * mean;
    assert!(mean.abs() < 0.005, "mean {mean}");
    assert!((var - 1.0).abs() < 0.007, "variance {var}");
    let p = beyond2 as f64 / n as f64;
    assert!((p - 0.0455).abs() < 0.001, "P(|z|>2) = {p}");
}

#[test]
fn gaussian_tails_have_normal_probability() {
    // The Ziggurat's tail (beyond R = 3.654) and wedges are separate code
    // paths: P(|z| > 3) = 2.700e-3, P(|z| > 3.654) = 2.581e-4 and
    // P(|z| > 4.5) = 6.795e-6 (erfc). With n = 4·10⁶ draws the counts are
    // binomial with SD √(np); 5 SD bounds (a tail drawn with a wrong R or a
    // missing sign is off by far more).
    let mut rng = Rng::from_seed(11);
    let n = 4_000_000usize;
    let limits = [
        (3.0, 2.699_796e-3),
        (3.654_152_885_361_009, 2.581_4e-4),
        (4.5, 6.795_3e-6),
    ];
    let mut counts = [0usize; 3];
    let mut negative_tail = 0usize;
    for _ in 0..n {
        let z = rng.gaussian();
        for (c, (lim, _)) in counts.iter_mut().zip(limits) {
            if z.abs() > lim {
                *c += 1;
            }
        }
        if z < -3.654_152_885_361_009 {
            negative_tail += 1;
        }
    }
    for (c, (lim, p)) in counts.iter().zip(limits) {
        let expected = p * n as f64;
        assert!(
            (*c as f64 - expected).abs() < 5.0 * expected.sqrt(),
            "P(|z| > {lim}): {c} vs {expected}"
        );
    }
    // Both signs of the tail: half each, SD √(c/4).
    let half = counts[1] as f64 / 2.0;
    assert!((negative_tail as f64 - half).abs() < 5.0 * (half / 2.0).sqrt());
}

#[test]
fn ziggurat_tables_satisfy_their_recurrence() {
    // x₀ = V/f(R), x₁ = R, and every layer has the same area V:
    // x_i·(f(x_{i+1}) − f(x_i)) = V; F holds f(x_i). Checked with libm to
    // 1e-12 relative (the tables were generated in another language).
    use triad_sim::effects::ziggurat::{F, R, X};
    let f = |x: f64| libm::exp(-0.5 * x * x);
    let v = X[0] * f(R);
    assert!((v - 0.004_928_673_233_99).abs() < 1e-15);
    assert_eq!(X[1], R);
    assert_eq!(X[256], 0.0);
    for i in 1..256 {
        let area = X[i] * (f(X[i + 1]) - f(X[i]));
        assert!(
            ((area - v) / v).abs() < 1e-9,
            "layer {i}: area {area} vs {v}"
        );
        assert!(X[i + 1] < X[i]);
    }
    for i in 0..257 {
        assert!((F[i] - f(X[i])).abs() <= 1e-15 * F[i].max(1e-300), "F[{i}]");
    }
}

#[test]
fn uniform_lies_in_unit_interval() {
    let mut rng = Rng::from_seed(3);
    for _ in 0..100_000 {
        let u = rng.uniform();
        assert!((0.0..1.0).contains(&u));
    }
}

#[test]
fn distinct_keys_give_distinct_streams_and_same_key_the_same() {
    let triads = [Triad::Accel, Triad::Gyro];
    let effects = [
        EffectId::WhiteNoise,
        EffectId::GaussMarkov,
        EffectId::RandomWalk,
        EffectId::BiasInstability,
        EffectId::TurnOnBias,
        EffectId::TurnOnScale,
    ];
    let mut firsts = Vec::new();
    for seed in [0u64, 1] {
        for t in triads {
            for axis in 0..3 {
                for e in effects {
                    let a = Rng::for_stream(seed, t, axis, e).next_u64();
                    let b = Rng::for_stream(seed, t, axis, e).next_u64();
                    assert_eq!(a, b, "same key, same stream");
                    firsts.push(a);
                }
            }
        }
    }
    let n = firsts.len();
    firsts.sort_unstable();
    firsts.dedup();
    assert_eq!(
        firsts.len(),
        n,
        "every (seed, triad, axis, effect) stream differs"
    );
}

#[test]
fn gaussian_sequence_is_pinned_for_portability() {
    // Golden values: the first deviates of one stream, recorded from this
    // implementation. Every operation on the path (integer xoshiro, exact
    // IEEE multiply/add/sqrt, libm's pure-Rust log) is platform independent,
    // so any machine must reproduce these bits; a change here changes every
    // simulated file ever made and must be deliberate.
    let mut rng = Rng::for_stream(12345, Triad::Gyro, 2, EffectId::WhiteNoise);
    let got: Vec<u64> = (0..4).map(|_| rng.gaussian().to_bits()).collect();
    let golden: [u64; 4] = GOLDEN;
    assert_eq!(
        got,
        golden,
        "got {:?}",
        got.iter().map(|b| f64::from_bits(*b)).collect::<Vec<_>>()
    );
}

const GOLDEN: [u64; 4] = [
    4607201671933904980,
    13827320764473206732,
    4607165968034714980,
    4603609197604402172,
];

#[test]
fn long_gaussian_sequence_is_pinned_for_portability() {
    // A checksum over 10⁵ deviates, so the wedge (exp) and tail (log) paths,
    // about 1.2 % of draws, are pinned too. Recorded like GOLDEN above.
    let mut rng = Rng::for_stream(12345, Triad::Accel, 0, EffectId::GaussMarkov);
    let mut h = 0u64;
    for _ in 0..100_000 {
        h = (h ^ rng.gaussian().to_bits()).wrapping_mul(0x100_0000_01b3);
    }
    assert_eq!(h, GOLDEN_CHECKSUM, "got {h}");
}

const GOLDEN_CHECKSUM: u64 = 9774169998629201616;
