//! Progress of long work on stderr: `triad sim` counts samples, `triad
//! allan`, `calib fit` and `decode` bytes read, `allan --all-tau` the τ
//! computed.
//!
//! On a terminal a one-line bar is redrawn (at most every 0.25 s); otherwise
//! (a log, a pipe) a line is written every few seconds (3, or
//! `TRIAD_PROGRESS_SECONDS`) with done/total, the rate and the time left.
//! Runs shorter than that print nothing; `--quiet` ([`silence`]) silences all.

use std::cell::Cell;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::plumbing::stdio::note;

/// Set by `--quiet`.
static QUIET: AtomicBool = AtomicBool::new(false);

/// No progress from now on (`--quiet`).
pub fn silence() {
    QUIET.store(true, Ordering::Relaxed);
}

/// Seconds between progress lines when stderr is not a terminal.
const LINE_PERIOD_S: f64 = 3.0;

/// Seconds between redraws of the bar on a terminal.
const BAR_PERIOD_S: f64 = 0.25;

/// What the progress counts.
#[derive(Clone, Copy, Debug)]
pub enum Unit {
    /// Samples written.
    Samples,
    /// Bytes read (shown in MB).
    Bytes,
    /// Averaging times computed.
    Taus,
}

/// How the progress shows.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Off,
    /// A bar redrawn in place (stderr is a terminal).
    Bar,
    /// A line every `period` seconds (stderr is a file or a pipe).
    Lines {
        period: f64,
    },
}

/// The progress of one piece of work.
pub struct Progress {
    /// 0 when unknown.
    total: u64,
    unit: Unit,
    start: Instant,
    mode: Mode,
    /// Elapsed seconds at the last line or redraw.
    last_shown: Cell<Option<f64>>,
}

impl Progress {
    /// Progress towards `total` (0: unknown). On a terminal no bar shows
    /// when `total` is known and at most `long` (a fraction of a second of
    /// work); lines show only once their period has passed anyway.
    pub fn new(total: u64, long: u64, unit: Unit) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let mode = if QUIET.load(Ordering::Relaxed) {
            Mode::Off
        } else if !terminal {
            Mode::Lines {
                period: line_period(),
            }
        } else if total == 0 || total > long {
            Mode::Bar
        } else {
            Mode::Off
        };
        Self {
            total,
            unit,
            start: Instant::now(),
            mode,
            last_shown: Cell::new(None),
        }
    }

    /// Shows the progress at `done` if it is time to.
    pub fn update(&self, done: u64) {
        if self.mode == Mode::Off || done == 0 {
            return;
        }
        let elapsed = self.start.elapsed().as_secs_f64();
        if let Some(text) = self.due(done, elapsed) {
            self.last_shown.set(Some(elapsed));
            self.show(&text);
        }
    }

    /// The text to show at `done` after `elapsed` seconds, if it is time.
    fn due(&self, done: u64, elapsed: f64) -> Option<String> {
        let since = elapsed - self.last_shown.get().unwrap_or(0.0);
        match self.mode {
            Mode::Off => None,
            Mode::Bar => (since >= BAR_PERIOD_S).then(|| self.bar(done, elapsed)),
            Mode::Lines { period } => (since >= period).then(|| self.line(done, elapsed)),
        }
    }

    fn show(&self, text: &str) {
        use std::io::Write as _;
        match self.mode {
            Mode::Bar => {
                let _ = write!(std::io::stderr(), "{text}");
            }
            _ => note!("{text}"),
        }
    }

    /// The fraction done, when the total is known.
    fn fraction(&self, done: u64) -> Option<f64> {
        (self.total > 0).then(|| (done as f64 / self.total as f64).min(1.0))
    }

    /// `done/total unit` (or `done unit` when the total is unknown).
    fn amount(&self, done: u64) -> String {
        let of = |x: u64| match self.unit {
            Unit::Bytes => format!("{}", x >> 20),
            _ => format!("{x}"),
        };
        let unit = match self.unit {
            Unit::Samples => "samples",
            Unit::Bytes => "MB",
            Unit::Taus => "τ",
        };
        match self.total {
            0 => format!("{} {unit}", of(done)),
            total => format!("{}/{} {unit}", of(done), of(total)),
        }
    }

    /// Seconds left at the current pace.
    fn eta(&self, done: u64, elapsed: f64) -> Option<f64> {
        let frac = self.fraction(done)?;
        (frac > 0.0).then(|| elapsed * (1.0 - frac) / frac)
    }

    /// The bar at `done` after `elapsed` seconds (from a carriage return on).
    fn bar(&self, done: u64, elapsed: f64) -> String {
        let width = 40;
        let frac = self.fraction(done).unwrap_or(0.0);
        let filled = (frac * width as f64) as usize;
        let eta = self
            .eta(done, elapsed)
            .map(|s| format!(", {s:.0} s left"))
            .unwrap_or_default();
        format!(
            "\r[{}{}] {:5.1} % {}{eta} ",
            "#".repeat(filled),
            " ".repeat(width - filled),
            100.0 * frac,
            self.amount(done),
        )
    }

    /// A log line: done/total, percentage, rate, time left.
    fn line(&self, done: u64, elapsed: f64) -> String {
        let per_s = if elapsed > 0.0 {
            done as f64 / elapsed
        } else {
            0.0
        };
        let rate = match self.unit {
            Unit::Bytes => format!("{:.1} MB/s", per_s / (1u64 << 20) as f64),
            Unit::Samples => format!("{per_s:.3e} samples/s"),
            Unit::Taus => format!("{per_s:.1} τ/s"),
        };
        let mut text = format!("triad: {}", self.amount(done));
        if let Some(frac) = self.fraction(done) {
            text += &format!(" ({:.1} %)", 100.0 * frac);
        }
        text += &format!(", {rate}");
        if let Some(eta) = self.eta(done, elapsed) {
            text += &format!(", {eta:.0} s left");
        }
        text
    }

    /// Ends the progress: the full bar and its newline, or a last line when
    /// lines were shown.
    pub fn finish(&self) {
        let elapsed = self.start.elapsed().as_secs_f64();
        let done = self.total;
        match (self.mode, self.last_shown.get()) {
            (Mode::Bar, Some(_)) => {
                self.show(&self.bar(done, elapsed));
                note!();
            }
            (Mode::Lines { .. }, Some(_)) => {
                note!("triad: done in {elapsed:.1} s");
            }
            _ => {}
        }
    }
}

/// `TRIAD_PROGRESS_SECONDS` when set to a number ≥ 0, else the default.
fn line_period() -> f64 {
    std::env::var("TRIAD_PROGRESS_SECONDS")
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(LINE_PERIOD_S)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(total: u64, unit: Unit) -> Progress {
        Progress {
            total,
            unit,
            start: Instant::now(),
            mode: Mode::Lines { period: 3.0 },
            last_shown: Cell::new(None),
        }
    }

    #[test]
    fn the_bar_shows_the_fraction_the_amount_and_the_time_left() {
        let bar = Progress {
            mode: Mode::Bar,
            ..lines(200, Unit::Samples)
        };
        let line = bar.bar(50, 10.0);
        assert_eq!(
            line,
            format!(
                "\r[{}{}]  25.0 % 50/200 samples, 30 s left ",
                "#".repeat(10),
                " ".repeat(30)
            )
        );
        // Past the total: full, nothing left.
        assert!(bar
            .bar(400, 5.0)
            .contains(&format!("[{}] 100.0 %", "#".repeat(40))));
    }

    #[test]
    fn a_log_line_has_done_total_rate_and_time_left() {
        let p = lines(8 << 20, Unit::Bytes);
        assert_eq!(
            p.line(2 << 20, 4.0),
            "triad: 2/8 MB (25.0 %), 0.5 MB/s, 12 s left"
        );
        let unknown = lines(0, Unit::Bytes);
        assert_eq!(unknown.line(3 << 20, 2.0), "triad: 3 MB, 1.5 MB/s");
        let s = lines(1000, Unit::Samples);
        assert_eq!(
            s.line(250, 0.5),
            "triad: 250/1000 samples (25.0 %), 5.000e2 samples/s, 2 s left"
        );
    }

    #[test]
    fn lines_come_every_period_and_not_before() {
        let p = lines(100, Unit::Taus);
        assert!(p.due(10, 1.0).is_none());
        assert!(p.due(10, 3.0).is_some());
        p.last_shown.set(Some(3.0));
        assert!(p.due(20, 5.9).is_none());
        assert!(p.due(20, 6.0).is_some());
    }

    #[test]
    fn quiet_runs_show_nothing() {
        let off = Progress {
            mode: Mode::Off,
            ..lines(100, Unit::Samples)
        };
        assert!(off.due(50, 100.0).is_none());
    }
}
