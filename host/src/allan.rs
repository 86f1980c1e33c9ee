//! `triad allan`: overlapping Allan deviation of rate columns of a CSV, with
//! χ² confidence intervals, the jointly fitted noise terms of IEEE Std 952
//! (Q, N, B, K, R) in data-sheet units, and the sensor grade.
//!
//! Octave τ (the default) streams: the file is read once (one thread splits
//! and parses, another integrates), each column feeds an
//! [`OctaveAccumulator`] whose ring of cumulative sums starts at 4096 slots
//! and doubles (before it wraps) up to what the τ grid needs: 2·m_max slots,
//! m_max = 2^24 by default or from `--max-tau`, and no more than the record
//! needs (N estimated from the file's size). Memory is therefore at most
//! 8·2·m_max bytes per column (256 MiB by default) whatever the record's
//! length, and time is linear in N. `--all-tau` holds the whole record in
//! memory (8·N bytes per column) and costs O(N) per τ, O(N·m_max) in all,
//! so its largest m defaults to 2^14 (change it with `--max-tau`).
//!
//! Each sample has the mean of the first [`OFFSET_ROWS`] rows of its column
//! subtracted before it is integrated, so a mean far above the noise (1 g on
//! an accelerometer) costs no digits (see `triad_lab::allan::accumulate`).

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context};
use serde_json::json;
use triad::units;
use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_lab::allan::direct;
use triad_lab::allan::edf::{self, NoiseType, ONE_SIGMA};
use triad_lab::allan::grade::{classify_accel, classify_gyro};
use triad_lab::allan::noise_terms::{self, CurvePoint, NoiseFit, Term};

use crate::allan_plot;
use crate::progress::{Progress, Unit};

/// Arguments of `triad allan`.
#[derive(clap::Args)]
pub struct AllanArgs {
    /// Input CSV with a header (e.g. `t,ax,ay,az,gx,gy,gz,temp` as `triad sim` writes; SI units).
    pub input: PathBuf,
    /// Columns to analyse, comma-separated (default: every column whose name
    /// starts with `g` (gyro, rad/s) or `a` (accel, m/s²)).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Sample rate in Hz (default: from the `t` column, which must then be uniform).
    #[arg(long, allow_hyphen_values = true)]
    pub rate: Option<f64>,
    /// Write the table `column,tau,oadev,ci_low,ci_high,m,terms,edf,noise,adev` (SI units).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write a log-log plot of σ(τ) with confidence bars and the fitted terms (SVG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Print the fitted terms, their uncertainties and the grade as JSON.
    #[arg(long)]
    pub json: bool,
    /// Every τ = m·τ₀ (m = 1, 2, 3, … up to 2^14 or --max-tau) instead of
    /// octaves; holds the record in memory, costs N per τ.
    #[arg(long)]
    pub all_tau: bool,
    /// Longest averaging time, seconds (bounds the memory of the octave mode).
    #[arg(long, allow_hyphen_values = true)]
    pub max_tau: Option<f64>,
    /// Confidence level of the intervals (default 0.6827, one sigma).
    #[arg(long, default_value_t = ONE_SIGMA)]
    pub confidence: f64,
}

/// Rows whose mean is each column's offset.
pub const OFFSET_ROWS: usize = 4096;

/// Fewest samples analysed (three octaves).
pub const MIN_SAMPLES: u64 = 8;

/// Default largest averaging factor of the octave mode.
const DEFAULT_MAX_M: u64 = 1 << 24;

/// Default largest averaging factor of the every-τ mode.
const DEFAULT_MAX_M_ALL_TAU: u64 = 1 << 14;

/// First ring length.
const FIRST_RING: usize = 4096;

/// Relative jitter of the t column's step tolerated before t is called non-uniform.
const T_JITTER: f64 = 0.01;

/// Gyro or accelerometer: decides the units of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Rate, rad/s.
    Gyro,
    /// Specific force, m/s².
    Accel,
}

impl Kind {
    fn of(name: &str) -> Option<Kind> {
        match name.as_bytes().first() {
            Some(b'g') => Some(Kind::Gyro),
            Some(b'a') => Some(Kind::Accel),
            _ => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Gyro => "gyro",
            Kind::Accel => "accel",
        }
    }

    /// SI unit of the samples.
    pub fn si_unit(self) -> &'static str {
        match self {
            Kind::Gyro => "rad/s",
            Kind::Accel => "m/s^2",
        }
    }
}

/// One point of a column's curve.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// Averaging factor.
    pub m: u64,
    /// τ, seconds.
    pub tau: f64,
    /// Overlapping Allan variance.
    pub avar: f64,
    /// Non-overlapping Allan variance (NaN when none).
    pub avar_non_overlapping: f64,
    /// Second differences in the overlapping estimate.
    pub terms: u64,
    /// Noise type assumed for the EDF.
    pub noise: NoiseType,
    /// Equivalent degrees of freedom.
    pub edf: f64,
    /// Confidence interval of the deviation.
    pub ci: (f64, f64),
}

/// One analysed column.
pub struct ColumnResult {
    /// Its header name.
    pub name: String,
    /// Gyro or accel.
    pub kind: Kind,
    /// The curve, shortest τ first.
    pub points: Vec<Point>,
    /// The fitted noise model (None with fewer than one valid point).
    pub fit: Option<NoiseFit>,
}

/// Runs `triad allan`.
pub fn run(args: AllanArgs) -> anyhow::Result<ExitCode> {
    if !(args.confidence > 0.0 && args.confidence < 1.0) {
        bail!(
            "--confidence {}: must lie strictly between 0 and 1",
            args.confidence
        );
    }
    if let Some(r) = args.rate {
        if !(r.is_finite() && r > 0.0) {
            bail!("--rate {r}: the sample rate must be a positive number of Hz");
        }
    }
    if let Some(t) = args.max_tau {
        if !(t.is_finite() && t > 0.0) {
            bail!("--max-tau {t}: must be a positive number of seconds");
        }
    }
    let analysis = analyse(&args)?;
    if let Some(path) = &args.out {
        write_table(path, &analysis.columns)?;
    }
    if let Some(path) = &args.plot {
        allan_plot::write_svg(path, &analysis.columns)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let stdout = std::io::stdout();
    let mut w = BufWriter::new(stdout.lock());
    if args.json {
        let v = json_report(&args, &analysis);
        writeln!(w, "{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        write_summary(&mut w, &args, &analysis)?;
    }
    w.flush()?;
    Ok(ExitCode::SUCCESS)
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

/// A selected column: header name, index, kind.
struct Selected {
    name: String,
    index: usize,
    kind: Kind,
}

fn select_columns(header: &[&str], wanted: Option<&Vec<String>>) -> anyhow::Result<Vec<Selected>> {
    let list = header.join(",");
    let mut out = Vec::new();
    match wanted {
        Some(names) => {
            for name in names {
                let name = name.trim();
                let index = header
                    .iter()
                    .position(|h| *h == name)
                    .ok_or_else(|| anyhow!("unknown column \"{name}\" (the header has {list})"))?;
                let kind = Kind::of(name).ok_or_else(|| {
                    anyhow!(
                        "column \"{name}\": neither a gyro (g…) nor an accelerometer (a…) column"
                    )
                })?;
                if out.iter().any(|s: &Selected| s.index == index) {
                    bail!("column \"{name}\" is named twice in --columns");
                }
                out.push(Selected {
                    name: name.to_string(),
                    index,
                    kind,
                });
            }
        }
        None => {
            for (index, h) in header.iter().enumerate() {
                if let Some(kind) = Kind::of(h) {
                    out.push(Selected {
                        name: h.to_string(),
                        index,
                        kind,
                    });
                }
            }
            if out.is_empty() {
                bail!("no gyro (g…) or accelerometer (a…) column in the header {list}");
            }
        }
    }
    Ok(out)
}

/// Splits a CSV line and parses the cells at `indices` (ascending order of
/// `order`) into `values`. Errors name the line, the column and the cell.
struct RowParser {
    /// (column index, output slot), sorted by column index.
    wanted: Vec<(usize, usize)>,
    names: Vec<String>,
}

impl RowParser {
    fn parse(&self, line: &[u8], line_no: u64, values: &mut [f64]) -> anyhow::Result<()> {
        let mut want = self.wanted.iter().peekable();
        let mut col = 0usize;
        let mut start = 0usize;
        let bytes = line;
        let mut i = 0usize;
        loop {
            let Some(&&(target, slot)) = want.peek() else {
                return Ok(());
            };
            // Find the end of the current cell.
            while i < bytes.len() && bytes[i] != b',' {
                i += 1;
            }
            if col == target {
                let cell = &bytes[start..i];
                values[slot] = parse_cell(cell).ok_or_else(|| {
                    anyhow!(
                        "line {line_no}, column {}: \"{}\" is not a finite number",
                        self.names[slot],
                        String::from_utf8_lossy(cell).trim()
                    )
                })?;
                want.next();
            }
            if i >= bytes.len() {
                if let Some(&&(_, slot)) = want.peek() {
                    bail!(
                        "line {line_no}: {} cells, no column {}",
                        col + 1,
                        self.names[slot]
                    );
                }
                return Ok(());
            }
            i += 1;
            start = i;
            col += 1;
        }
    }
}

fn parse_cell(cell: &[u8]) -> Option<f64> {
    let s = std::str::from_utf8(cell).ok()?.trim();
    let v: f64 = s.parse().ok()?;
    v.is_finite().then_some(v)
}

/// The uniformity check of the t column.
struct TimeCheck {
    first: f64,
    last: f64,
    step: Option<f64>,
}

impl TimeCheck {
    fn new(t0: f64) -> Self {
        Self {
            first: t0,
            last: t0,
            step: None,
        }
    }

    fn next(&mut self, t: f64, line_no: u64) -> anyhow::Result<()> {
        let dt = t - self.last;
        match self.step {
            None => {
                // Also catches NaN: only a positive step passes.
                if dt.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    bail!(
                        "line {line_no}: t = {t} after {}: t must increase (non-positive sample period {dt} s)",
                        self.last
                    );
                }
                self.step = Some(dt);
            }
            Some(step) => {
                // Rounding of printed times: a few ulps of t, plus the jitter allowance.
                let tol = T_JITTER * step + 8.0 * f64::EPSILON * t.abs();
                if (dt - step).abs() > tol {
                    bail!(
                        "line {line_no}: t = {t} after {}: step {dt} s differs from the sample period {step} s by more than {} % (non-uniform t: a gap or jitter; resample or give --rate)",
                        self.last,
                        100.0 * T_JITTER
                    );
                }
            }
        }
        self.last = t;
        Ok(())
    }
}

/// Per-column streaming state.
struct ColumnState {
    acc: OctaveAccumulator<Vec<f64>>,
    all: Option<Vec<f64>>,
    ring_cap: usize,
}

impl ColumnState {
    /// Pushes one sample, growing the ring (before it wraps) up to its cap.
    fn push(&mut self, v: f64) {
        let len = self.acc.ring_len();
        if self.acc.samples() + 1 == len as u64 && len < self.ring_cap {
            // Cannot fail: a longer power of two, before the ring wraps.
            let _ = self.acc.grow(vec![0.0; 2 * len]);
        }
        self.acc.push(v);
        if let Some(all) = self.all.as_mut() {
            all.push(v);
        }
    }
}

/// The CSV rows after the header: line splitting, parsing, the t check.
struct Rows {
    name: String,
    reader: BufReader<File>,
    line: Vec<u8>,
    line_no: u64,
    parser: RowParser,
    /// Slot of t in a row, when the rate comes from t.
    t_slot: Option<usize>,
    time: Option<TimeCheck>,
    bytes: u64,
}

impl Rows {
    /// Reads the next non-empty row into `values`; false at the end.
    fn next_row(&mut self, values: &mut [f64]) -> anyhow::Result<bool> {
        loop {
            self.line.clear();
            let n = self.reader.read_until(b'\n', &mut self.line)?;
            if n == 0 {
                return Ok(false);
            }
            self.bytes += n as u64;
            self.line_no += 1;
            let trimmed = trim_line(&self.line);
            if trimmed.is_empty() {
                continue;
            }
            let name = &self.name;
            self.parser
                .parse(trimmed, self.line_no, values)
                .map_err(|e| anyhow!("{name}: {e}"))?;
            if let Some(slot) = self.t_slot {
                let t = values[slot];
                match &mut self.time {
                    None => self.time = Some(TimeCheck::new(t)),
                    Some(tc) => tc
                        .next(t, self.line_no)
                        .map_err(|e| anyhow!("{name}: {e}"))?,
                }
            }
            return Ok(true);
        }
    }
}

/// Rows per block handed from the parsing thread to the accumulating one.
const BLOCK_ROWS: usize = 8192;

/// Reads the CSV once and computes every column's curve and fit.
///
/// Two threads: one splits and parses the rows, the other integrates them
/// (on two cores the parsing and the accumulation overlap).
pub fn analyse(args: &AllanArgs) -> anyhow::Result<Analysis> {
    let name = args.input.display().to_string();
    let file = File::open(&args.input).with_context(|| format!("{name}: cannot open"))?;
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let mut line = Vec::with_capacity(256);
    let header_bytes = reader.read_until(b'\n', &mut line)?;
    if header_bytes == 0 {
        bail!("{name}: empty file (no header)");
    }
    let header_text = String::from_utf8_lossy(&line).trim().to_string();
    let header: Vec<&str> = header_text.split(',').map(str::trim).collect();
    let selected =
        select_columns(&header, args.columns.as_ref()).map_err(|e| anyhow!("{name}: {e}"))?;
    let t_index = header.iter().position(|h| *h == "t");
    let use_t = args.rate.is_none();
    if use_t && t_index.is_none() {
        bail!("{name}: no t column to take the sample rate from; give --rate HZ");
    }
    // Output slots: the selected columns, then t.
    let mut wanted: Vec<(usize, usize)> = selected
        .iter()
        .enumerate()
        .map(|(slot, s)| (s.index, slot))
        .collect();
    let mut names: Vec<String> = selected.iter().map(|s| s.name.clone()).collect();
    let t_slot = selected.len();
    if use_t {
        wanted.push((t_index.unwrap_or(0), t_slot));
        names.push("t".to_string());
    }
    wanted.sort_unstable();
    let width = names.len();
    let mut rows = Rows {
        name: name.clone(),
        reader,
        line,
        line_no: 1,
        parser: RowParser { wanted, names },
        t_slot: use_t.then_some(t_slot),
        time: None,
        bytes: header_bytes as u64,
    };

    // The first block: offsets (means), the rate from t, the record's length
    // estimated from the file's size.
    let mut values = vec![0.0; width];
    let mut first: Vec<f64> = Vec::with_capacity(OFFSET_ROWS * width);
    while first.len() < OFFSET_ROWS * width && rows.next_row(&mut values)? {
        first.extend_from_slice(&values);
    }
    let first_rows = first.len() / width;
    let provisional_rate = match (args.rate, &rows.time) {
        (Some(r), _) => r,
        (None, Some(TimeCheck { step: Some(s), .. })) => 1.0 / s,
        _ => 1.0,
    };
    let ring_cap = ring_cap(args, provisional_rate, size, rows.bytes, first_rows);
    let mut states: Vec<ColumnState> = Vec::with_capacity(selected.len());
    for c in 0..selected.len() {
        let offset = if first_rows == 0 {
            0.0
        } else {
            (0..first_rows).map(|r| first[r * width + c]).sum::<f64>() / first_rows as f64
        };
        let acc = OctaveAccumulator::new(vec![0.0; FIRST_RING.min(ring_cap)], offset)
            .map_err(|e| anyhow!("{e}"))?;
        states.push(ColumnState {
            acc,
            all: args.all_tau.then(Vec::new),
            ring_cap,
        });
    }
    let push_block = |states: &mut [ColumnState], block: &[f64]| {
        for row in block.chunks_exact(width) {
            for (st, &v) in states.iter_mut().zip(row) {
                st.push(v);
            }
        }
    };
    push_block(&mut states, &first);
    drop(first);

    // Inputs over 64 MB show the bar.
    let progress = Progress::new(size, 64 << 20, Unit::Bytes);
    let bytes_per_row = rows.bytes as f64 / first_rows.max(1) as f64;
    let (tx, rx) = std::sync::mpsc::sync_channel::<anyhow::Result<Vec<f64>>>(4);
    let rows = std::thread::scope(|scope| {
        let parser = scope.spawn(move || {
            let mut values = vec![0.0; width];
            loop {
                let mut block = Vec::with_capacity(BLOCK_ROWS * width);
                let mut result = Ok(());
                while block.len() < BLOCK_ROWS * width {
                    match rows.next_row(&mut values) {
                        Ok(true) => block.extend_from_slice(&values),
                        Ok(false) => break,
                        Err(e) => {
                            result = Err(e);
                            break;
                        }
                    }
                }
                let done = block.len() < BLOCK_ROWS * width || result.is_err();
                if !block.is_empty() && tx.send(Ok(block)).is_err() {
                    break;
                }
                if let Err(e) = result {
                    let _ = tx.send(Err(e));
                    break;
                }
                if done {
                    break;
                }
            }
            rows
        });
        let mut consumed = 0u64;
        let mut failure = None;
        for msg in rx {
            match msg {
                Ok(block) => {
                    push_block(&mut states, &block);
                    consumed += (block.len() / width) as u64;
                    if consumed % (16 * BLOCK_ROWS as u64) == 0 {
                        // Bytes done, from the rows done and the first rows' mean length.
                        progress.update((consumed as f64 * bytes_per_row) as u64);
                    }
                }
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            }
        }
        let rows = parser
            .join()
            .map_err(|_| anyhow!("{name}: the parsing thread failed"))?;
        match failure {
            Some(e) => Err(e),
            None => Ok(rows),
        }
    })?;
    progress.finish();

    let samples = states[0].acc.samples();
    if samples < MIN_SAMPLES {
        bail!("{name}: too few samples: {samples} rows; the Allan deviation needs at least {MIN_SAMPLES}");
    }
    let (rate, rate_source) = match (args.rate, &rows.time) {
        (Some(r), _) => (r, "--rate"),
        (None, Some(tc)) => {
            let span = tc.last - tc.first;
            let r = (samples - 1) as f64 / span;
            if !(r.is_finite() && r > 0.0) {
                bail!("{name}: the t column spans {span} s: no positive sample rate");
            }
            (r, "t column")
        }
        (None, None) => bail!("{name}: no rows"),
    };
    let max_m = self::max_m(args, rate);
    let mut columns = Vec::with_capacity(selected.len());
    for (sel, st) in selected.into_iter().zip(states) {
        let raw = match &st.all {
            Some(all) => every_tau(all, st.acc.offset(), rate, max_m),
            None => st
                .acc
                .results()
                .filter(|r| r.m <= max_m)
                .map(|r| {
                    (
                        r.m,
                        r.m as f64 / rate,
                        r.overlapping,
                        r.non_overlapping,
                        r.overlapping_terms,
                    )
                })
                .collect(),
        };
        let points = with_intervals(&raw, samples, args.confidence);
        let fit = fit_octaves(&points);
        columns.push(ColumnResult {
            name: sel.name,
            kind: sel.kind,
            points,
            fit,
        });
    }
    Ok(Analysis {
        samples,
        rate,
        rate_source,
        columns,
    })
}

/// The ring length cap: twice the largest m (from --max-tau or the mode's
/// default), and no longer than the record needs: the largest octave with
/// 2m ≤ N wants 2^⌊log2 N⌋ slots, N estimated from the file's size and the
/// first rows' mean length with a 1.5 margin (rows that later get much
/// shorter could cost the last octave; longer ones only memory).
fn ring_cap(args: &AllanArgs, rate: f64, size: u64, bytes_read: u64, rows_read: usize) -> usize {
    let by_grid = (2 * max_m(args, rate)).next_power_of_two();
    let by_record = if rows_read > 0 && bytes_read > 0 {
        let per_row = bytes_read as f64 / rows_read as f64;
        let estimate = (1.5 * size as f64 / per_row).max(2.0) as u64;
        1u64 << estimate.ilog2()
    } else {
        by_grid
    };
    by_grid.min(by_record).clamp(2, 1 << 40) as usize
}

fn trim_line(line: &[u8]) -> &[u8] {
    let mut end = line.len();
    while end > 0 && (line[end - 1] == b'\n' || line[end - 1] == b'\r') {
        end -= 1;
    }
    &line[..end]
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

/// (m, τ, overlapping variance, non-overlapping variance, terms).
type RawPoint = (u64, f64, f64, f64, u64);

/// Every m from 1 to min(N/2, max_m) on the record held in memory.
fn every_tau(y: &[f64], offset: f64, rate: f64, max_m: u64) -> Vec<RawPoint> {
    let mut s = vec![0.0; y.len() + 1];
    direct::cumulative_sums(y, offset, &mut s);
    let top = (y.len() as u64 / 2).min(max_m);
    (1..=top)
        .filter_map(|m| {
            let (o, n) = direct::overlapping(&s, m as usize)?;
            let a = direct::non_overlapping(&s, m as usize).map_or(f64::NAN, |x| x.0);
            Some((m, m as f64 / rate, o, a, n))
        })
        .collect()
}

/// The local log-log slope of σ² at each point (from the points nearest τ/2
/// and 2τ, one-sided at the ends), the noise type it names, the EDF (capped
/// at white FM's, see `edf_conservative`) and the interval.
fn with_intervals(raw: &[RawPoint], samples: u64, level: f64) -> Vec<Point> {
    let taus: Vec<f64> = raw.iter().map(|p| p.1).collect();
    let nearest = |target: f64| -> usize {
        let i = taus.partition_point(|&t| t < target);
        if i == 0 {
            0
        } else if i >= taus.len() {
            taus.len() - 1
        } else if (taus[i] / target).ln().abs() < (target / taus[i - 1]).ln().abs() {
            i
        } else {
            i - 1
        }
    };
    raw.iter()
        .enumerate()
        .map(|(i, &(m, tau, avar, non, terms))| {
            let (a, b) = (nearest(tau / 2.0).min(i), nearest(tau * 2.0).max(i));
            let mu = if a != b && raw[a].2 > 0.0 && raw[b].2 > 0.0 {
                (raw[b].2 / raw[a].2).ln() / (raw[b].1 / raw[a].1).ln()
            } else {
                -1.0
            };
            let noise = NoiseType::from_slope(mu);
            let nu = edf::edf_conservative(noise, samples, m);
            let ci = edf::deviation_interval(avar, nu, level);
            Point {
                m,
                tau,
                avar,
                avar_non_overlapping: non,
                terms,
                noise,
                edf: nu,
                ci,
            }
        })
        .collect()
}

/// The joint fit on the octave points (m a power of two: in every-τ mode the
/// neighbouring points are strongly correlated and would overstate the
/// information).
fn fit_octaves(points: &[Point]) -> Option<NoiseFit> {
    let curve: Vec<CurvePoint> = points
        .iter()
        .filter(|p| p.m.is_power_of_two())
        .map(|p| CurvePoint {
            tau: p.tau,
            avar: p.avar,
            edf: p.edf,
        })
        .collect();
    let mut scratch = vec![0.0; curve.len()];
    noise_terms::fit(&curve, &mut scratch).ok()
}

/// A term in data-sheet units: (value factor from SI, unit).
pub fn datasheet(kind: Kind, term: Term) -> (f64, &'static str) {
    match (kind, term) {
        (Kind::Gyro, Term::Quantisation) => (1e6, "urad"),
        (Kind::Gyro, Term::WhiteNoise) => (units::arw_si_to_deg_per_sqrt_h(1.0), "deg/sqrt(h)"),
        (Kind::Gyro, Term::BiasInstability) => (units::rad_per_s_to_deg_per_h(1.0), "deg/h"),
        (Kind::Gyro, Term::RandomWalk) => {
            (units::rrw_si_to_deg_per_h_per_sqrt_h(1.0), "deg/h/sqrt(h)")
        }
        (Kind::Gyro, Term::RateRamp) => (
            units::rad_to_deg(1.0) * units::SECONDS_PER_HOUR * units::SECONDS_PER_HOUR,
            "deg/h^2",
        ),
        (Kind::Accel, Term::Quantisation) => (1e3, "mm/s"),
        (Kind::Accel, Term::WhiteNoise) => (units::si_to_ug_per_sqrt_hz(1.0), "ug/sqrt(Hz)"),
        (Kind::Accel, Term::BiasInstability) => (units::mps2_to_ug(1.0), "ug"),
        (Kind::Accel, Term::RandomWalk) => (
            units::SECONDS_PER_HOUR * units::SQRT_SECONDS_PER_HOUR,
            "m/s/h/sqrt(h)",
        ),
        (Kind::Accel, Term::RateRamp) => (units::mps2_to_ug(1.0) * units::SECONDS_PER_HOUR, "ug/h"),
    }
}

/// The grade line of a column: (grade name, decided by).
pub fn grade_of(col: &ColumnResult) -> Option<(String, &'static str)> {
    let fit = col.fit.as_ref()?;
    let n = fit.term(Term::WhiteNoise).value;
    let b = fit.term(Term::BiasInstability).value;
    Some(match col.kind {
        Kind::Gyro => {
            let (fn_, _) = datasheet(Kind::Gyro, Term::WhiteNoise);
            let (fb, _) = datasheet(Kind::Gyro, Term::BiasInstability);
            let c = classify_gyro(n * fn_, b * fb);
            (
                c.grade
                    .map_or("below rate grade".into(), |g| g.name().into()),
                c.decided_by.name(),
            )
        }
        Kind::Accel => {
            let (fn_, _) = datasheet(Kind::Accel, Term::WhiteNoise);
            let (fb, _) = datasheet(Kind::Accel, Term::BiasInstability);
            let c = classify_accel(n * fn_, b * fb);
            (
                c.grade
                    .map_or("below automotive grade".into(), |g| g.name().into()),
                c.decided_by.name(),
            )
        }
    })
}

fn write_table(path: &Path, columns: &[ColumnResult]) -> anyhow::Result<()> {
    let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = BufWriter::new(file);
    writeln!(w, "column,tau,oadev,ci_low,ci_high,m,terms,edf,noise,adev")?;
    for col in columns {
        for p in &col.points {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{}",
                col.name,
                p.tau,
                p.avar.sqrt(),
                p.ci.0,
                p.ci.1,
                p.m,
                p.terms,
                p.edf,
                p.noise.name(),
                p.avar_non_overlapping.sqrt()
            )?;
        }
    }
    w.flush()
        .with_context(|| format!("writing {}", path.display()))
}

fn json_report(args: &AllanArgs, a: &Analysis) -> serde_json::Value {
    let columns: Vec<serde_json::Value> = a
        .columns
        .iter()
        .map(|col| {
            let mut terms = serde_json::Map::new();
            if let Some(fit) = &col.fit {
                for t in Term::ALL {
                    let (f, unit) = datasheet(col.kind, t);
                    let e = fit.term(t);
                    terms.insert(
                        t.symbol().to_string(),
                        json!({
                            "value": e.value * f,
                            "sigma": e.sigma * f,
                            "unit": unit,
                            "fitted": e.in_support,
                            "si": e.value,
                            "si_sigma": e.sigma,
                        }),
                    );
                }
                if col.kind == Kind::Accel {
                    let e = fit.term(Term::WhiteNoise);
                    let f = units::SQRT_SECONDS_PER_HOUR;
                    terms.insert(
                        "N_vrw".into(),
                        json!({"value": e.value * f, "sigma": e.sigma * f, "unit": "m/s/sqrt(h)", "fitted": e.in_support}),
                    );
                }
            }
            let grade = grade_of(col).map(|(g, d)| json!({"grade": g, "decided_by": d}));
            let curve: Vec<_> = col
                .points
                .iter()
                .map(|p| json!({"tau": p.tau, "oadev": p.avar.sqrt(), "ci_low": p.ci.0, "ci_high": p.ci.1, "edf": p.edf}))
                .collect();
            json!({
                "column": col.name,
                "kind": col.kind.name(),
                "unit": col.kind.si_unit(),
                "terms": terms,
                "grade": grade,
                "fit": col.fit.map(|f| json!({"chi2": f.chi2, "dof": f.dof})),
                "curve": curve,
            })
        })
        .collect();
    json!({
        "input": args.input.display().to_string(),
        "samples": a.samples,
        "rate_hz": a.rate,
        "rate_from": a.rate_source,
        "confidence": args.confidence,
        "tau": if args.all_tau { "every m" } else { "octave" },
        "columns": columns,
    })
}

fn write_summary(w: &mut impl Write, args: &AllanArgs, a: &Analysis) -> anyhow::Result<()> {
    writeln!(
        w,
        "{}: {} samples at {} Hz ({}), {} s; {} tau, {:.1} % confidence intervals",
        args.input.display(),
        a.samples,
        a.rate,
        a.rate_source,
        a.samples as f64 / a.rate,
        if args.all_tau { "every" } else { "octave" },
        100.0 * args.confidence
    )?;
    for col in &a.columns {
        let (first, last) = (col.points.first(), col.points.last());
        writeln!(
            w,
            "\n{} ({}, {}): tau {} .. {} s",
            col.name,
            col.kind.name(),
            col.kind.si_unit(),
            first.map_or(f64::NAN, |p| p.tau),
            last.map_or(f64::NAN, |p| p.tau)
        )?;
        let Some(fit) = &col.fit else {
            writeln!(w, "  no fit (no valid point)")?;
            continue;
        };
        for t in Term::ALL {
            let (f, unit) = datasheet(col.kind, t);
            let e = fit.term(t);
            let note = if e.in_support {
                ""
            } else {
                "  (not seen: value at 0, sigma is what it could hide)"
            };
            writeln!(
                w,
                "  {} {:<17} {:>12.4e} ± {:.2e} {unit}{note}",
                t.symbol(),
                term_name(t),
                e.value * f,
                e.sigma * f
            )?;
        }
        if let Some((g, d)) = grade_of(col) {
            writeln!(w, "  grade: {g} (decided by {d})")?;
        }
    }
    Ok(())
}

fn term_name(t: Term) -> &'static str {
    match t {
        Term::Quantisation => "quantisation",
        Term::WhiteNoise => "white noise",
        Term::BiasInstability => "bias instability",
        Term::RandomWalk => "rate random walk",
        Term::RateRamp => "rate ramp",
    }
}
