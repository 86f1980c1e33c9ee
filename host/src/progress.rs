//! A one-line progress bar on stderr, shown only for long runs when stderr
//! is a terminal (`triad sim` counts samples, `triad allan` bytes read).

use std::io::IsTerminal;
use std::time::Instant;

/// What the bar counts.
#[derive(Clone, Copy, Debug)]
pub enum Unit {
    /// Samples written.
    Samples,
    /// Bytes read (shown in MB).
    Bytes,
}

/// The bar.
pub struct Progress {
    total: u64,
    unit: Unit,
    start: Instant,
    shown: bool,
}

impl Progress {
    /// A bar towards `total`, shown when `total` exceeds `long` (the size of
    /// about a second of work) and stderr is a terminal.
    pub fn new(total: u64, long: u64, unit: Unit) -> Self {
        Self {
            total,
            unit,
            start: Instant::now(),
            shown: total > long && std::io::stderr().is_terminal(),
        }
    }

    /// Redraws the bar at `done`.
    pub fn update(&self, done: u64) {
        if !self.shown {
            return;
        }
        let frac = (done as f64 / self.total as f64).min(1.0);
        let width = 40;
        let filled = (frac * width as f64) as usize;
        let elapsed = self.start.elapsed().as_secs_f64();
        let eta = if frac > 0.0 {
            elapsed * (1.0 - frac) / frac
        } else {
            0.0
        };
        let amount = match self.unit {
            Unit::Samples => format!("{done}/{} samples", self.total),
            Unit::Bytes => format!("{} MB", done >> 20),
        };
        eprint!(
            "\r[{}{}] {:5.1} % {amount}, {eta:.0} s left ",
            "#".repeat(filled),
            " ".repeat(width - filled),
            100.0 * frac,
        );
    }

    /// Draws the full bar and ends its line.
    pub fn finish(&self) {
        if self.shown {
            self.update(self.total);
            eprintln!();
        }
    }
}
