//! The covariance of the overlapping Allan-variance estimates at several
//! averaging factors of one record, under the five-term noise model.
//!
//! Why: overlapping estimates at neighbouring octaves share most of their
//! data, and each one's second differences overlap each other; treating
//! the points as independent (weights from their EDF alone) makes the fitted
//! terms look several times more certain than they are. The generalised
//! least-squares fit ([`super::gls`]) needs the full matrix.
//!
//! Model. With the phase x_k = τ₀·S_k (S the cumulative sums, τ₀ the sample
//! period) the estimate at m is ŝ²(m) = Σ_a D(a)² / (2τ²n), D(a) =
//! x_{a+2m} − 2x_{a+m} + x_a, n = N − 2m + 1. Each noise term has a
//! generalised covariance of the phase g(t) (one that any second difference
//! turns into a true covariance; t the lag in seconds):
//!
//! - quantisation Q (white phase): Q²·[t = 0];
//! - white noise N (white rate, phase a random walk): −N²|t|/2;
//! - bias instability B (flicker rate, S_y = B²/(2πf)): (B²/2π)·t² ln|t|;
//! - random walk K (phase an integrated random walk): K²|t|³/12;
//!
//! each giving exactly the IEEE 952 terms 3Q²/τ², N²/τ, (2 ln 2/π)B², K²τ/3
//! of [`super::noise_terms`]. A rate ramp R is deterministic: it adds the
//! constant μ = Rτ² to every D.
//!
//! For Gaussian noise (Isserlis), with C_ij(L) the covariance of D_i(a) and
//! D_j(a + L) and w(L) the number of index pairs at lag L,
//!
//!   Cov(ŝ²_i, ŝ²_j) = [Σ_L w(L)·C_ij(L)² / (2τ_i²τ_j²) + R²·Σ_L w(L)·C_ij(L)] / (n_i n_j).
//!
//! C is linear in the squared coefficients c = (Q², N², B², K²), so the
//! matrix is a quadratic form in c plus R² times a linear one: the sums are
//! computed once per record for every pair of noise terms ([`OctaveCovariance::new`])
//! and combined for any c in [`OctaveCovariance::matrix`].
//!
//! Computing the sums. C_ij is a double second difference of g (steps m_i
//! and m_j); it is evaluated as an outer difference of the inner one, each
//! inner one in closed form (N, K) or, for B, by its Taylor series where the
//! argument is far from zero, so that no digits are lost to cancellation
//! when m_i ≪ m_j. Far from every kink of C (|c| ≥ 3(m_i + m_j)) B's C has
//! its own convergent series (N and K vanish there). The sum over up to 2N
//! lags is split at the kinks of C and w: near each kink it is summed term
//! by term ([`EXACT_LAGS`] lags), in between C is smooth and the sum is
//! an integral, done by 4-point Gauss–Legendre on intervals growing
//! geometrically away from the kinks (error ≈ 10⁻⁴ relative, far below what
//! the fit needs). Q's C is nonzero only at the 9 kinks: summed exactly.
//!
//! Cost: ≈ (points²/2) pairs × a few thousand evaluations, once per record
//! (not per column): measured in release 0.04 s for 2^19 samples (19
//! octaves), 0.05 s for 2^21, 0.08 s for 2^24.
//!
//! Limits: Isserlis holds for Gaussian noise (quantisation is uniform: its
//! fourth moment is lower, so its variance is slightly overstated); the
//! flicker term is ideal 1/f noise at every lag (a real sensor's, or the
//! simulator's sum of Gauss–Markov terms, only approximates it over a band).

use core::f64::consts::PI;

/// Most points (octaves) one matrix holds: m up to 2^39.
pub const MAX_POINTS: usize = 40;

/// Noise terms with a random part: Q, N, B, K (the ramp R is deterministic).
const NOISES: usize = 4;

/// Pairs (a ≤ b) of noise terms.
const PAIRS: usize = NOISES * (NOISES + 1) / 2;

/// Lags summed term by term at each end of a smooth stretch of C.
pub const EXACT_LAGS: i64 = 16;

/// Gauss–Legendre subintervals grow by this fraction of their distance to the nearest kink.
const GROWTH: f64 = 0.5;

/// Where the flicker C switches to its far series: |c| ≥ FAR·(m_i + m_j).
const FAR: f64 = 3.0;

/// Term indices (as in [`super::noise_terms::Term::ALL`]).
const Q: usize = 0;
const N: usize = 1;
const B: usize = 2;
const K: usize = 3;
const R: usize = 4;

/// Why a covariance cannot be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CovarianceError {
    /// More points than [`MAX_POINTS`].
    TooManyPoints(usize),
    /// The sample period is not a positive finite number.
    Period(f64),
    /// Strides not one per factor, or one of 0 or above its factor.
    Strides,
    /// An averaging factor of 0 or with fewer than one term (2m > N).
    Factor {
        /// The averaging factor.
        m: u64,
        /// The record's samples.
        samples: u64,
    },
    /// A share of the pairs that is not one of the shares.
    Share {
        /// The share asked for.
        share: usize,
        /// The shares.
        shares: usize,
    },
}

impl core::fmt::Display for CovarianceError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CovarianceError::TooManyPoints(n) => {
                write!(f, "{n} points: at most {MAX_POINTS} octaves are supported")
            }
            CovarianceError::Period(p) => {
                write!(f, "sample period {p} s: must be a positive number")
            }
            CovarianceError::Strides => write!(
                f,
                "one stride per averaging factor, each between 1 and its factor"
            ),
            CovarianceError::Share { share, shares } => {
                write!(f, "share {share} of {shares}: there is no such share")
            }
            CovarianceError::Factor { m, samples } => write!(
                f,
                "averaging factor {m} has no Allan term in {samples} samples (needs 1 ≤ 2m ≤ N)"
            ),
        }
    }
}

/// The sums of one record's points, from which the covariance of their
/// overlapping Allan-variance estimates follows for any model.
#[derive(Clone, Debug)]
pub struct OctaveCovariance {
    points: usize,
    m: [u64; MAX_POINTS],
    strides: [u64; MAX_POINTS],
    /// Σ_L w C_a C_b / (2τ_i²τ_j² n_i n_j), per pair of noise terms (a ≤ b).
    quadratic: [[[f64; MAX_POINTS]; MAX_POINTS]; PAIRS],
    /// Σ_L w C_a / (n_i n_j), per noise term (the ramp's cross term).
    linear: [[[f64; MAX_POINTS]; MAX_POINTS]; NOISES],
}

/// The index of the pair (a, b), a ≤ b, of noise terms.
fn pair(a: usize, b: usize) -> usize {
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    a * NOISES - a * (a + 1) / 2 + b
}

impl OctaveCovariance {
    /// The sums for the overlapping estimates at averaging factors `m` of a
    /// record of `samples` rate samples taken every `period` seconds.
    pub fn new(samples: u64, period: f64, m: &[u64]) -> Result<Self, CovarianceError> {
        Self::with_strides(
            samples,
            period,
            m,
            &[1; MAX_POINTS][..m.len().min(MAX_POINTS)],
        )
    }

    /// The sums for estimates whose terms are taken every `strides[i]`
    /// samples at `m[i]` ([`super::strided`]: d = m/M, M ≫ 1; 1 is the fully
    /// overlapping estimator). For N, B and K the sum over every d-th lag is
    /// a Riemann sum of the fully overlapping one's integral (equal to
    /// O(d/m)); quantisation's C lives on a few lags alone, where the pairs
    /// of strided terms are counted exactly (about a min(d_i, d_j)-fold
    /// variance: a d-th of the terms carry it).
    pub fn with_strides(
        samples: u64,
        period: f64,
        m: &[u64],
        strides: &[u64],
    ) -> Result<Self, CovarianceError> {
        Self::share_of_pairs(samples, period, m, strides, 0, 1)
    }

    /// [`Self::with_strides`] of the pairs of points (i, j ≥ i) whose place
    /// in the order (0, 0), (0, 1), … is `share` modulo `shares`, the
    /// others left at zero: `shares` of them, made on as many cores and
    /// added by [`Self::add_share`], are the whole, bit for bit (each pair
    /// is made by one share alone). Balanced: consecutive pairs go to
    /// different shares.
    pub fn share_of_pairs(
        samples: u64,
        period: f64,
        m: &[u64],
        strides: &[u64],
        share: usize,
        shares: usize,
    ) -> Result<Self, CovarianceError> {
        if share >= shares {
            return Err(CovarianceError::Share { share, shares });
        }
        if m.len() > MAX_POINTS {
            return Err(CovarianceError::TooManyPoints(m.len()));
        }
        if !(period.is_finite() && period > 0.0) {
            return Err(CovarianceError::Period(period));
        }
        if let Some(&bad) = m.iter().find(|&&x| x == 0 || x > samples / 2) {
            return Err(CovarianceError::Factor { m: bad, samples });
        }
        if strides.len() != m.len() || strides.iter().zip(m).any(|(&d, &x)| d == 0 || d > x) {
            return Err(CovarianceError::Strides);
        }
        let mut cov = OctaveCovariance {
            points: m.len(),
            m: [0; MAX_POINTS],
            strides: [1; MAX_POINTS],
            quadratic: [[[0.0; MAX_POINTS]; MAX_POINTS]; PAIRS],
            linear: [[[0.0; MAX_POINTS]; MAX_POINTS]; NOISES],
        };
        cov.m[..m.len()].copy_from_slice(m);
        cov.strides[..m.len()].copy_from_slice(strides);
        let mut place = 0;
        for i in 0..m.len() {
            for j in i..m.len() {
                place += 1;
                if (place - 1) % shares != share {
                    continue;
                }
                let sums = PairSums::of(samples, period, [m[i], m[j]], [strides[i], strides[j]]);
                let (ni, nj) = (
                    (samples - 2 * m[i] + 1) as f64,
                    (samples - 2 * m[j] + 1) as f64,
                );
                let (ti, tj) = (m[i] as f64 * period, m[j] as f64 * period);
                let q = 1.0 / (2.0 * ti * ti * tj * tj * ni * nj);
                for p in 0..PAIRS {
                    cov.quadratic[p][i][j] = sums.quadratic[p] * q;
                    cov.quadratic[p][j][i] = sums.quadratic[p] * q;
                }
                for a in 0..NOISES {
                    cov.linear[a][i][j] = sums.linear[a] / (ni * nj);
                    cov.linear[a][j][i] = sums.linear[a] / (ni * nj);
                }
            }
        }
        Ok(cov)
    }

    /// Adds `other`, another share of the same points' pairs
    /// ([`Self::share_of_pairs`]); false (and nothing added) when its
    /// points are not these.
    pub fn add_share(&mut self, other: &Self) -> bool {
        if other.factors() != self.factors() || other.strides() != self.strides() {
            return false;
        }
        for (mine, theirs) in self.quadratic.iter_mut().zip(&other.quadratic) {
            for (row, other_row) in mine.iter_mut().zip(theirs) {
                for (x, y) in row.iter_mut().zip(other_row) {
                    *x += y;
                }
            }
        }
        for (mine, theirs) in self.linear.iter_mut().zip(&other.linear) {
            for (row, other_row) in mine.iter_mut().zip(theirs) {
                for (x, y) in row.iter_mut().zip(other_row) {
                    *x += y;
                }
            }
        }
        true
    }

    /// Number of points.
    pub fn points(&self) -> usize {
        self.points
    }

    /// The averaging factors, in the order given.
    pub fn factors(&self) -> &[u64] {
        &self.m[..self.points]
    }

    /// The strides of the estimates (1: fully overlapping).
    pub fn strides(&self) -> &[u64] {
        &self.strides[..self.points]
    }

    /// The covariance of the estimates under the model with squared
    /// coefficients `c` = (Q², N², B², K², R²) (SI), into `out` (row-major,
    /// points × points); false when `out` is too short.
    pub fn matrix(&self, c: &[f64; 5], out: &mut [f64]) -> bool {
        let p = self.points;
        if out.len() < p * p {
            return false;
        }
        for i in 0..p {
            for j in 0..p {
                let mut v = 0.0;
                for a in 0..NOISES {
                    for b in a..NOISES {
                        let twice = if a == b { 1.0 } else { 2.0 };
                        v += twice * c[a] * c[b] * self.quadratic[pair(a, b)][i][j];
                    }
                    v += c[R] * c[a] * self.linear[a][i][j];
                }
                out[i * p + j] = v;
            }
        }
        true
    }
}

/// The lag sums of one pair of points.
struct PairSums {
    quadratic: [f64; PAIRS],
    linear: [f64; NOISES],
}

/// The geometry of one pair of points: steps, term counts and unit factors.
struct Pair {
    /// Averaging factors of the two points.
    mi: i64,
    mj: i64,
    /// The smaller and the larger step.
    h: f64,
    big: f64,
    /// Terms of each estimate (fully overlapping).
    ni: i64,
    nj: i64,
    /// Strides of each estimate.
    di: i64,
    dj: i64,
    /// τ₀ factors of each generalised covariance.
    unit: [f64; NOISES],
}

impl Pair {
    /// The pair of points at factors `mi` and `mj` of a record of `samples`
    /// taken every `period` seconds.
    fn new(samples: u64, period: f64, mi: u64, mj: u64) -> Self {
        let n = samples as i64;
        let (mi, mj) = (mi as i64, mj as i64);
        Pair {
            mi,
            mj,
            h: mi.min(mj) as f64,
            big: mi.max(mj) as f64,
            ni: n - 2 * mi + 1,
            nj: n - 2 * mj + 1,
            di: 1,
            dj: 1,
            unit: [
                1.0,
                -period / 2.0,
                period * period / (2.0 * PI),
                period * period * period / 12.0,
            ],
        }
    }

    /// Number of index pairs (a, b) with b − a = L.
    fn count(&self, lag: f64) -> f64 {
        let hi = (self.ni as f64).min(self.nj as f64 - lag);
        let lo = (-lag).max(0.0);
        (hi - lo).max(0.0)
    }

    /// The strides of the two estimates (1: fully overlapping).
    fn with_strides(mut self, [di, dj]: [u64; 2]) -> Self {
        self.di = di as i64;
        self.dj = dj as i64;
        self
    }

    /// The pairs of terms at lag L (a ≡ 0 mod d_i, a + L ≡ 0 mod d_j)
    /// scaled to the fully overlapping normalisation: w′(L)·n_i n_j/(n′_i n′_j)
    /// with n′ the strided term counts; [`Self::count`] at strides 1.
    fn strided_count(&self, lag: i64) -> f64 {
        let (di, dj) = (self.di, self.dj);
        let (lo, hi) = ((-lag).max(0), self.ni.min(self.nj - lag));
        if hi <= lo || lag.rem_euclid(di.min(dj)) != 0 {
            return 0.0;
        }
        // Powers of two: a multiple of the larger stride is one of the smaller.
        let pairs = if di >= dj {
            congruent(lo, hi, 0, di)
        } else {
            congruent(lo, hi, (-lag).rem_euclid(dj), dj)
        };
        let n = |n: i64, d: i64| ((n - 1) / d + 1) as f64;
        pairs as f64 * (self.ni as f64 / n(self.ni, di)) * (self.nj as f64 / n(self.nj, dj))
    }

    /// The centre of the double difference at lag L.
    fn centre(&self, lag: f64) -> f64 {
        lag + (self.mj - self.mi) as f64
    }

    /// C_N, C_B, C_K at lag L (any real L: the integrals need it).
    fn smooth(&self, lag: f64) -> [f64; 3] {
        let c = self.centre(lag);
        let (h, big) = (self.h, self.big);
        let outer = |inner: &dyn Fn(f64) -> f64| inner(c + big) - 2.0 * inner(c) + inner(c - big);
        let near = c.abs() < h + big;
        let white = if near {
            outer(&|x| 2.0 * (h - x.abs()).max(0.0))
        } else {
            0.0
        };
        let walk = if near {
            outer(&|x| walk_inner(x, h))
        } else {
            0.0
        };
        let flicker = if c.abs() >= FAR * (h + big) {
            flicker_far(c, h, big)
        } else {
            outer(&|x| flicker_inner(x, h))
        };
        [
            white * self.unit[N],
            flicker * self.unit[B],
            walk * self.unit[K],
        ]
    }

    /// C_Q at an integer lag: the weights of the double difference whose
    /// phase points coincide.
    fn quantisation(&self, lag: i64) -> f64 {
        let c = lag + self.mj - self.mi;
        let beta = [(-1i64, 1.0), (0, -2.0), (1, 1.0)];
        let mut sum = 0.0;
        for (u, bu) in beta {
            for (v, bv) in beta {
                if c + u * self.mi + v * self.mj == 0 {
                    sum += bu * bv;
                }
            }
        }
        sum
    }
}

/// The integers a in lo..hi (lo ≥ 0) with a ≡ r (mod d), 0 ≤ r < d.
fn congruent(lo: i64, hi: i64, r: i64, d: i64) -> i64 {
    let below = |x: i64| (x - r + d - 1).div_euclid(d); // a < x
    (below(hi) - below(lo)).max(0)
}

/// D_h of |x|³: 6h²|x| beyond h, a cubic inside.
fn walk_inner(x: f64, h: f64) -> f64 {
    let a = x.abs();
    if a >= h {
        6.0 * h * h * a
    } else {
        2.0 * h * h * h + 6.0 * h * a * a - 2.0 * a * a * a
    }
}

/// x² ln|x| (0 at 0).
fn flicker_g(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x * x * libm::log(libm::fabs(x))
    }
}

/// D_h of x² ln|x| at x: directly near 0, else its Taylor series
/// h²(2 ln|x| + 3) − 4h² Σ_{k≥2} (h/x)^{2k−2} / (2k(2k−1)(2k−2)), which keeps
/// every digit when h ≪ |x|.
fn flicker_inner(x: f64, h: f64) -> f64 {
    if libm::fabs(x) < FAR * h {
        return flicker_g(x + h) - 2.0 * flicker_g(x) + flicker_g(x - h);
    }
    let r2 = (h / x) * (h / x);
    let mut power = r2;
    let mut tail = 0.0;
    for k in 2..40 {
        let k2 = 2.0 * k as f64;
        let term = power / (k2 * (k2 - 1.0) * (k2 - 2.0));
        tail += term;
        if term < 1e-17 * tail {
            break;
        }
        power *= r2;
    }
    h * h * (2.0 * libm::log(libm::fabs(x)) + 3.0 - 4.0 * tail)
}

/// The flicker C far from every kink: −2 Σ_{n even ≥ 4} M_n / (n(n−1)(n−2) c^{n−2})
/// with M_n = Σ_{r even, 2 ≤ r ≤ n−2} C(n,r)·4·h^r·H^{n−r} (all terms positive).
fn flicker_far(c: f64, h: f64, big: f64) -> f64 {
    const TOP: usize = 60;
    let (x, y) = (h / c, big / c);
    // x^k and y^k for k ≤ TOP by running products, not pow() per term
    // (pow per term took two thirds of the covariance's time).
    let (mut xp, mut yp) = ([1.0; TOP + 1], [1.0; TOP + 1]);
    for k in 1..=TOP {
        xp[k] = xp[k - 1] * x;
        yp[k] = yp[k - 1] * y;
    }
    let mut total = 0.0;
    let mut n = 4usize;
    while n <= TOP {
        // Σ_r C(n,r) x^r y^{n−r} over even r in 2..=n−2.
        let mut binom = 1.0; // C(n, 0)
        let mut s = 0.0;
        for r in 0..=n {
            if r >= 2 && r <= n - 2 && r % 2 == 0 {
                s += binom * xp[r] * yp[n - r];
            }
            binom = binom * (n - r) as f64 / (r + 1) as f64;
        }
        let nf = n as f64;
        let term = 4.0 * s / (nf * (nf - 1.0) * (nf - 2.0));
        total += term;
        if libm::fabs(term) < 1e-16 * libm::fabs(total) {
            break;
        }
        n += 2;
    }
    -2.0 * c * c * total
}

/// 4-point Gauss–Legendre nodes and weights on [−1, 1].
const GAUSS: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
];

impl PairSums {
    fn of(samples: u64, period: f64, [mi, mj]: [u64; 2], strides: [u64; 2]) -> Self {
        let p = Pair::new(samples, period, mi, mj).with_strides(strides);
        let (mi, mj) = (p.mi, p.mj);
        let mut sums = PairSums {
            quadratic: [0.0; PAIRS],
            linear: [0.0; NOISES],
        };
        let (first, end) = (-(p.ni - 1), p.nj);
        // Kinks of C (where a phase point of one difference meets one of the
        // other) and of w, then the range's ends: the smooth stretches lie between.
        let mut cuts = [0i64; 13];
        let mut k = 0;
        for u in -1..=1 {
            for v in -1..=1 {
                cuts[k] = -(u * mi + v * mj) - (mj - mi);
                k += 1;
            }
        }
        cuts[9] = 0;
        cuts[10] = p.nj - p.ni;
        cuts[11] = first;
        cuts[12] = end;
        for c in cuts.iter_mut() {
            *c = (*c).clamp(first, end);
        }
        cuts.sort_unstable();
        for w in cuts.windows(2) {
            if w[1] > w[0] {
                sums.stretch(&p, w[0], w[1]);
            }
        }
        sums.quantisation_terms(&p, &cuts, first, end);
        sums
    }

    /// Adds weight·f at lag L for every smooth term (N, B, K).
    fn add(&mut self, p: &Pair, lag: f64, weight: f64) {
        let w = weight * p.count(lag);
        if w == 0.0 {
            return;
        }
        let c = p.smooth(lag);
        let terms = [N, B, K];
        for (x, &a) in terms.iter().enumerate() {
            self.linear[a] += w * c[x];
            for (y, &b) in terms.iter().enumerate().skip(x) {
                self.quadratic[pair(a, b)] += w * c[x] * c[y];
            }
        }
    }

    /// Σ over the integer lags from..stop (exclusive), C smooth inside.
    fn stretch(&mut self, p: &Pair, from: i64, stop: i64) {
        if stop - from <= 2 * EXACT_LAGS + 2 {
            for lag in from..stop {
                self.add(p, lag as f64, 1.0);
            }
            return;
        }
        for lag in (from..from + EXACT_LAGS).chain(stop - EXACT_LAGS..stop) {
            self.add(p, lag as f64, 1.0);
        }
        // The integers a..b−1 as the integral over [a − ½, b − ½], in
        // intervals growing away from the kinks at `from` and at `stop`.
        let a = (from + EXACT_LAGS) as f64 - 0.5;
        let b = (stop - EXACT_LAGS) as f64 - 0.5;
        let mid = 0.5 * (a + b);
        let mut x = a;
        while x < mid {
            let next = (x + GROWTH * (x - from as f64)).min(mid);
            self.gauss(p, x, next);
            x = next;
        }
        let mut x = b;
        while x > mid {
            let next = (x - GROWTH * (stop as f64 - x)).max(mid);
            self.gauss(p, next, x);
            x = next;
        }
        // Euler–Maclaurin: the sum is the integral − (f′(b) − f′(a))/24, f′
        // by central differences over the neighbouring integers.
        let (ia, ib) = (from + EXACT_LAGS, stop - EXACT_LAGS);
        self.add(p, ib as f64, -1.0 / 24.0);
        self.add(p, (ib - 1) as f64, 1.0 / 24.0);
        self.add(p, ia as f64, 1.0 / 24.0);
        self.add(p, (ia - 1) as f64, -1.0 / 24.0);
    }

    fn gauss(&mut self, p: &Pair, lo: f64, hi: f64) {
        let (half, centre) = (0.5 * (hi - lo), 0.5 * (hi + lo));
        for (node, weight) in GAUSS {
            self.add(p, centre + half * node, weight * half);
        }
    }

    /// Q's terms: its C is nonzero only at the kinks.
    fn quantisation_terms(&mut self, p: &Pair, cuts: &[i64], first: i64, end: i64) {
        for (idx, &lag) in cuts.iter().enumerate() {
            if lag < first || lag >= end || cuts[..idx].contains(&lag) {
                continue;
            }
            let cq = p.quantisation(lag);
            if cq == 0.0 {
                continue;
            }
            let w = p.strided_count(lag);
            let c = p.smooth(lag as f64);
            self.linear[Q] += w * cq;
            self.quadratic[pair(Q, Q)] += w * cq * cq;
            for (x, a) in [N, B, K].into_iter().enumerate() {
                self.quadratic[pair(Q, a)] += w * cq * c[x];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_of_the_pairs_add_up_to_the_whole_bit_for_bit() {
        let m = [1u64, 2, 4, 8, 16, 32, 64, 128];
        let strides = [1u64, 1, 1, 1, 1, 2, 4, 8];
        let whole = OctaveCovariance::with_strides(10_000, 0.01, &m, &strides).unwrap();
        let mut sum = OctaveCovariance::share_of_pairs(10_000, 0.01, &m, &strides, 0, 3).unwrap();
        for share in 1..3 {
            let part =
                OctaveCovariance::share_of_pairs(10_000, 0.01, &m, &strides, share, 3).unwrap();
            assert!(sum.add_share(&part));
        }
        let c = [1e-6, 2e-5, 3e-7, 4e-8, 5e-9];
        let (mut a, mut b) = ([0.0; 64], [0.0; 64]);
        assert!(whole.matrix(&c, &mut a) && sum.matrix(&c, &mut b));
        assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        // One share alone is not the whole, and other points are refused.
        let one = OctaveCovariance::share_of_pairs(10_000, 0.01, &m, &strides, 1, 3).unwrap();
        let mut c1 = [0.0; 64];
        assert!(one.matrix(&c, &mut c1));
        assert_ne!(c1.map(f64::to_bits), a.map(f64::to_bits));
        let other = OctaveCovariance::new(10_000, 0.01, &m[..4]).unwrap();
        assert!(!sum.add_share(&other));
        assert!(matches!(
            OctaveCovariance::share_of_pairs(10_000, 0.01, &m, &strides, 3, 3),
            Err(CovarianceError::Share {
                share: 3,
                shares: 3
            })
        ));
    }

    #[test]
    fn pairs_are_numbered_once_each() {
        let mut seen = [false; PAIRS];
        for a in 0..NOISES {
            for b in a..NOISES {
                assert!(!seen[pair(a, b)]);
                seen[pair(a, b)] = true;
                assert_eq!(pair(a, b), pair(b, a));
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn the_flicker_series_agree_where_they_meet() {
        // Near and far formulas of the flicker C at the switch, for equal
        // and very unequal steps.
        for (h, big) in [(4.0, 4.0), (1.0, 1024.0), (16.0, 64.0)] {
            let c = FAR * (h + big);
            let near = {
                let inner = |x: f64| flicker_inner(x, h);
                inner(c + big) - 2.0 * inner(c) + inner(c - big)
            };
            let far = flicker_far(c, h, big);
            assert!(
                libm::fabs(near - far) <= 1e-6 * libm::fabs(far),
                "h {h} H {big}: {near} vs {far}"
            );
        }
    }

    /// The sums lag by lag, without the integrals (the reference for them).
    fn brute(samples: u64, period: f64, mi: u64, mj: u64) -> PairSums {
        let quick = PairSums::of(samples, period, [mi, mj], [1, 1]);
        let p = Pair::new(samples, period, mi, mj);
        let mut sums = PairSums {
            quadratic: [0.0; PAIRS],
            linear: [0.0; NOISES],
        };
        for lag in -(p.ni - 1)..p.nj {
            sums.add(&p, lag as f64, 1.0);
        }
        // Q's terms are exact sums already.
        for a in [Q] {
            sums.linear[a] = quick.linear[a];
            for b in 0..NOISES {
                sums.quadratic[pair(a, b)] = quick.quadratic[pair(a, b)];
            }
        }
        sums
    }

    #[test]
    fn the_integrals_match_the_lag_by_lag_sums() {
        for (samples, mi, mj) in [
            (4000u64, 1u64, 1u64),
            (4000, 2, 64),
            (5000, 128, 512),
            (3000, 1, 1024),
        ] {
            let quick = PairSums::of(samples, 0.1, [mi, mj], [1, 1]);
            let slow = brute(samples, 0.1, mi, mj);
            for (k, (a, b)) in quick.quadratic.iter().zip(&slow.quadratic).enumerate() {
                assert!(
                    libm::fabs(a - b) <= 1e-4 * libm::fabs(*b) + 1e-300,
                    "m {mi},{mj} quadratic {k}: {a:e} vs {b:e}"
                );
            }
            for (k, (a, b)) in quick.linear.iter().zip(&slow.linear).enumerate() {
                // The linear sums cancel (a second difference sums to its
                // ends), so they are compared with the scale of their terms.
                let scale = libm::sqrt(libm::fabs(slow.quadratic[pair(k, k)]));
                assert!(
                    libm::fabs(a - b) <= 1e-4 * scale + 1e-300,
                    "m {mi},{mj} linear {k}: {a:e} vs {b:e}"
                );
            }
        }
    }

    #[test]
    fn each_term_gives_its_allan_variance_at_lag_zero() {
        // C_ii(0) / (2τ²) is the Allan variance of the term with unit coefficient.
        let (period, m) = (0.5, 8u64);
        let p = Pair::new(200, period, m, m);
        let tau = m as f64 * period;
        let [n, b, k] = p.smooth(0.0).map(|c| c / (2.0 * tau * tau));
        let q = p.quantisation(0) / (2.0 * tau * tau);
        let close = |a: f64, b: f64| libm::fabs(a - b) <= 1e-12 * libm::fabs(b);
        assert!(close(q, 3.0 / (tau * tau)), "Q {q}");
        assert!(close(n, 1.0 / tau), "N {n}");
        assert!(close(b, 2.0 * core::f64::consts::LN_2 / PI), "B {b}");
        assert!(close(k, tau / 3.0), "K {k}");
    }
}
