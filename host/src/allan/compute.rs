//! Streaming the Allan deviation: the file read once, one thread splitting
//! and parsing rows in blocks while the others integrate them, the columns
//! shared among the cores ([`parallel`](super::parallel)), each column into
//! its [`ColumnState`]: [`OctaveBlocks`] (fully overlapping octaves up to
//! m = [`BASE`], a block at a time, over a buffer of at most 8·BASE sums)
//! and, above, [`StridedBlocks`] (terms every m/BASE samples, over the sums
//! taken every m/BASE samples, at most 4·BASE of them each); then each
//! column's curve and fit. Memory per column is therefore at most 64·BASE
//! bytes (8 MiB) for the octaves up to BASE and 4 MiB per octave above it
//! up to the τ grid's end (36 MiB in all at the default m = 2^24), whatever
//! the record's length.

use std::sync::mpsc::SyncSender;

use anyhow::anyhow;
use triad::model::Triad;
use triad_lab::allan::noise_terms::NoiseFit;
use triad_lab::allan::strided::BASE;

use super::columns::{Layout, Selected};
use super::curve::{self, Point};
use super::fit::{fit_octaves, CovarianceCache, NoFit};
use super::mcap_rows::{self, McapRows};
use super::octave_blocks::{OctaveBlocks, StridedBlocks};
use super::parallel;
use super::record_rows::{self, RecordRows};
use super::rows::{self, RowSource, Rows};
use super::time;
use super::AllanArgs;
use crate::plumbing::progress::{Progress, Unit};

/// Rows whose mean is each column's offset.
pub const OFFSET_ROWS: usize = 4096;

/// Fewest samples analysed (three octaves).
pub const MIN_SAMPLES: u64 = 8;

/// Default largest averaging factor of the octave mode.
const DEFAULT_MAX_M: u64 = 1 << 24;

/// Default largest averaging factor of the every-τ mode.
const DEFAULT_MAX_M_ALL_TAU: u64 = 1 << 14;

/// Rows per block handed from the parsing thread to the accumulating ones
/// (as many as [`OctaveBlocks`] sums plainly before a compensated flush).
pub(super) const BLOCK_ROWS: usize = super::octave_blocks::MAX_BLOCK;

/// One analysed column.
pub struct ColumnResult {
    /// Its header name.
    pub name: String,
    /// Gyro or accel.
    pub triad: Triad,
    /// The curve, shortest τ first.
    pub points: Vec<Point>,
    /// The fitted noise model, or why there is none.
    pub fit: Result<NoiseFit, NoFit>,
}

/// Everything the outputs need.
pub struct Analysis {
    /// Samples per column.
    pub samples: u64,
    /// Sample rate, Hz.
    pub rate: f64,
    /// Where the rate came from.
    pub rate_source: &'static str,
    /// Per column.
    pub columns: Vec<ColumnResult>,
}

/// Per-column streaming state.
pub(super) struct ColumnState {
    pub(super) acc: OctaveBlocks,
    /// The octaves above BASE, shortest first (empty when the grid stops below).
    pub(super) above: Vec<StridedBlocks>,
    all: Option<Vec<f64>>,
}

impl ColumnState {
    /// A column whose samples have mean ≈ `offset`, for octaves up to
    /// `max_m` (`all_tau`: the record kept for every τ as well).
    fn new(offset: f64, max_m: u64, all_tau: bool) -> anyhow::Result<Self> {
        let acc = OctaveBlocks::new(history(max_m), offset).map_err(|e| anyhow!("{e}"))?;
        // Every τ holds the record: no octave strided there.
        let top = if all_tau { BASE } else { max_m.max(1) };
        let above = (BASE.ilog2() + 1..=top.ilog2())
            .map(|o| StridedBlocks::new(1 << o, BASE))
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow!("{e}"))?;
        Ok(ColumnState {
            acc,
            above,
            all: all_tau.then(Vec::new),
        })
    }
}

/// Pushes column `first + i` of a block of rows of `width` values into
/// `states[i]`: the octaves up to BASE of all of them a block at a time
/// ([`OctaveBlocks::push_columns`]), then each column's strided octaves at
/// the multiples of their strides within the block.
pub(super) fn push_columns(states: &mut [ColumnState], block: &[f64], width: usize, first: usize) {
    for piece in block.chunks(BLOCK_ROWS * width) {
        let start: Vec<u64> = states.iter().map(|s| s.acc.samples()).collect();
        let mut accs: Vec<&mut OctaveBlocks> = states.iter_mut().map(|s| &mut s.acc).collect();
        OctaveBlocks::push_columns(&mut accs, piece, width, first);
        for (i, (state, start)) in states.iter_mut().zip(start).enumerate() {
            let n = state.acc.samples() - start;
            let sums = state.acc.last_block(n as usize);
            for o in state.above.iter_mut() {
                o.push(start, sums);
            }
            if let Some(all) = state.all.as_mut() {
                all.extend(piece.chunks_exact(width).map(|row| row[first + i]));
            }
        }
    }
}

/// Reads the record once and computes every column's curve and fit: an
/// MCAP bag's IMU topic from rows made as its chunks are decoded
/// ([`mcap_rows`](super::mcap_rows)), a recording in another format from
/// its reader's samples ([`record_rows`](super::record_rows)), a CSV from
/// its lines.
pub fn analyse(args: &AllanArgs) -> anyhow::Result<Analysis> {
    if let Some(opened) = mcap_rows::open(&args.input)? {
        let name = opened.name.clone();
        let header = opened.header.clone();
        return analyse_rows(args, &header, &name, 0, |layout| {
            McapRows::new(opened, layout)
        });
    }
    if let Some(opened) = record_rows::open(&args.input)? {
        let name = opened.name.clone();
        let header = opened.header.clone();
        return analyse_rows(args, &header, &name, 0, |layout| {
            RecordRows::new(opened, layout)
        });
    }
    let opened = rows::open(&args.input, &crate::plumbing::input::name(&args.input))?;
    let name = opened.name.clone();
    let (header, size) = (opened.header.clone(), opened.size);
    analyse_rows(args, &header, &name, size, |layout| {
        Rows::new(opened, layout, &name)
    })
}

/// The analysis of the rows `rows_of` gives for the layout of `header`
/// (`name` in messages; `size` bytes, 0 when unknown).
///
/// One thread reads (splits and parses the CSV, or runs the recording's
/// reader), the others integrate the rows, the columns shared among them.
fn analyse_rows<R: RowSource>(
    args: &AllanArgs,
    header: &str,
    name: &str,
    size: u64,
    rows_of: impl FnOnce(&Layout) -> R,
) -> anyhow::Result<Analysis> {
    let layout = Layout::new(header, args.columns.as_deref(), args.rate.is_none())
        .map_err(|e| anyhow!("{name}: {e}"))?;
    let mut rows = rows_of(&layout);
    let width = layout.width();
    let first = first_block(&mut rows, width)?;
    let first_rows = first.len() / width;
    let mut states = column_states(args, &rows, &first, width, layout.selected.len())?;
    push_columns(&mut states, &first, width, 0);
    drop(first);
    // Progress in bytes where they are counted (a CSV), else in samples.
    let progress = match rows.bytes() {
        0 => (Progress::new(0, 0, Unit::Samples), 1.0),
        bytes => (
            Progress::new(size, 64 << 20, Unit::Bytes),
            bytes as f64 / first_rows.max(1) as f64,
        ),
    };
    let rows = stream(rows, &mut states, width, progress, name)?;
    let samples = states[0].acc.samples();
    if samples < MIN_SAMPLES {
        anyhow::bail!("{name}: too few samples: {samples} rows; the Allan deviation needs at least {MIN_SAMPLES}");
    }
    let (rate, rate_source) = time::sample_rate(args.rate, rows.time(), samples, name)?;
    let columns = results(args, layout.selected, states, rate, samples)
        .map_err(|e| anyhow!("{name}: {e}"))?;
    Ok(Analysis {
        samples,
        rate,
        rate_source,
        columns,
    })
}

/// The first [`OFFSET_ROWS`] rows, `width` values each: they give the
/// offsets (means) and the rate from t.
fn first_block(rows: &mut impl RowSource, width: usize) -> anyhow::Result<Vec<f64>> {
    let mut values = vec![0.0; width];
    let mut first: Vec<f64> = Vec::with_capacity(OFFSET_ROWS * width);
    while first.len() < OFFSET_ROWS * width && rows.next_row(&mut values)? {
        first.extend_from_slice(&values);
    }
    Ok(first)
}

/// One accumulator per column, its offset the column's mean over `first`.
fn column_states(
    args: &AllanArgs,
    rows: &impl RowSource,
    first: &[f64],
    width: usize,
    columns: usize,
) -> anyhow::Result<Vec<ColumnState>> {
    let first_rows = first.len() / width;
    let max_m = max_m(args, time::provisional_rate(args.rate, rows.time()));
    (0..columns)
        .map(|c| {
            let offset = if first_rows == 0 {
                0.0
            } else {
                (0..first_rows).map(|r| first[r * width + c]).sum::<f64>() / first_rows as f64
            };
            ColumnState::new(offset, max_m, args.all_tau)
        })
        .collect()
}

/// The rest of the rows: read in blocks by a second thread (or by the
/// threads of a source that reads ahead), integrated by the others
/// ([`parallel::accumulate`]); `progress` shows the rows done times its
/// scale (bytes per row, or 1). Returns the rows (their t check) once the
/// record is read.
fn stream<R: RowSource>(
    mut rows: R,
    states: &mut [ColumnState],
    width: usize,
    (progress, scale): (Progress, f64),
    name: &str,
) -> anyhow::Result<R> {
    let report = |consumed| progress.update((consumed as f64 * scale) as u64);
    if R::READS_AHEAD {
        let failure = parallel::accumulate(|| rows.next_block().transpose(), states, width, report);
        progress.finish();
        return match failure {
            Some(e) => Err(e),
            None => Ok(rows),
        };
    }
    let (tx, rx) = std::sync::mpsc::sync_channel::<anyhow::Result<Vec<f64>>>(4);
    let rows = std::thread::scope(|scope| {
        let parser = scope.spawn(move || parse_blocks(rows, width, tx));
        let failure = parallel::accumulate(|| rx.recv().ok(), states, width, report);
        let rows = parser
            .join()
            .map_err(|_| anyhow!("{name}: the reading thread failed"))?;
        match failure {
            Some(e) => Err(e),
            None => Ok(rows),
        }
    })?;
    progress.finish();
    Ok(rows)
}

/// The parsing thread: blocks of [`BLOCK_ROWS`] rows sent on `tx`, then the
/// first error if any; returns the rows when done.
fn parse_blocks<R: RowSource>(
    mut rows: R,
    width: usize,
    tx: SyncSender<anyhow::Result<Vec<f64>>>,
) -> R {
    let mut values = vec![0.0; width];
    loop {
        let mut block = Vec::with_capacity(BLOCK_ROWS * width);
        let result = rows.next_rows(&mut block, &mut values, BLOCK_ROWS);
        let more = matches!(result, Ok(true));
        if !block.is_empty() && tx.send(Ok(block)).is_err() {
            break;
        }
        if let Err(e) = result {
            let _ = tx.send(Err(e));
            break;
        }
        if !more {
            break;
        }
    }
    rows
}

/// Each column's curve (octaves or every τ, up to the largest m) and fit,
/// the columns shared among the cores (each independent of the others but
/// for the covariance of the fit, made once); an estimate that is not
/// finite (values so large that their squares overflow) is an error naming
/// the column and τ (the first such column's).
fn results(
    args: &AllanArgs,
    selected: Vec<Selected>,
    states: Vec<ColumnState>,
    rate: f64,
    samples: u64,
) -> anyhow::Result<Vec<ColumnResult>> {
    let max_m = max_m(args, rate);
    let cache = CovarianceCache::default();
    let column = |(sel, st): (Selected, ColumnState)| -> anyhow::Result<ColumnResult> {
        let raw = match &st.all {
            Some(all) => curve::every_tau(all, st.acc.offset(), rate, max_m),
            None => curve::octaves(&st.acc, &st.above, rate, max_m),
        };
        if let Some(p) = raw.iter().find(|p| !p.avar.is_finite()) {
            anyhow::bail!(
                "column {}: the Allan variance at tau {:e} s is {} (the values are too large to square and sum)",
                sel.name,
                p.tau,
                p.avar
            );
        }
        let points = curve::with_intervals(&raw, samples, args.confidence);
        let fit = fit_octaves(&points, st.acc.offset(), samples, rate, &cache);
        Ok(ColumnResult {
            name: sel.name,
            triad: sel.triad,
            points,
            fit,
        })
    };
    let mut columns: Vec<_> = selected.into_iter().zip(states).collect();
    let per_thread = columns
        .len()
        .div_ceil(parallel::threads(columns.len()))
        .max(1);
    let mut groups = Vec::new();
    while columns.len() > per_thread {
        let rest = columns.split_off(per_thread);
        groups.push(std::mem::replace(&mut columns, rest));
    }
    groups.push(columns);
    let mine = groups.remove(0);
    let done: Vec<Vec<anyhow::Result<ColumnResult>>> = std::thread::scope(|scope| {
        let column = &column;
        let others: Vec<_> = groups
            .into_iter()
            .map(|group| scope.spawn(move || group.into_iter().map(column).collect()))
            .collect();
        let mut done = vec![mine.into_iter().map(column).collect()];
        for other in others {
            done.push(
                other
                    .join()
                    .unwrap_or_else(|_| vec![Err(anyhow!("a thread analysing columns failed"))]),
            );
        }
        done
    });
    done.into_iter().flatten().collect()
}

/// The sums kept before a block: twice the largest m (from --max-tau or
/// the mode's default), and no more than the fully overlapping octaves need
/// (2·BASE: the octaves above are strided). The buffer grows only as the
/// record reaches its length, so a short record keeps a short one.
fn history(max_m: u64) -> usize {
    (2 * max_m).next_power_of_two().clamp(2, 2 * BASE) as usize
}

/// The largest averaging factor: from --max-tau, else the mode's default.
fn max_m(args: &AllanArgs, rate: f64) -> u64 {
    let default = if args.all_tau {
        DEFAULT_MAX_M_ALL_TAU
    } else {
        DEFAULT_MAX_M
    };
    match args.max_tau {
        Some(t) => ((t * rate).floor() as u64).clamp(1, 1 << 40),
        None => default,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::tests::args;

    #[test]
    fn the_largest_m_comes_from_max_tau_or_the_mode() {
        let mut a = args("x.csv");
        assert_eq!(max_m(&a, 100.0), 1 << 24);
        a.all_tau = true;
        assert_eq!(max_m(&a, 100.0), 1 << 14);
        a.max_tau = Some(2.5);
        assert_eq!(max_m(&a, 100.0), 250);
        a.max_tau = Some(1e-9);
        assert_eq!(max_m(&a, 100.0), 1);
    }

    #[test]
    fn the_history_is_no_longer_than_the_grid_or_the_base_needs() {
        // The default grid: the base's 2^18 sums, the octaves above strided.
        assert_eq!(history(1 << 24), 2 * BASE as usize);
        // A short --max-tau bounds it by the grid: 2·500 → 1024.
        assert_eq!(history(500), 1024);
        assert_eq!(history(0), 2);
        let st = ColumnState::new(0.0, 1 << 20, false).unwrap();
        let m: Vec<u64> = st.above.iter().map(|o| o.m()).collect();
        assert_eq!(m, [1 << 18, 1 << 19, 1 << 20]);
        assert!(ColumnState::new(0.0, 1 << 20, true)
            .unwrap()
            .above
            .is_empty());
        assert!(ColumnState::new(0.0, BASE, false).unwrap().above.is_empty());
    }

    /// A column pushed a block at a time (blocks of rows of two columns)
    /// gives what the lab's one-sample accumulator and strided octave fed
    /// at every even k give, the strided octaves' terms included (a record
    /// past 4·BASE samples, so that m = 2·BASE has some).
    #[test]
    fn a_pushed_column_gives_the_one_sample_results_strided_octaves_included() {
        use triad_lab::allan::accumulate::OctaveAccumulator;
        use triad_lab::allan::strided::StridedOctave;
        let n = 4 * BASE as usize + 12_345;
        let y = |i: usize| ((i as u32).wrapping_mul(2_654_435_761) % 1000) as f64 * 1e-3;
        let mut st = ColumnState::new(0.5, 2 * BASE, false).unwrap();
        let mut one = OctaveAccumulator::new(vec![0.0; 2 * BASE as usize], 0.5).unwrap();
        let mut above: Vec<StridedOctave<Vec<f64>>> = [2 * BASE]
            .iter()
            .map(|&m| StridedOctave::new(m, BASE, vec![0.0; 2 * BASE as usize]).unwrap())
            .collect();
        let rows: Vec<f64> = (0..n).flat_map(|i| [-1.0, y(i)]).collect();
        for block in rows.chunks(2 * 5000) {
            push_columns(std::slice::from_mut(&mut st), block, 2, 1);
        }
        for i in 0..n {
            one.push(y(i));
            let k = one.samples();
            if k.is_multiple_of(2) {
                for o in above.iter_mut() {
                    o.push(k, one.cumulative());
                }
            }
        }
        let got = curve::octaves(&st.acc, &st.above, 1.0, 2 * BASE);
        let want_full = one.results().map(|r| (r, 1));
        let want_strided = above.iter().map(|o| (o.result().unwrap(), o.stride()));
        let want: Vec<_> = want_full.chain(want_strided).collect();
        assert_eq!(got.len(), 19, "m = 1 … 2^18");
        assert_eq!(got.len(), want.len());
        for (g, (w, stride)) in got.iter().zip(want) {
            assert_eq!((g.m, g.terms, g.stride), (w.m, w.overlapping_terms, stride));
            assert!(
                (g.avar - w.overlapping).abs() <= 1e-12 * w.overlapping,
                "m = {}",
                g.m
            );
            let (a, b) = (g.avar_non_overlapping, w.non_overlapping);
            assert!((a - b).abs() <= 1e-12 * b, "m = {}", g.m);
        }
        assert_eq!(st.acc.samples(), n as u64);
    }

    #[test]
    fn every_tau_keeps_the_column() {
        let mut st = ColumnState::new(0.0, 16, true).unwrap();
        let rows: Vec<f64> = (0..40).map(|i| i as f64).collect();
        push_columns(std::slice::from_mut(&mut st), &rows, 1, 0);
        assert_eq!(st.acc.samples(), 40);
        assert_eq!(st.all.as_deref(), Some(&rows[..]));
    }
}
