//! What the session tells the user, and the one question it asks. Guidance
//! and the stillness meter go to stderr (stdout carries the report); on a
//! terminal the meter is one line redrawn in place, elsewhere (a log, a
//! test) only the events are written, a line each.

use std::io::{BufRead, IsTerminal, Write};

use super::coverage::Coverage;

/// Where the guidance goes.
pub struct Guide {
    terminal: bool,
    /// A meter line is on screen (to be cleared before the next line).
    meter_shown: bool,
}

impl Guide {
    /// Guidance on stderr, redrawn in place when it is a terminal.
    pub fn stderr() -> Guide {
        Guide {
            terminal: std::io::stderr().is_terminal(),
            meter_shown: false,
        }
    }

    /// A line of guidance.
    pub fn say(&mut self, text: &str) {
        let mut err = std::io::stderr().lock();
        if self.meter_shown {
            let _ = write!(err, "\r\x1b[K");
            self.meter_shown = false;
        }
        let _ = writeln!(err, "{text}");
    }

    /// The stillness meter (a terminal only).
    pub fn meter(&mut self, meter: f64, still_for: f64, needed: f64) {
        if self.terminal {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r\x1b[K{}", meter_line(meter, still_for, needed));
            let _ = err.flush();
            self.meter_shown = true;
        }
    }
}

/// "stillness [########··] still 0.6/1.0 s": the bar fills as the
/// stillness test's ratio to its limit falls to 1 (still) and below.
pub fn meter_line(meter: f64, still_for: f64, needed: f64) -> String {
    const WIDTH: usize = 10;
    let filled = if meter.is_finite() && meter > 0.0 {
        ((WIDTH as f64 / meter).round() as usize).min(WIDTH)
    } else if meter == 0.0 {
        WIDTH
    } else {
        0
    };
    let bar: String = "#".repeat(filled) + &"·".repeat(WIDTH - filled);
    if meter <= 1.0 {
        format!("stillness [{bar}] still {still_for:.1}/{needed:.1} s")
    } else {
        format!("stillness [{bar}] moving")
    }
}

/// Which way to turn the board next.
pub fn next_turn(coverage: &Coverage) -> String {
    match coverage.missing().first() {
        Some(side) => format!(
            "turn the board so that its {side} axis points up (gravity not yet seen from: {}), then hold it still",
            coverage.missing().join(", ")
        ),
        None => "turn the board to a new orientation, about another axis than the last turn \
                 (30° or more), then hold it still"
            .to_string(),
    }
}

/// Reads the answer to a yes/no question from `input`: yes only for "y"
/// or "yes" (any case); anything else, or no line at all, is no.
pub fn answer_is_yes(input: &mut impl BufRead) -> bool {
    let mut line = String::new();
    match input.read_line(&mut line) {
        Ok(_) => matches!(line.trim().to_ascii_lowercase().as_str(), "y" | "yes"),
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_meter_fills_as_the_board_settles() {
        assert_eq!(
            meter_line(f64::INFINITY, 0.0, 1.0),
            "stillness [··········] moving"
        );
        assert_eq!(meter_line(4.0, 0.0, 1.0), "stillness [###·······] moving");
        assert_eq!(
            meter_line(0.5, 0.42, 1.0),
            "stillness [##########] still 0.4/1.0 s"
        );
    }

    #[test]
    fn the_next_turn_names_the_first_missing_side_then_asks_for_new_orientations() {
        let mut c = Coverage::default();
        c.add(&[0.0, 0.0, 1.0]);
        c.add(&[1.0, 0.0, 0.0]);
        assert_eq!(
            next_turn(&c),
            "turn the board so that its −x axis points up (gravity not yet seen from: −x, +y, −y, −z), then hold it still"
        );
        for up in [
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
        ] {
            c.add(&up);
        }
        assert!(next_turn(&c).starts_with("turn the board to a new orientation"));
    }

    #[test]
    fn only_y_or_yes_is_yes() {
        for (text, yes) in [
            ("y\n", true),
            (" YES \n", true),
            ("n\n", false),
            ("", false),
            ("yep\n", false),
        ] {
            assert_eq!(answer_is_yes(&mut text.as_bytes()), yes, "{text:?}");
        }
    }
}
