//! The random streams: the generator matches the reference xoshiro256++ and
//! SplitMix64, the normal deviates have the right moments, and distinct
//! (triad, axis, effect) keys give distinct streams.

use triad::sim::rng::{EffectId, Rng, TriadId};

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
fn uniform_lies_in_unit_interval() {
    let mut rng = Rng::from_seed(3);
    for _ in 0..100_000 {
        let u = rng.uniform();
        assert!((0.0..1.0).contains(&u));
    }
}

#[test]
fn distinct_keys_give_distinct_streams_and_same_key_the_same() {
    let triads = [TriadId::Accel, TriadId::Gyro];
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
    let mut rng = Rng::for_stream(12345, TriadId::Gyro, 2, EffectId::WhiteNoise);
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
    4607543083741690748,
    13827103337834838821,
    4607785347424463077,
    4603625530770094100,
];
