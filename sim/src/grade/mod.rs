//! Sensor grades: the tables of ../shared/THEORY.md ("Sensor grades") as
//! data ([`table`]), and presets, one sensor written down inside each grade's
//! row ([`preset`]). A test checks every preset against its row (the table is
//! data kept apart from the presets); `triad_lab::allan::grade` classifies a
//! measured sensor by the same tables.

pub mod preset;
pub mod table;

pub use preset::{AccelPreset, GyroPreset, Optics, Technology};
pub use table::{
    Cell, OpticalFigures, Parameter, Row, Table, ACCEL_TABLE, FOG_FIGURES, GYRO_TABLE, RLG_FIGURES,
};

/// Gyro grades, worst first (the columns of [`GYRO_TABLE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum GyroGrade {
    /// Rate grade (MEMS).
    RateGrade,
    /// Tactical grade (MEMS, FOG).
    Tactical,
    /// Aviation grade (RLG, FOG).
    Aviation,
    /// Navigation grade (RLG, FOG?).
    Navigation,
}

/// Accelerometer grades, worst first (the columns of [`ACCEL_TABLE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum AccelGrade {
    /// Low / automotive grade.
    Automotive,
    /// Tactical grade.
    Tactical,
    /// Navigation grade.
    Navigation,
}

/// A grade of one of the tables: its column there.
pub trait Grade: Copy {
    /// The table whose column it is.
    const TABLE: &'static Table;

    /// The grade's column in [`Self::TABLE`].
    fn index(self) -> usize;

    /// The grade's name in the table ("rate grade", "tactical", ...).
    fn name(self) -> &'static str {
        Self::TABLE.grades[self.index()]
    }

    /// The cell of `parameter` for this grade.
    fn cell(self, parameter: Parameter) -> Option<Cell> {
        Self::TABLE.cell(parameter, self.index())
    }
}

impl Grade for GyroGrade {
    const TABLE: &'static Table = &GYRO_TABLE;

    fn index(self) -> usize {
        self as usize
    }
}

impl Grade for AccelGrade {
    const TABLE: &'static Table = &ACCEL_TABLE;

    fn index(self) -> usize {
        self as usize
    }
}

impl GyroGrade {
    /// Every gyro grade, worst first.
    pub const ALL: [GyroGrade; 4] = [
        GyroGrade::RateGrade,
        GyroGrade::Tactical,
        GyroGrade::Aviation,
        GyroGrade::Navigation,
    ];
}

impl AccelGrade {
    /// Every accelerometer grade, worst first.
    pub const ALL: [AccelGrade; 3] = [
        AccelGrade::Automotive,
        AccelGrade::Tactical,
        AccelGrade::Navigation,
    ];
}
