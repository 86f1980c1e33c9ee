//! The fully overlapping octaves of one column, a block of samples at a
//! time: the streaming estimator of
//! [`OctaveAccumulator`](triad_lab::allan::accumulate::OctaveAccumulator)
//! (the same cumulative sums S_k, the same terms), reorganised for speed.
//!
//! Why not one sample at a time: there, each sample visits every octave
//! (a dozen and more), each visit two dependent reads of a ring and two
//! sums; that was half of `triad allan`'s time on a long bag. Here a block's
//! cumulative sums are appended to a plain buffer that keeps the last
//! 2·m_max of them before the block, and then each octave m sums
//! (S_k − 2S_{k−m} + S_{k−2m})² over the block in one loop over three
//! contiguous slices, in [`LANES`] independent partial sums, which the
//! compiler vectorises. The buffer is shifted down only when full (it holds
//! the history four times over), so the copy costs a third of an f64 per
//! sample.
//!
//! Rounding: a lane adds at most [`MAX_BLOCK`]/[`LANES`] = 256 terms (each
//! square added in one rounding, a fused multiply-add) before its block's
//! total is added with compensation, within the bound the one-sample
//! accumulator has (1024·ε relative); the order of the terms differs, so
//! the two agree to that bound, not bit for bit.

use triad_lab::allan::accumulate::{OctaveResult, MAX_OCTAVES};
use triad_lab::allan::{CompensatedLanes, CompensatedSum};

/// Independent partial sums per octave: four AVX-512 vectors (eight AVX2
/// ones), so that each vector's chain of multiply-adds waits on its last
/// step only every fourth (eighth) one, and the loop runs at the rate of
/// its subtractions rather than the latency of one chain.
pub const LANES: usize = 32;

/// Most samples a block may hold: 256 terms per lane before a compensated flush.
pub const MAX_BLOCK: usize = 256 * LANES;

/// Columns whose running sums [`OctaveBlocks::push_columns`] keeps in registers at once.
const GROUP: usize = 4;

/// The octaves m = 1, 2, 4, … ≤ `history`/2 of one column, fully overlapping.
#[derive(Debug)]
pub struct OctaveBlocks {
    /// S_k for k = `first`, `first` + 1, …, `count`.
    sums: Vec<f64>,
    /// The k of `sums[0]`.
    first: u64,
    /// Sums kept before a block: 2·(the largest m), a power of two.
    history: usize,
    /// Most sums the buffer holds before it is shifted down to the history.
    limit: usize,
    /// Octaves served: m = 2^o for `lowest` ≤ o < `octaves`.
    octaves: usize,
    lowest: usize,
    offset: f64,
    running: CompensatedSum,
    count: u64,
    overlapping: [CompensatedSum; MAX_OCTAVES],
    non_overlapping: [CompensatedSum; MAX_OCTAVES],
}

impl OctaveBlocks {
    /// Octaves up to m = `history`/2 (`history` a power of two, at least 2;
    /// a longer one is clamped to the octaves [`MAX_OCTAVES`] allows) of
    /// samples from which `offset` is subtracted (the mean of the first
    /// samples, so that S grows only as the noise integrates).
    pub fn new(history: usize, offset: f64) -> Result<Self, String> {
        if history < 2 || !history.is_power_of_two() {
            return Err(format!(
                "history of {history} sums: must be a power of two, at least 2"
            ));
        }
        if !offset.is_finite() {
            return Err(format!("offset {offset} is not a finite number"));
        }
        let octaves = (history.trailing_zeros() as usize).min(MAX_OCTAVES);
        let history = 1 << octaves;
        Ok(OctaveBlocks {
            sums: vec![0.0],
            first: 0,
            history,
            // Three histories of room: the shift copies a third of a sum per sample.
            limit: history + (3 * history).max(MAX_BLOCK),
            octaves,
            lowest: 0,
            offset,
            running: CompensatedSum::ZERO,
            count: 0,
            overlapping: [CompensatedSum::ZERO; MAX_OCTAVES],
            non_overlapping: [CompensatedSum::ZERO; MAX_OCTAVES],
        })
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> u64 {
        self.count
    }

    /// The offset subtracted from every sample.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// The cumulative sums of the last block pushed, S_k for k = the
    /// samples before it + 1, …, [`Self::samples`] (what strided octaves take).
    pub fn last_block(&self, len: usize) -> &[f64] {
        &self.sums[self.sums.len() - len..]
    }

    /// Adds the samples `values` (at most [`MAX_BLOCK`] of them; more are
    /// pushed in pieces of that length).
    pub fn push(&mut self, values: impl ExactSizeIterator<Item = f64>) {
        let n = values.len();
        if n > MAX_BLOCK {
            let all: Vec<f64> = values.collect();
            for piece in all.chunks(MAX_BLOCK) {
                self.push(piece.iter().copied());
            }
            return;
        }
        // The running sum in a local: kept in registers over the block.
        let (mut running, offset) = (self.running, self.offset);
        self.push_sums(values.map(|v| {
            running.add(v - offset);
            running.value()
        }));
        self.running = running;
    }

    /// Adds column `first + i` of `rows` (rows of `width` values, at most
    /// [`MAX_BLOCK`] of them) to `blocks[i]`: what [`Self::push`] of each
    /// column does, the same operations, with the cumulative sums of all
    /// the columns made in one pass over the rows (the rows read once
    /// rather than once per column, and the columns' running sums, each a
    /// chain of dependent additions, overlapping in the core).
    pub fn push_columns(
        blocks: &mut [&mut OctaveBlocks],
        rows: &[f64],
        width: usize,
        first: usize,
    ) {
        for (g, group) in blocks.chunks_mut(GROUP).enumerate() {
            let first = first + g * GROUP;
            match group.len() {
                4 => Self::push_group::<4>(group, rows, width, first),
                3 => Self::push_group::<3>(group, rows, width, first),
                2 => Self::push_group::<2>(group, rows, width, first),
                _ => Self::push_group::<1>(group, rows, width, first),
            }
        }
    }

    /// [`Self::push_columns`] of `G` columns (at most [`GROUP`]): their
    /// running sums kept in registers over the rows as the lanes of one
    /// vector ([`CompensatedLanes`], lanes past G adding zeros), each
    /// column's cumulative sums written straight into its buffer.
    fn push_group<const G: usize>(
        group: &mut [&mut OctaveBlocks],
        rows: &[f64],
        width: usize,
        first: usize,
    ) {
        let Ok(group) = <&mut [&mut OctaveBlocks; G]>::try_from(group) else {
            return;
        };
        let n = rows.len() / width;
        debug_assert!(n <= MAX_BLOCK, "{n} rows, more than a block");
        let mut running = CompensatedLanes::<GROUP>::new(std::array::from_fn(|i| {
            group.get(i).map_or(CompensatedSum::ZERO, |b| b.running)
        }));
        let offset: [f64; G] = std::array::from_fn(|i| group[i].offset);
        let start: [u64; G] = std::array::from_fn(|i| group[i].count);
        // Room made for the block's sums, which are pushed (not written
        // over zeros: zeroing them first was a fortieth of the time).
        let mut outs = group.each_mut().map(|b| {
            b.make_room(n);
            b.sums.reserve(n);
            &mut b.sums
        });
        cumulative_sums(&mut running, &offset, rows, width, first, &mut outs);
        let running = running.sums();
        for (i, b) in group.iter_mut().enumerate() {
            b.running = running[i];
            b.count += n as u64;
            b.sum_block(start[i]);
        }
    }

    /// Adds the cumulative sums S_k of the next samples themselves (at
    /// most [`MAX_BLOCK`]): what a strided octave takes ([`StridedBlocks`]).
    fn push_sums(&mut self, sums: impl ExactSizeIterator<Item = f64>) {
        let n = sums.len();
        self.make_room(n);
        let start = self.count;
        self.sums.extend(sums);
        self.count += n as u64;
        self.sum_block(start);
    }

    /// Shifts the buffer down, keeping the history, when `n` more sums
    /// would take it past its limit.
    fn make_room(&mut self, n: usize) {
        let limit = self.limit;
        let len = self.sums.len();
        if len + n <= limit || len <= self.history {
            // Grown by doubling up to the limit, no further.
            if len + n > self.sums.capacity() {
                let want = (2 * len).clamp(len + n, limit.max(len + n));
                self.sums.reserve_exact(want - len);
            }
            return;
        }
        let drop = self.sums.len() - self.history;
        self.sums.copy_within(drop.., 0);
        self.sums.truncate(self.history);
        self.first += drop as u64;
    }

    /// Adds the terms of the samples after `start` (the block just
    /// appended) to every octave that has any: the octaves with a term at
    /// every sample of the block (2m ≤ `start` + 1, all of them once the
    /// record is past the history) in one tiled pass
    /// ([`steady_octave_sums`]), the others (a record's first samples,
    /// or a lone octave) one at a time.
    fn sum_block(&mut self, start: u64) {
        let count = self.count;
        let at = |k: u64| (k - self.first) as usize;
        let steady = self.lowest
            ..(self.lowest..self.octaves)
                .find(|&o| 2u64 << o > start + 1)
                .unwrap_or(self.octaves);
        let mut over = [0.0; MAX_OCTAVES];
        let mut non_in_lanes = [0.0; MAX_OCTAVES];
        // One octave alone (a strided one's) gains nothing from the tiles.
        let tiled = steady.len() > 1 && count > start;
        if tiled {
            let phase = ((start + 1) % LANES as u64) as usize;
            steady_octave_sums(
                &self.sums,
                (at(start + 1), at(count) + 1),
                steady.clone(),
                phase,
                (&mut over, &mut non_in_lanes),
            );
        }
        for (o, over_o) in over
            .iter_mut()
            .enumerate()
            .take(self.octaves)
            .skip(self.lowest)
        {
            let m = 1u64 << o;
            // Terms at k = 2m, …, count.
            let from = (start + 1).max(2 * m);
            if from > count {
                break;
            }
            let (j0, j1, mu) = (at(from), at(count) + 1, m as usize);
            if !(tiled && steady.contains(&o)) {
                *over_o = squared_second_differences(
                    &self.sums[j0..j1],
                    &self.sums[j0 - mu..j1 - mu],
                    &self.sums[j0 - 2 * mu..j1 - 2 * mu],
                );
            }
            self.overlapping[o].add(*over_o);
            // The non-overlapping terms: those at multiples of m (m = 1: all;
            // up to LANES, whole lanes of the tiled pass).
            let non = if m == 1 {
                *over_o
            } else if tiled && steady.contains(&o) && m <= LANES as u64 {
                non_in_lanes[o]
            } else {
                let mut non = 0.0;
                let mut k = from.next_multiple_of(m);
                while k <= count {
                    let j = at(k);
                    let s = &self.sums;
                    let d = (s[j] - s[j - mu]) - (s[j - mu] - s[j - 2 * mu]);
                    non += d * d;
                    k += m;
                }
                non
            };
            self.non_overlapping[o].add(non);
        }
    }

    /// The result at octave `o` (m = 2^o), or None when it has no term yet.
    pub fn result(&self, o: usize) -> Option<OctaveResult> {
        if o >= self.octaves || o < self.lowest {
            return None;
        }
        OctaveResult::fully_overlapping(
            1 << o,
            self.count,
            self.overlapping[o].value(),
            self.non_overlapping[o].value(),
        )
    }

    /// Every octave that has at least one term, shortest τ first.
    pub fn results(&self) -> impl Iterator<Item = OctaveResult> + '_ {
        (0..self.octaves).map_while(move |o| self.result(o))
    }
}

/// One octave m above a base M (both powers of two): the strided estimator
/// of [`StridedOctave`](triad_lab::allan::strided::StridedOctave), its terms
/// every d = m/M samples, computed as the octave M of the cumulative sums
/// taken every d samples (D_p = S_{p·d}: the term at k = p·d is
/// D_p − 2D_{p−M} + D_{p−2M}), a block at a time by [`OctaveBlocks`]; its
/// variance is that octave's over d². Memory: at most 4·M sums.
#[derive(Debug)]
pub struct StridedBlocks {
    m: u64,
    stride: u64,
    /// The octave M of the sums taken every `stride` samples, alone.
    every_stride: OctaveBlocks,
}

impl StridedBlocks {
    /// Octave `m` (a power of two above `base`, itself a power of two of at least 1).
    pub fn new(m: u64, base: u64) -> Result<Self, String> {
        if !(base.is_power_of_two() && m.is_power_of_two() && m > base) {
            return Err(format!(
                "averaging factor {m}: a strided octave needs a power of two above the base {base} (itself a power of two)"
            ));
        }
        let history = usize::try_from(2 * base).map_err(|e| e.to_string())?;
        let mut every_stride = OctaveBlocks::new(history, 0.0)?;
        every_stride.lowest = every_stride.octaves - 1;
        // One history of room: these take a sum every stride, so their
        // shifts cost little, and there are many of them.
        every_stride.limit = every_stride.history + every_stride.history.max(MAX_BLOCK);
        Ok(StridedBlocks {
            m,
            stride: m / base,
            every_stride,
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

    /// Takes the cumulative sums `sums` = S_k, k = `start` + 1, …,
    /// `start` + sums.len() (at most [`MAX_BLOCK`] of them; those at
    /// multiples of the stride are used).
    pub fn push(&mut self, start: u64, sums: &[f64]) {
        let first = (start + 1).next_multiple_of(self.stride) - start - 1;
        if let Some(from) = sums.get(first as usize..) {
            self.every_stride
                .push_sums(from.iter().step_by(self.stride as usize).copied());
        }
    }

    /// The estimates, or None without a term.
    pub fn result(&self) -> Option<OctaveResult> {
        let r = self.every_stride.result(self.every_stride.lowest)?;
        let d2 = (self.stride as f64) * (self.stride as f64);
        Some(OctaveResult {
            m: self.m,
            overlapping: r.overlapping / d2,
            non_overlapping: r.non_overlapping / d2,
            ..r
        })
    }
}

/// The cumulative sums of columns `first`, … of `rows` (rows of `width`
/// values), less their `offset`s, pushed onto `outs` (one per column, a
/// value per row), `running` carrying them on; compiled for AVX2 where the
/// CPU has it (the same operations, so the same sums, bit for bit).
fn cumulative_sums<const G: usize>(
    running: &mut CompensatedLanes<GROUP>,
    offset: &[f64; G],
    rows: &[f64],
    width: usize,
    first: usize,
    outs: &mut [&mut Vec<f64>; G],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { cumulative_sums_avx2(running, offset, rows, width, first, outs) };
    }
    cumulative_rows(running, offset, rows, width, first, outs)
}

/// [`cumulative_rows`] compiled for AVX2 (call only on a CPU with it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn cumulative_sums_avx2<const G: usize>(
    running: &mut CompensatedLanes<GROUP>,
    offset: &[f64; G],
    rows: &[f64],
    width: usize,
    first: usize,
    outs: &mut [&mut Vec<f64>; G],
) {
    cumulative_rows(running, offset, rows, width, first, outs)
}

/// The loop of [`cumulative_sums`], for the compiler to vectorise.
#[inline(always)]
fn cumulative_rows<const G: usize>(
    running: &mut CompensatedLanes<GROUP>,
    offset: &[f64; G],
    rows: &[f64],
    width: usize,
    first: usize,
    outs: &mut [&mut Vec<f64>; G],
) {
    for row in rows.chunks_exact(width) {
        let values = &row[first..first + G];
        running.add(std::array::from_fn(|i| {
            if i < G {
                values[i] - offset[i]
            } else {
                0.0
            }
        }));
        let sums = running.value();
        for i in 0..G {
            outs[i].push(sums[i]);
        }
    }
}

/// Σ ((s − b) − (b − c))² over three slices of one length, in [`LANES`]
/// partial sums (independent, so the loop vectorises), added pairwise at
/// the end. Compiled for the widest vectors the CPU has ([`vector_kind`]):
/// the same operations in the same order on each (each square added by a
/// fused multiply-add, one rounding everywhere), so the same result, bit
/// for bit.
fn squared_second_differences(s: &[f64], b: &[f64], c: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    match vector_kind() {
        // SAFETY: the CPU has the features each is compiled for (vector_kind).
        VectorKind::Avx512 => return unsafe { lane_sums_avx512(s, b, c) },
        VectorKind::Avx2 => return unsafe { lane_sums_avx2(s, b, c) },
        VectorKind::Plain => {}
    }
    lane_sums(s, b, c)
}

/// The vector instructions the loops are compiled for on this CPU.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq)]
enum VectorKind {
    /// AVX-512F and FMA: eight f64 a vector.
    Avx512,
    /// AVX2 and FMA: four.
    Avx2,
    /// Neither: the baseline (x86-64 without FMA adds a square by a call to libm's `fma`).
    Plain,
}

/// What this CPU has (the detection is cached by std).
#[cfg(target_arch = "x86_64")]
fn vector_kind() -> VectorKind {
    use std::arch::is_x86_feature_detected as has;
    if !has!("fma") {
        VectorKind::Plain
    } else if has!("avx512f") {
        VectorKind::Avx512
    } else if has!("avx2") {
        VectorKind::Avx2
    } else {
        VectorKind::Plain
    }
}

/// [`lane_sums`] compiled for AVX-512 (call only where [`vector_kind`] says so).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
fn lane_sums_avx512(s: &[f64], b: &[f64], c: &[f64]) -> f64 {
    lane_sums(s, b, c)
}

/// [`lane_sums`] compiled for AVX2 (call only where [`vector_kind`] says so).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn lane_sums_avx2(s: &[f64], b: &[f64], c: &[f64]) -> f64 {
    lane_sums(s, b, c)
}

/// Rows of [`LANES`] sums per tile of [`steady_octave_sums`]: a tile's
/// slices (4 KiB each) stay in L1 from one octave to the next.
const TILE_ROWS: usize = 128;

/// The sums of one tiled pass, by octave: of every term, and of the terms
/// at multiples of m (for m up to [`LANES`]; left as they were above).
type TiledOut<'a> = (&'a mut [f64; MAX_OCTAVES], &'a mut [f64; MAX_OCTAVES]);

/// [`squared_second_differences`] of every octave o in `octaves` over the
/// sums `sums[j0..j1]` (each with its 2m sums before it in `sums`), into
/// `out.0[o]`: one pass over the block in tiles, each tile's octaves one
/// after the other, so that the tile's own sums are read from L1 by every
/// octave and the sums m back, read by octave o, are still there when
/// octave o + 1 reads them as its 2m back (one read from L2 or memory per
/// sum and octave instead of two). Each octave's lane l sums the same terms
/// in the same order as [`lane_sums`], so the same result, bit for bit.
///
/// Lane l holds the terms at the samples k ≡ `phase` + l (mod [`LANES`]),
/// `phase` being k mod LANES at `sums[j0]`; so for m up to LANES the
/// non-overlapping terms (k a multiple of m) are whole lanes, added into
/// `out.1[o]` (the scalar loop over them was ~3 % of `triad allan`).
fn steady_octave_sums(
    sums: &[f64],
    (j0, j1): (usize, usize),
    octaves: std::ops::Range<usize>,
    phase: usize,
    out: TiledOut,
) {
    #[cfg(target_arch = "x86_64")]
    match vector_kind() {
        // SAFETY: the CPU has the features each is compiled for (vector_kind).
        VectorKind::Avx512 => return unsafe { tiled_avx512(sums, (j0, j1), octaves, phase, out) },
        VectorKind::Avx2 => return unsafe { tiled_avx2(sums, (j0, j1), octaves, phase, out) },
        VectorKind::Plain => {}
    }
    tiled_lane_sums(sums, (j0, j1), octaves, phase, out)
}

/// [`tiled_lane_sums`] compiled for AVX-512 (call only where [`vector_kind`] says so).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
fn tiled_avx512(
    sums: &[f64],
    block: (usize, usize),
    octaves: std::ops::Range<usize>,
    phase: usize,
    out: TiledOut,
) {
    tiled_lane_sums(sums, block, octaves, phase, out)
}

/// [`tiled_lane_sums`] compiled for AVX2 (call only where [`vector_kind`] says so).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn tiled_avx2(
    sums: &[f64],
    block: (usize, usize),
    octaves: std::ops::Range<usize>,
    phase: usize,
    out: TiledOut,
) {
    tiled_lane_sums(sums, block, octaves, phase, out)
}

/// The term of one second difference added to a lane: ((s − b) − (b − c))²
/// in one rounding (what every compiled form of the loops does).
#[inline(always)]
fn add_term(lane: &mut f64, s: f64, b: f64, c: f64) {
    let d = (s - b) - (b - c);
    *lane = d.mul_add(d, *lane);
}

/// The loops of [`steady_octave_sums`], in plain Rust for the compiler to
/// vectorise for the target it is compiled for.
#[inline(always)]
fn tiled_lane_sums(
    sums: &[f64],
    (j0, j1): (usize, usize),
    octaves: std::ops::Range<usize>,
    phase: usize,
    (out, non): TiledOut,
) {
    let n = j1 - j0;
    let full = n - n % LANES;
    // As many rows as the octaves reach (zeroing all MAX_OCTAVES was a
    // tenth of the kernel's time).
    let mut lanes = vec![[0.0f64; LANES]; octaves.end];
    let mut a = j0;
    while a < j0 + full {
        let b = (a + TILE_ROWS * LANES).min(j0 + full);
        for o in octaves.clone() {
            let m = 1usize << o;
            let mut acc = lanes[o];
            let (s_rows, _) = rows(&sums[a..b]);
            let (b_rows, _) = rows(&sums[a - m..b - m]);
            let (c_rows, _) = rows(&sums[a - 2 * m..b - 2 * m]);
            for ((s, b), c) in s_rows.zip(b_rows).zip(c_rows) {
                for l in 0..LANES {
                    add_term(&mut acc[l], s[l], b[l], c[l]);
                }
            }
            lanes[o] = acc;
        }
        a = b;
    }
    for o in octaves {
        let m = 1usize << o;
        let acc = &mut lanes[o];
        for (l, j) in (j0 + full..j1).enumerate() {
            add_term(&mut acc[l], sums[j], sums[j - m], sums[j - 2 * m]);
        }
        if m <= LANES {
            // The lanes l with phase + l ≡ 0 (mod m), in order.
            let first = (m - phase % m) % m;
            non[o] = acc[first..].iter().step_by(m).sum();
        }
        out[o] = pairwise(acc);
    }
}

/// The lanes added pairwise: 32 → 16 → … → 1.
#[inline(always)]
fn pairwise(lanes: &mut [f64; LANES]) -> f64 {
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for l in 0..width {
            lanes[l] += lanes[l + width];
        }
    }
    lanes[0]
}

/// `x` as rows of [`LANES`] values (as arrays: the loop over them then
/// has no bounds to check), and the values after the last full row.
#[inline(always)]
fn rows(x: &[f64]) -> (impl Iterator<Item = &[f64; LANES]>, &[f64]) {
    let rows = x.chunks_exact(LANES);
    let tail = rows.remainder();
    // A chunk of chunks_exact has LANES values: the fallback is never taken.
    (rows.map(|r| r.try_into().unwrap_or(&[0.0; LANES])), tail)
}

/// The sum of [`squared_second_differences`], in plain Rust for the
/// compiler to vectorise for the target it is compiled for.
#[inline(always)]
fn lane_sums(s: &[f64], b: &[f64], c: &[f64]) -> f64 {
    let n = s.len().min(b.len()).min(c.len());
    let (s_rows, s_tail) = rows(&s[..n]);
    let (b_rows, b_tail) = rows(&b[..n]);
    let (c_rows, c_tail) = rows(&c[..n]);
    let mut lanes = [0.0f64; LANES];
    for ((s, b), c) in s_rows.zip(b_rows).zip(c_rows) {
        for l in 0..LANES {
            add_term(&mut lanes[l], s[l], b[l], c[l]);
        }
    }
    for (l, ((s, b), c)) in s_tail.iter().zip(b_tail).zip(c_tail).enumerate() {
        add_term(&mut lanes[l], *s, *b, *c);
    }
    pairwise(&mut lanes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad_lab::allan::accumulate::OctaveAccumulator;

    fn record(n: u32) -> Vec<f64> {
        (0..n)
            .map(|i| f64::from(i.wrapping_mul(2_654_435_761) % 1000) * 1e-3 + 9.8)
            .collect()
    }

    /// Every octave's estimates and counts as the one-sample accumulator
    /// gives them, whatever the blocks' lengths (the buffer shifted many
    /// times over): the same terms, summed in another order.
    #[test]
    fn blocks_of_any_length_give_the_one_sample_accumulator_results() {
        let y = record(40_000);
        let mut one = OctaveAccumulator::new(vec![0.0; 1 << 10], 9.8).unwrap();
        for &v in &y {
            one.push(v);
        }
        let want: Vec<OctaveResult> = one.results().collect();
        assert_eq!(want.len(), 10, "m = 1 … 512");
        for lengths in [&[1usize][..], &[7, 1000, 3], &[MAX_BLOCK], &[20_000]] {
            let mut blocks = OctaveBlocks::new(1 << 10, 9.8).unwrap();
            let mut at = 0;
            for &n in lengths.iter().cycle() {
                if at == y.len() {
                    break;
                }
                let end = (at + n).min(y.len());
                blocks.push(y[at..end].iter().copied());
                at = end;
            }
            let got: Vec<OctaveResult> = blocks.results().collect();
            assert_eq!(got.len(), want.len(), "{lengths:?}");
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(
                    (g.m, g.overlapping_terms, g.non_overlapping_terms),
                    (w.m, w.overlapping_terms, w.non_overlapping_terms)
                );
                for (a, b) in [
                    (g.overlapping, w.overlapping),
                    (g.non_overlapping, w.non_overlapping),
                ] {
                    assert!((a - b).abs() <= 1e-12 * b, "m = {}: {a} against {b}", g.m);
                }
            }
            assert_eq!(blocks.samples(), y.len() as u64);
            assert!(blocks.sums.len() <= 2 * MAX_BLOCK.max(1 << 10) + 1);
        }
    }

    /// Each compiled form of the loop the CPU can run (AVX-512, AVX2) and
    /// the plain one give the same sum, bit for bit, whatever the tail.
    #[test]
    fn the_vector_loops_are_the_plain_one_bit_for_bit() {
        let y = record(1003);
        for n in [0, 5, 8, 31, 32, 33, 997, 1001] {
            let (s, b, c) = (&y[2..2 + n], &y[1..1 + n], &y[..n]);
            let plain = lane_sums(s, b, c);
            let by_definition: f64 = (0..n)
                .map(|i| ((s[i] - b[i]) - (b[i] - c[i])).powi(2))
                .sum();
            assert!(
                (plain - by_definition).abs() <= 1e-13 * by_definition,
                "{n}"
            );
            assert_eq!(
                squared_second_differences(s, b, c).to_bits(),
                plain.to_bits(),
                "{n}"
            );
            #[cfg(target_arch = "x86_64")]
            {
                use std::arch::is_x86_feature_detected as has;
                if has!("avx512f") && has!("fma") {
                    // SAFETY: the CPU has them, checked just above.
                    let wide = unsafe { lane_sums_avx512(s, b, c) };
                    assert_eq!(wide.to_bits(), plain.to_bits(), "AVX-512, {n}");
                }
                if has!("avx2") && has!("fma") {
                    // SAFETY: as above.
                    let wide = unsafe { lane_sums_avx2(s, b, c) };
                    assert_eq!(wide.to_bits(), plain.to_bits(), "AVX2, {n}");
                }
            }
        }
    }

    /// Columns pushed together give what each pushed alone gives, bit for bit.
    #[test]
    fn columns_pushed_together_are_each_pushed_alone() {
        let y = record(6 * 5000);
        let new = || OctaveBlocks::new(1 << 8, 9.8).unwrap();
        let mut alone: Vec<OctaveBlocks> = (0..6).map(|_| new()).collect();
        let mut together: Vec<OctaveBlocks> = (0..6).map(|_| new()).collect();
        for rows in y.chunks(6 * 777) {
            for (c, b) in alone.iter_mut().enumerate() {
                b.push(rows.chunks_exact(6).map(|r| r[c]));
            }
            // Five at once (a group of four and one of one), and one.
            let mut refs: Vec<&mut OctaveBlocks> = together[1..].iter_mut().collect();
            OctaveBlocks::push_columns(&mut refs, rows, 6, 1);
            OctaveBlocks::push_columns(&mut [&mut together[0]], rows, 6, 0);
        }
        for (a, t) in alone.iter().zip(&together) {
            assert_eq!(a.samples(), t.samples());
            let (a, t): (Vec<_>, Vec<_>) = (a.results().collect(), t.results().collect());
            assert_eq!(a.len(), 8);
            for (a, t) in a.iter().zip(&t) {
                assert_eq!(a.overlapping.to_bits(), t.overlapping.to_bits());
                assert_eq!(a.non_overlapping.to_bits(), t.non_overlapping.to_bits());
            }
        }
    }

    /// The tiled pass over several octaves gives each octave's sum of the
    /// one-octave loop bit for bit, whatever the block's length against
    /// the tiles and the lanes, and for m up to the lanes the sum of the
    /// terms at multiples of m (to rounding: another order).
    #[test]
    fn the_tiled_pass_is_the_one_octave_loop_bit_for_bit() {
        let sums = record(40_000);
        let j0 = 1 << 13;
        // k mod LANES at sums[j0]: every residue of the octaves up to 32 met.
        let phase = 5;
        for n in [
            0,
            1,
            7,
            8,
            9,
            TILE_ROWS * LANES,
            TILE_ROWS * LANES + 3,
            5 * 1024 + 5,
            MAX_BLOCK,
        ] {
            let (mut out, mut non) = ([f64::NAN; MAX_OCTAVES], [f64::NAN; MAX_OCTAVES]);
            steady_octave_sums(&sums, (j0, j0 + n), 2..13, phase, (&mut out, &mut non));
            for (o, &got) in out.iter().enumerate() {
                if !(2..13).contains(&o) {
                    assert!(got.is_nan() && non[o].is_nan(), "octave {o} left alone");
                    continue;
                }
                let m = 1 << o;
                let one = squared_second_differences(
                    &sums[j0..j0 + n],
                    &sums[j0 - m..j0 + n - m],
                    &sums[j0 - 2 * m..j0 + n - 2 * m],
                );
                assert_eq!(got.to_bits(), one.to_bits(), "n = {n}, m = {m}");
                if m > LANES {
                    assert!(non[o].is_nan(), "m = {m} left alone");
                    continue;
                }
                let at_multiples: f64 = (j0..j0 + n)
                    .filter(|j| (phase + j - j0) % m == 0)
                    .map(|j| ((sums[j] - sums[j - m]) - (sums[j - m] - sums[j - 2 * m])).powi(2))
                    .sum();
                assert!(
                    (non[o] - at_multiples).abs() <= 1e-13 * at_multiples,
                    "n = {n}, m = {m}: {} against {at_multiples}",
                    non[o]
                );
            }
            let mut plain = ([f64::NAN; MAX_OCTAVES], [f64::NAN; MAX_OCTAVES]);
            tiled_lane_sums(
                &sums,
                (j0, j0 + n),
                2..13,
                phase,
                (&mut plain.0, &mut plain.1),
            );
            #[cfg(target_arch = "x86_64")]
            {
                use std::arch::is_x86_feature_detected as has;
                type Tiled =
                    unsafe fn(&[f64], (usize, usize), std::ops::Range<usize>, usize, TiledOut);
                let forms: [(&str, bool, Tiled); 2] = [
                    ("AVX-512", has!("avx512f") && has!("fma"), tiled_avx512),
                    ("AVX2", has!("avx2") && has!("fma"), tiled_avx2),
                ];
                for (what, available, tiled) in forms {
                    if !available {
                        continue;
                    }
                    let mut wide = ([f64::NAN; MAX_OCTAVES], [f64::NAN; MAX_OCTAVES]);
                    // SAFETY: the CPU has the features `tiled` is compiled for, checked above.
                    unsafe {
                        tiled(
                            &sums,
                            (j0, j0 + n),
                            2..13,
                            phase,
                            (&mut wide.0, &mut wide.1),
                        )
                    };
                    for o in 2..13 {
                        for (w, p) in [(wide.0[o], plain.0[o]), (wide.1[o], plain.1[o])] {
                            assert_eq!(w.to_bits(), p.to_bits(), "{what}, n = {n}, o = {o}");
                        }
                    }
                }
            }
        }
    }

    /// A strided octave fed a block of sums at a time gives what the
    /// one-sum-at-a-time one of the lab gives: the same terms and counts.
    #[test]
    fn strided_blocks_give_the_strided_octave_results() {
        use triad_lab::allan::strided::StridedOctave;
        let y = record(9_000);
        let mut s = vec![0.0; y.len() + 1];
        triad_lab::allan::direct::cumulative_sums(&y, 9.8, &mut s);
        for m in [16u64, 64, 1024] {
            let mut lab = StridedOctave::new(m, 8, vec![0.0; 16]).unwrap();
            let mut blocks = StridedBlocks::new(m, 8).unwrap();
            for (k, &sk) in s.iter().enumerate().skip(1) {
                lab.push(k as u64, sk);
            }
            let mut start = 0;
            for block in s[1..].chunks(777) {
                blocks.push(start, block);
                start += block.len() as u64;
            }
            let (g, w) = (blocks.result().unwrap(), lab.result().unwrap());
            assert_eq!((blocks.m(), blocks.stride()), (m, m / 8));
            assert_eq!(
                (g.m, g.overlapping_terms, g.non_overlapping_terms),
                (w.m, w.overlapping_terms, w.non_overlapping_terms)
            );
            assert!((g.overlapping - w.overlapping).abs() <= 1e-12 * w.overlapping);
            assert!((g.non_overlapping - w.non_overlapping).abs() <= 1e-12 * w.non_overlapping);
        }
        assert!(StridedBlocks::new(8, 8).is_err());
        assert!(StridedBlocks::new(24, 8).is_err());
        assert!(StridedBlocks::new(1 << 20, 1 << 10)
            .unwrap()
            .result()
            .is_none());
    }

    #[test]
    fn a_short_record_has_the_octaves_it_reaches_and_bad_settings_are_refused() {
        let mut blocks = OctaveBlocks::new(1 << 20, 0.0).unwrap();
        blocks.push(record(9).into_iter());
        // 2m ≤ 9: m = 1, 2, 4.
        assert_eq!(blocks.results().count(), 3);
        assert_eq!(blocks.last_block(9).len(), 9);
        assert!(OctaveBlocks::new(3, 0.0).is_err());
        assert!(OctaveBlocks::new(0, 0.0).is_err());
        assert!(OctaveBlocks::new(4, f64::NAN).is_err());
    }
}
