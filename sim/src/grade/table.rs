//! The grade tables of ../shared/THEORY.md, "Sensor grades" (the founding
//! notes' tables), as data: every row, in the tables' own units, each cell
//! as the notes write it ("> 0.5", "1–10", "≈ 500", "stability control 2;
//! airbag 50").
//!
//! Units: the gyro rows are in THEORY's units (°/√h, °/h, %, °/s, Hz, g,
//! US$). The accelerometer table mixes units within a row (mg/√Hz and
//! µg/√Hz; mg and µg; % and ppm); each of its rows is written here in one
//! unit, the smaller (µg/√Hz, µg, ppm), the conversion being exact (1 mg =
//! 1000 µg, 1 % = 10⁴ ppm). The accelerometer table gives no cost and no
//! technology; its shock row is survival of a 1 ms shock.

/// One cell of a table, as THEORY.md writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    /// "lo–hi": both ends included.
    Range(f64, f64),
    /// "> x".
    Above(f64),
    /// "< x" (the quantity is non-negative, so 0 ≤ value < x).
    Below(f64),
    /// "≈ x": read as within a factor [`ABOUT_FACTOR`] of x.
    About(f64),
    /// A bare order of magnitude ("10³ g"): read as [`Cell::About`].
    Order(f64),
    /// Figures per application ("stability control 0.5; airbag 5"): the
    /// span from the least to the greatest.
    Uses(&'static [(&'static str, f64)]),
}

/// How far from x a value "≈ x" may be: a factor of 2 either way. The notes
/// give no tolerance; a factor of two keeps "≈ 100 Hz" apart from "≈ 500 Hz".
pub const ABOUT_FACTOR: f64 = 2.0;

impl Cell {
    /// The interval the cell stands for: (low, high, high included).
    pub fn interval(&self) -> (f64, f64, bool) {
        match *self {
            Cell::Range(lo, hi) => (lo, hi, true),
            Cell::Above(x) => (x, f64::INFINITY, false),
            Cell::Below(x) => (0.0, x, false),
            Cell::About(x) | Cell::Order(x) => (x / ABOUT_FACTOR, x * ABOUT_FACTOR, true),
            Cell::Uses(uses) => {
                let lo = uses.iter().map(|u| u.1).fold(f64::INFINITY, f64::min);
                let hi = uses.iter().map(|u| u.1).fold(f64::NEG_INFINITY, f64::max);
                (lo, hi, true)
            }
        }
    }

    /// True when `x` lies in the cell ("> x" excludes x; "< x" excludes x).
    pub fn holds(&self, x: f64) -> bool {
        let (lo, hi, hi_in) = self.interval();
        let above_lo = match self {
            Cell::Above(_) => x > lo,
            _ => x >= lo,
        };
        above_lo && (x < hi || (hi_in && x == hi))
    }

    /// True when every value of the cell is greater than `x`.
    pub fn above(&self, x: f64) -> bool {
        let (lo, _, _) = self.interval();
        match self {
            Cell::Above(_) => x <= lo,
            _ => x < lo,
        }
    }

    /// True when every value of the cell is less than `x`.
    pub fn below(&self, x: f64) -> bool {
        let (_, hi, hi_in) = self.interval();
        x > hi || (!hi_in && x == hi)
    }
}

impl core::fmt::Display for Cell {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Cell::Range(lo, hi) => write!(f, "{lo}–{hi}"),
            Cell::Above(x) => write!(f, "> {x}"),
            Cell::Below(x) => write!(f, "< {x}"),
            Cell::About(x) => write!(f, "≈ {x}"),
            Cell::Order(x) => write!(f, "{x}"),
            Cell::Uses(uses) => {
                for (i, (what, x)) in uses.iter().enumerate() {
                    let sep = if i > 0 { "; " } else { "" };
                    write!(f, "{sep}{what} {x}")?;
                }
                Ok(())
            }
        }
    }
}

/// A parameter of the tables (a row).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// White noise: angle random walk (gyros), noise density (accelerometers).
    Noise,
    /// Bias instability (drift).
    BiasInstability,
    /// Scale-factor instability.
    ScaleFactorInstability,
    /// Measurement range.
    Range,
    /// Bandwidth.
    Bandwidth,
    /// Shock survival.
    Shock,
    /// Cost of an IMU of the grade.
    Cost,
}

impl Parameter {
    /// The name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Noise => "white noise",
            Parameter::BiasInstability => "bias instability",
            Parameter::ScaleFactorInstability => "scale-factor instability",
            Parameter::Range => "measurement range",
            Parameter::Bandwidth => "bandwidth",
            Parameter::Shock => "shock survival",
            Parameter::Cost => "cost",
        }
    }

    /// True for the error parameters: a lower value is a better sensor, and
    /// the grades are ordered by them. Range, bandwidth, shock and cost
    /// describe a grade but do not rank sensors.
    pub fn ranks(self) -> bool {
        matches!(
            self,
            Parameter::Noise | Parameter::BiasInstability | Parameter::ScaleFactorInstability
        )
    }
}

/// One row: a parameter, its unit and a cell per grade (worst grade first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// The parameter.
    pub parameter: Parameter,
    /// Its unit (ASCII, as reports print units).
    pub unit: &'static str,
    /// A cell per grade, in the table's grade order (worst first).
    pub cells: &'static [Cell],
}

/// A grade table: its grades (worst first), the technology typical of each
/// where the notes give it, and its rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Table {
    /// What the table is of ("gyro", "accelerometer").
    pub name: &'static str,
    /// The grades, worst first.
    pub grades: &'static [&'static str],
    /// The technology typical of each grade (the gyro table's headings).
    pub technology: Option<&'static [&'static str]>,
    /// The rows.
    pub rows: &'static [Row],
}

impl Table {
    /// The row of `parameter`, if the table has one.
    pub fn row(&self, parameter: Parameter) -> Option<&'static Row> {
        self.rows.iter().find(|r| r.parameter == parameter)
    }

    /// The cell of `parameter` for grade index `grade`.
    pub fn cell(&self, parameter: Parameter, grade: usize) -> Option<Cell> {
        self.row(parameter)?.cells.get(grade).copied()
    }
}

use Cell::{About, Above, Below, Order, Range};

/// The gyro table (THEORY.md, "Sensor grades", "Gyros").
pub const GYRO_TABLE: Table = Table {
    name: "gyro",
    grades: &["rate grade", "tactical", "aviation", "navigation"],
    technology: Some(&["MEMS", "MEMS, FOG", "RLG, FOG", "RLG, FOG?"]),
    rows: &[
        Row {
            parameter: Parameter::Noise,
            unit: "deg/sqrt(h)",
            cells: &[Above(0.5), Range(0.05, 0.5), Below(0.05), Below(0.001)],
        },
        Row {
            parameter: Parameter::BiasInstability,
            unit: "deg/h",
            cells: &[Above(10.0), Range(1.0, 10.0), Below(0.1), Below(0.01)],
        },
        Row {
            parameter: Parameter::ScaleFactorInstability,
            unit: "%",
            cells: &[Range(0.1, 1.0), Range(0.01, 0.1), Below(0.01), Below(0.001)],
        },
        Row {
            parameter: Parameter::Range,
            unit: "deg/s",
            cells: &[
                Range(50.0, 1000.0),
                Above(500.0),
                Range(50.0, 300.0),
                Above(400.0),
            ],
        },
        Row {
            parameter: Parameter::Bandwidth,
            unit: "Hz",
            cells: &[Above(70.0), About(500.0), About(100.0), Range(100.0, 500.0)],
        },
        Row {
            parameter: Parameter::Shock,
            unit: "g",
            cells: &[Order(1e3), Range(1e3, 1e4), Order(1e3), Order(1e3)],
        },
        Row {
            parameter: Parameter::Cost,
            unit: "US$",
            cells: &[
                Range(500.0, 5e3),
                Range(5e3, 20e3),
                Range(20e3, 50e3),
                Range(50e3, 100e3),
            ],
        },
    ],
};

/// The accelerometer table (THEORY.md, "Sensor grades", "Accelerometers").
pub const ACCEL_TABLE: Table = Table {
    name: "accelerometer",
    grades: &["automotive", "tactical", "navigation"],
    technology: None,
    rows: &[
        Row {
            parameter: Parameter::Noise,
            unit: "ug/sqrt(Hz)",
            cells: &[
                Cell::Uses(&[("stability control", 500.0), ("airbag", 5000.0)]),
                Range(50.0, 500.0),
                Below(10.0),
            ],
        },
        Row {
            parameter: Parameter::BiasInstability,
            unit: "ug",
            cells: &[Range(10e3, 100e3), Range(200.0, 1000.0), Range(10.0, 100.0)],
        },
        Row {
            parameter: Parameter::ScaleFactorInstability,
            unit: "ppm",
            cells: &[Above(10e3), Range(100.0, 1000.0), Below(100.0)],
        },
        Row {
            parameter: Parameter::Range,
            unit: "g",
            cells: &[
                Cell::Uses(&[("stability control", 2.0), ("airbag", 50.0)]),
                Above(50.0),
                Range(2.0, 50.0),
            ],
        },
        Row {
            parameter: Parameter::Bandwidth,
            unit: "Hz",
            cells: &[Range(0.0, 400.0), Range(50.0, 300.0), Range(50.0, 300.0)],
        },
        Row {
            parameter: Parameter::Shock,
            unit: "g",
            cells: &[Above(2000.0), Below(200.0), Above(10.0)],
        },
    ],
};

/// The figures THEORY.md ("Optical gyros") gives for a technology, beside
/// the grade tables: the fixed bias and scale-factor error a calibration
/// removes (their instability is the grade tables' row), and for a ring
/// laser the angle of a fringe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpticalFigures {
    /// The technology ("RLG", "FOG").
    pub technology: &'static str,
    /// Bias, °/h.
    pub bias_deg_per_h: Cell,
    /// Scale-factor error, ppm.
    pub scale_factor_error_ppm: Cell,
    /// Angle per fringe counted, arc-seconds (ring lasers).
    pub fringe_arcsec: Option<Cell>,
}

/// The ring laser gyro: bias ≈ 0.001 °/h, scale-factor error 1–10 ppm,
/// 2–5 arc-seconds per fringe.
pub const RLG_FIGURES: OpticalFigures = OpticalFigures {
    technology: "RLG",
    bias_deg_per_h: About(0.001),
    scale_factor_error_ppm: Range(1.0, 10.0),
    fringe_arcsec: Some(Range(2.0, 5.0)),
};

/// The fibre-optic gyro: bias 0.5–50 °/h, scale-factor error 500–5000 ppm.
pub const FOG_FIGURES: OpticalFigures = OpticalFigures {
    technology: "FOG",
    bias_deg_per_h: Range(0.5, 50.0),
    scale_factor_error_ppm: Range(500.0, 5000.0),
    fringe_arcsec: None,
};
