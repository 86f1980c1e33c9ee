//! The quantities inertial-sensor specifications are given in, and the units
//! each is quoted in, with the factor to its SI form (THEORY.md,
//! "Nomenclature and unit equivalences"; IEEE Std 952 Annex C; Kalibr's
//! IMU noise model for the Kalibr names).
//!
//! A white-noise density N (two-sided PSD S = N²) integrates to a random walk
//! σ(t) = N·√t, so one number has three spellings: per √Hz, per √s (the
//! same), per √h (÷ 60). The factors below are exact but for standard
//! gravity's and π's.

use std::f64::consts::PI;

use triad::units::STANDARD_GRAVITY as G;

/// A physical quantity of a specification.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Gyro white rate noise: angle random walk.
    AngleRandomWalk,
    /// Accelerometer white noise: velocity random walk.
    VelocityRandomWalk,
    /// A rate bias or bias instability.
    RateBias,
    /// An acceleration bias or bias instability.
    AccelBias,
    /// Gyro rate random walk (white noise in the rate's derivative).
    RateRandomWalk,
    /// Accelerometer acceleration random walk.
    AccelRandomWalk,
}

impl Quantity {
    /// What it is, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Quantity::AngleRandomWalk => {
                "gyro white noise: angle random walk (ARW), the density N of IEEE 952"
            }
            Quantity::VelocityRandomWalk => {
                "accelerometer white noise: velocity random walk (VRW), the density N"
            }
            Quantity::RateBias => "a rate: bias, bias instability (B of IEEE 952) or offset",
            Quantity::AccelBias => "an acceleration: bias or bias instability",
            Quantity::RateRandomWalk => "gyro rate random walk (K of IEEE 952)",
            Quantity::AccelRandomWalk => "accelerometer acceleration random walk (K)",
        }
    }

    /// Kalibr's name for the quantity (in its SI unit), if Kalibr has one.
    pub fn kalibr(self) -> Option<&'static str> {
        match self {
            Quantity::AngleRandomWalk => Some("gyroscope_noise_density"),
            Quantity::VelocityRandomWalk => Some("accelerometer_noise_density"),
            Quantity::RateRandomWalk => Some("gyroscope_random_walk"),
            Quantity::AccelRandomWalk => Some("accelerometer_random_walk"),
            Quantity::RateBias | Quantity::AccelBias => None,
        }
    }

    /// True for a noise density: √(density² × bandwidth) is the rms
    /// resolution over that bandwidth.
    pub fn is_density(self) -> bool {
        matches!(
            self,
            Quantity::AngleRandomWalk | Quantity::VelocityRandomWalk
        )
    }
}

/// One unit: how it is written, what it measures, and its SI factor.
#[derive(Clone, Copy, Debug)]
pub struct Unit {
    /// As printed.
    pub name: &'static str,
    /// Spellings accepted (after [`normalise`]), the printed one first.
    pub spellings: &'static [&'static str],
    /// The quantity.
    pub quantity: Quantity,
    /// SI units of the quantity per one of this unit.
    pub si: f64,
}

const DEG: f64 = PI / 180.0;
const UG: f64 = 1e-6 * G;
const MG: f64 = 1e-3 * G;

use Quantity::*;

/// Every unit `triad units` knows, grouped by quantity, the SI one first.
pub const UNITS: &[Unit] = &[
    Unit {
        name: "rad/s/√Hz",
        spellings: &["rad/s/sqrthz", "rad/sqrts"],
        quantity: AngleRandomWalk,
        si: 1.0,
    },
    Unit {
        name: "°/s/√Hz",
        spellings: &["deg/s/sqrthz", "dps/sqrthz", "deg/sqrts"],
        quantity: AngleRandomWalk,
        si: DEG,
    },
    Unit {
        name: "°/√h",
        spellings: &["deg/sqrth"],
        quantity: AngleRandomWalk,
        si: DEG / 60.0,
    },
    Unit {
        name: "°/h/√Hz",
        spellings: &["deg/h/sqrthz", "dph/sqrthz"],
        quantity: AngleRandomWalk,
        si: DEG / 3600.0,
    },
    Unit {
        name: "m/s²/√Hz",
        spellings: &["m/s^2/sqrthz", "m/s/sqrts"],
        quantity: VelocityRandomWalk,
        si: 1.0,
    },
    Unit {
        name: "g/√Hz",
        spellings: &["g/sqrthz"],
        quantity: VelocityRandomWalk,
        si: G,
    },
    Unit {
        name: "mg/√Hz",
        spellings: &["mg/sqrthz"],
        quantity: VelocityRandomWalk,
        si: MG,
    },
    Unit {
        name: "µg/√Hz",
        spellings: &["ug/sqrthz"],
        quantity: VelocityRandomWalk,
        si: UG,
    },
    Unit {
        name: "m/s/√h",
        spellings: &["m/s/sqrth"],
        quantity: VelocityRandomWalk,
        si: 1.0 / 60.0,
    },
    Unit {
        name: "ft/s/√h",
        spellings: &["ft/s/sqrth", "fps/sqrth"],
        quantity: VelocityRandomWalk,
        si: 0.3048 / 60.0,
    },
    Unit {
        name: "rad/s",
        spellings: &["rad/s"],
        quantity: RateBias,
        si: 1.0,
    },
    Unit {
        name: "°/s",
        spellings: &["deg/s", "dps"],
        quantity: RateBias,
        si: DEG,
    },
    Unit {
        name: "°/h",
        spellings: &["deg/h", "dph"],
        quantity: RateBias,
        si: DEG / 3600.0,
    },
    Unit {
        name: "m/s²",
        spellings: &["m/s^2", "m/s2"],
        quantity: AccelBias,
        si: 1.0,
    },
    Unit {
        name: "g",
        spellings: &["g"],
        quantity: AccelBias,
        si: G,
    },
    Unit {
        name: "mg",
        spellings: &["mg"],
        quantity: AccelBias,
        si: MG,
    },
    Unit {
        name: "µg",
        spellings: &["ug"],
        quantity: AccelBias,
        si: UG,
    },
    Unit {
        name: "rad/s²/√Hz",
        spellings: &["rad/s^2/sqrthz", "rad/s/sqrts"],
        quantity: RateRandomWalk,
        si: 1.0,
    },
    Unit {
        name: "°/s²/√Hz",
        spellings: &["deg/s^2/sqrthz", "deg/s/sqrts"],
        quantity: RateRandomWalk,
        si: DEG,
    },
    Unit {
        name: "°/h/√h",
        spellings: &["deg/h/sqrth", "dph/sqrth"],
        quantity: RateRandomWalk,
        si: DEG / 3600.0 / 60.0,
    },
    Unit {
        name: "m/s³/√Hz",
        spellings: &["m/s^3/sqrthz", "m/s^2/sqrts"],
        quantity: AccelRandomWalk,
        si: 1.0,
    },
    Unit {
        name: "µg/s/√Hz",
        spellings: &["ug/s/sqrthz", "ug/sqrts"],
        quantity: AccelRandomWalk,
        si: UG,
    },
    Unit {
        name: "mg/s/√Hz",
        spellings: &["mg/s/sqrthz", "mg/sqrts"],
        quantity: AccelRandomWalk,
        si: MG,
    },
    Unit {
        name: "µg/√h",
        spellings: &["ug/sqrth"],
        quantity: AccelRandomWalk,
        si: UG / 60.0,
    },
    Unit {
        name: "mg/√h",
        spellings: &["mg/sqrth"],
        quantity: AccelRandomWalk,
        si: MG / 60.0,
    },
    Unit {
        name: "m/s/h/√h",
        spellings: &["m/s/h/sqrth"],
        quantity: AccelRandomWalk,
        si: 1.0 / 3600.0 / 60.0,
    },
];

/// A unit as typed, in the form the table spells: lower case, no spaces or
/// parentheses, `°` → `deg`, `µ`/`μ` → `u`, `√` → `sqrt`, `²`/`³` → `^2`/`^3`,
/// `²` typed as `2` after `s` (`m/s2`) is a spelling of its own.
pub fn normalise(unit: &str) -> String {
    let mut out = String::new();
    for c in unit.chars() {
        match c {
            ' ' | '(' | ')' => {}
            '°' => out.push_str("deg"),
            'µ' | 'μ' => out.push('u'),
            '√' => out.push_str("sqrt"),
            '²' => out.push_str("^2"),
            '³' => out.push_str("^3"),
            c => out.extend(c.to_lowercase()),
        }
    }
    out
}

/// The unit spelt `unit`, if known.
pub fn find(unit: &str) -> Option<&'static Unit> {
    let key = normalise(unit);
    // "mg" and "Mg" both lower-case to "mg": only milli-g makes sense here.
    UNITS.iter().find(|u| u.spellings.contains(&key.as_str()))
}
