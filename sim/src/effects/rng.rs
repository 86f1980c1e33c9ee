//! Portable random streams: one per (seed, triad, axis, effect).
//!
//! SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number
//! generators", OOPSLA 2014) turns the stream key into the state of a
//! xoshiro256++ generator (Blackman & Vigna, "Scrambled linear pseudorandom
//! number generators", ACM TOMS 2021). Normal deviates come from the
//! Ziggurat method ([`super::ziggurat`]: constant tables, `libm`'s pure-Rust
//! `exp` and `log` on the rare slow paths), so the same seed gives the same
//! bits on every machine (no platform libm).

use triad::model::Triad;

/// SplitMix64's output function: a bijective 64-bit mixer.
pub const fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The SplitMix64 generator: used only to expand a key into xoshiro state.
#[derive(Clone, Copy, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

    /// A generator starting at `seed`.
    pub const fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(Self::GOLDEN_GAMMA);
        mix64(self.0)
    }
}

/// Which effect a stream feeds. The numbers are part of the file format of
/// every simulation ever made: never renumber, only append.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EffectId {
    /// Band-limited white noise.
    WhiteNoise = 1,
    /// First-order Gauss–Markov bias.
    GaussMarkov = 2,
    /// Random walk of the bias.
    RandomWalk = 3,
    /// Bias instability (sum of Gauss–Markov terms).
    BiasInstability = 4,
    /// Turn-on bias, drawn once.
    TurnOnBias = 5,
    /// Turn-on scale-factor error, drawn once.
    TurnOnScale = 6,
    /// A ring laser gyro's dither: its passages and its fringe offsets.
    RingLaser = 7,
    /// Turn-on misalignment of a unit, drawn once.
    TurnOnMisalignment = 8,
}

/// A xoshiro256++ generator.
#[derive(Clone, Copy, Debug)]
pub struct Rng {
    s: [u64; 4],
}

impl Rng {
    /// A generator whose state SplitMix64 expands from `seed`.
    pub fn from_seed(seed: u64) -> Self {
        let mut sm = SplitMix64::new(seed);
        // SplitMix64 outputs of consecutive counters are distinct (mix64 is a
        // bijection), so at most one word is zero: never the all-zero state.
        let s = [sm.next_u64(), sm.next_u64(), sm.next_u64(), sm.next_u64()];
        Self { s }
    }

    /// A generator with the given xoshiro256++ state (must not be all zero);
    /// for checking against the reference implementation's test vectors.
    pub const fn from_state(s: [u64; 4]) -> Self {
        Self { s }
    }

    /// The stream of one effect on one axis of one triad.
    ///
    /// For a fixed seed, distinct (triad, axis, effect) keys give distinct
    /// SplitMix64 seeds: the key is packed injectively, multiplied by an odd
    /// constant (a bijection mod 2⁶⁴), XORed with a mix of the seed and mixed
    /// again (a bijection).
    pub fn for_stream(seed: u64, triad: Triad, axis: u8, effect: EffectId) -> Self {
        let key = ((triad as u64) << 16) | ((axis as u64) << 8) | (effect as u64);
        let inner = mix64(seed) ^ key.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        Self::from_seed(mix64(inner))
    }

    /// The next 64 random bits (xoshiro256++).
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// A uniform deviate in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (Ziggurat method).
    pub fn gaussian(&mut self) -> f64 {
        super::ziggurat::sample(|| self.next_u64())
    }
}
