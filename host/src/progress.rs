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
        if self.shown {
            eprint!("{}", self.line(done, self.start.elapsed().as_secs_f64()));
        }
    }

    /// The bar at `done` after `elapsed` seconds (from a carriage return on).
    fn line(&self, done: u64, elapsed: f64) -> String {
        let frac = (done as f64 / self.total as f64).min(1.0);
        let width = 40;
        let filled = (frac * width as f64) as usize;
        let eta = if frac > 0.0 {
            elapsed * (1.0 - frac) / frac
        } else {
            0.0
        };
        let amount = match self.unit {
            Unit::Samples => format!("{done}/{} samples", self.total),
            Unit::Bytes => format!("{} MB", done >> 20),
        };
        format!(
            "\r[{}{}] {:5.1} % {amount}, {eta:.0} s left ",
            "#".repeat(filled),
            " ".repeat(width - filled),
            100.0 * frac,
        )
    }

    /// Draws the full bar and ends its line.
    pub fn finish(&self) {
        if self.shown {
            self.update(self.total);
            eprintln!();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bar_shows_the_fraction_the_amount_and_the_time_left() {
        let bar = Progress::new(200, 0, Unit::Samples);
        let line = bar.line(50, 10.0);
        assert_eq!(
            line,
            format!(
                "\r[{}{}]  25.0 % 50/200 samples, 30 s left ",
                "#".repeat(10),
                " ".repeat(30)
            )
        );
        let bytes = Progress::new(8 << 20, 0, Unit::Bytes);
        assert!(bytes
            .line(3 << 20, 1.0)
            .contains("]  37.5 % 3 MB, 2 s left"));
        // Past the total: full, nothing left.
        assert!(bar
            .line(400, 5.0)
            .contains(&format!("[{}] 100.0 %", "#".repeat(40))));
    }

    #[test]
    fn short_runs_show_no_bar() {
        assert!(!Progress::new(10, 100, Unit::Samples).shown);
    }
}
