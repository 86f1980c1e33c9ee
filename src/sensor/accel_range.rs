//! The accelerometer full-scale ranges every chip triad drives offers:
//! ±2, 4, 8 and 16 g. One type for all of them; each chip gives only what
//! its data sheet says of them — the range field's codes
//! ([`Chip::accel_code`]) and the sensitivity table
//! ([`Chip::accel_si_per_lsb`]), which differ from chip to chip.

use super::chip::Chip;
use super::{CodeRange, TriadScale};
use crate::units::STANDARD_GRAVITY;

/// Accelerometer full-scale range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AccelRange {
    /// ±2 g.
    G2,
    /// ±4 g.
    G4,
    /// ±8 g.
    G8,
    /// ±16 g.
    G16,
}

impl AccelRange {
    /// All ranges, narrowest first.
    pub const ALL: [AccelRange; 4] = [Self::G2, Self::G4, Self::G8, Self::G16];

    /// The full scale in g.
    pub fn g(self) -> f64 {
        match self {
            Self::G2 => 2.0,
            Self::G4 => 4.0,
            Self::G8 => 8.0,
            Self::G16 => 16.0,
        }
    }

    /// The range chip `C` holds as `code` in its range field.
    pub fn from_code<C: Chip>(code: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|&r| C::accel_code(r) == code)
    }

    /// Counts → m/s² on chip `C` and the range in m/s².
    pub fn scale<C: Chip>(self) -> TriadScale {
        TriadScale {
            si_per_lsb: C::accel_si_per_lsb(self),
            full_scale: self.g() * STANDARD_GRAVITY,
            codes: CodeRange::I16,
        }
    }
}
