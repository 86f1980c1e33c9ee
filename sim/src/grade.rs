//! Grade presets from the published sensor-grade tables.
//!
//! Sources of the table rows (each row is a band of data-sheet values):
//!
//! - Gyros, rate / tactical / navigation ("inertial") grade: Yazdi, Ayazi &
//!   Najafi, "Micromachined Inertial Sensors", Proc. IEEE 86(8), 1998,
//!   Table 1 (angle random walk, bias drift, scale-factor accuracy). Open
//!   bounds ("> 0.5 °/√h", "< 0.01 °/h") are kept open (infinite or zero).
//! - Gyros, aviation grade: Groves, "Principles of GNSS, Inertial, and
//!   Multisensor Integrated Navigation Systems", 2nd ed., 2013, §4.4.1 and
//!   Table 4.2 (aviation- and intermediate-grade gyro biases 0.01–0.1 °/h); its
//!   ARW and scale-factor bands are the gap between Yazdi's tactical and
//!   inertial rows.
//! - Accelerometers: Groves 2nd ed. §4.4 and Table 4.1 with El-Sheimy &
//!   Youssef, "Inertial sensors technologies for navigation applications",
//!   Satellite Navigation 1:2, 2020, Table 1; automotive noise from consumer
//!   MEMS data sheets (e.g. TDK ICM-42688-P, 70 µg/√Hz; Bosch BMI088,
//!   175 µg/√Hz). These bands are orders of magnitude, as the tables are.
//!
//! A preset is one sensor written down inside its row (checked by a test
//! against the row, which is data kept separately from the preset).

use super::bias_instability::BiasInstabilityParams;
use super::scene::TriadEffects;
use triad::units::{
    arw_deg_per_sqrt_h_to_si, deg_per_h_to_rad_per_s, ppm_to_ratio, ug_per_sqrt_hz_to_si,
    ug_to_mps2,
};

/// A closed band [lo, hi] of a table row (hi may be infinite for an open row).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Band {
    /// True when `x` lies in the band.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
}

const fn band(lo: f64, hi: f64) -> Band {
    Band { lo, hi }
}

/// Gyro grades.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroGrade {
    /// Rate grade (consumer and automotive MEMS).
    RateGrade,
    /// Tactical grade.
    Tactical,
    /// Aviation grade.
    Aviation,
    /// Navigation (inertial) grade.
    Navigation,
}

/// Accelerometer grades.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccelGrade {
    /// Automotive (consumer MEMS).
    Automotive,
    /// Tactical grade.
    Tactical,
    /// Navigation grade.
    Navigation,
}

/// A gyro grade-table row, in data-sheet units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroRow {
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: Band,
    /// Bias instability (drift), °/h.
    pub bias_instability_deg_per_h: Band,
    /// Scale-factor accuracy, ppm.
    pub scale_factor_ppm: Band,
}

/// One gyro of a grade, in data-sheet units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroPreset {
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// Bias instability, °/h.
    pub bias_instability_deg_per_h: f64,
    /// Scale-factor error (1σ, run to run), ppm.
    pub scale_factor_ppm: f64,
}

/// An accelerometer grade-table row, in data-sheet units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelRow {
    /// Noise density, µg/√Hz.
    pub noise_ug_per_sqrt_hz: Band,
    /// Bias instability, µg.
    pub bias_instability_ug: Band,
    /// Scale-factor accuracy, ppm.
    pub scale_factor_ppm: Band,
}

/// One accelerometer of a grade, in data-sheet units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelPreset {
    /// Noise density, µg/√Hz.
    pub noise_ug_per_sqrt_hz: f64,
    /// Bias instability, µg.
    pub bias_instability_ug: f64,
    /// Scale-factor error (1σ, run to run), ppm.
    pub scale_factor_ppm: f64,
}

impl GyroGrade {
    /// Every gyro grade.
    pub const ALL: [GyroGrade; 4] = [
        GyroGrade::RateGrade,
        GyroGrade::Tactical,
        GyroGrade::Aviation,
        GyroGrade::Navigation,
    ];

    /// The grade's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            GyroGrade::RateGrade => "rate-grade",
            GyroGrade::Tactical => "tactical",
            GyroGrade::Aviation => "aviation",
            GyroGrade::Navigation => "navigation",
        }
    }

    /// The table row (see the module comment for sources).
    pub const fn row(self) -> GyroRow {
        match self {
            // Yazdi 1998 Table 1, rate grade: ARW > 0.5 °/√h, drift 10–1000 °/h, SF 0.1–1 %.
            GyroGrade::RateGrade => GyroRow {
                arw_deg_per_sqrt_h: band(0.5, f64::INFINITY),
                bias_instability_deg_per_h: band(10.0, 1000.0),
                scale_factor_ppm: band(1000.0, 10_000.0),
            },
            // Yazdi 1998 Table 1, tactical: ARW 0.05–0.5 °/√h, drift 0.1–10 °/h, SF 0.01–0.1 %.
            GyroGrade::Tactical => GyroRow {
                arw_deg_per_sqrt_h: band(0.05, 0.5),
                bias_instability_deg_per_h: band(0.1, 10.0),
                scale_factor_ppm: band(100.0, 1000.0),
            },
            // Groves 2nd ed. Table 4.2 (0.01–0.1 °/h); ARW and SF between Yazdi's rows.
            GyroGrade::Aviation => GyroRow {
                arw_deg_per_sqrt_h: band(0.001, 0.05),
                bias_instability_deg_per_h: band(0.01, 0.1),
                scale_factor_ppm: band(10.0, 100.0),
            },
            // Yazdi 1998 Table 1, inertial grade: ARW < 0.001 °/√h, drift < 0.01 °/h, SF < 0.001 %.
            GyroGrade::Navigation => GyroRow {
                arw_deg_per_sqrt_h: band(0.0, 0.001),
                bias_instability_deg_per_h: band(0.0, 0.01),
                scale_factor_ppm: band(0.0, 10.0),
            },
        }
    }

    /// The preset gyro of the grade.
    pub const fn preset(self) -> GyroPreset {
        match self {
            GyroGrade::RateGrade => GyroPreset {
                arw_deg_per_sqrt_h: 0.8,
                bias_instability_deg_per_h: 50.0,
                scale_factor_ppm: 3000.0,
            },
            GyroGrade::Tactical => GyroPreset {
                arw_deg_per_sqrt_h: 0.15,
                bias_instability_deg_per_h: 1.0,
                scale_factor_ppm: 300.0,
            },
            GyroGrade::Aviation => GyroPreset {
                arw_deg_per_sqrt_h: 0.01,
                bias_instability_deg_per_h: 0.03,
                scale_factor_ppm: 30.0,
            },
            GyroGrade::Navigation => GyroPreset {
                arw_deg_per_sqrt_h: 0.0007,
                bias_instability_deg_per_h: 0.005,
                scale_factor_ppm: 5.0,
            },
        }
    }

    /// The preset as SI effects: white noise, bias instability (default band)
    /// and a turn-on scale-factor error.
    pub fn effects(self) -> TriadEffects {
        let p = self.preset();
        let b = deg_per_h_to_rad_per_s(p.bias_instability_deg_per_h);
        TriadEffects {
            white_noise: Some([arw_deg_per_sqrt_h_to_si(p.arw_deg_per_sqrt_h); 3]),
            bias_instability: Some([BiasInstabilityParams::with_default_band(b); 3]),
            turn_on_scale: Some([ppm_to_ratio(p.scale_factor_ppm); 3]),
            ..TriadEffects::NONE
        }
    }

    /// The grade named `name` in a scene file.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == name)
    }
}

impl AccelGrade {
    /// Every accelerometer grade.
    pub const ALL: [AccelGrade; 3] = [
        AccelGrade::Automotive,
        AccelGrade::Tactical,
        AccelGrade::Navigation,
    ];

    /// The grade's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            AccelGrade::Automotive => "automotive",
            AccelGrade::Tactical => "tactical",
            AccelGrade::Navigation => "navigation",
        }
    }

    /// The table row (see the module comment for sources).
    pub const fn row(self) -> AccelRow {
        match self {
            AccelGrade::Automotive => AccelRow {
                noise_ug_per_sqrt_hz: band(50.0, 1000.0),
                bias_instability_ug: band(20.0, 1000.0),
                scale_factor_ppm: band(1000.0, 10_000.0),
            },
            AccelGrade::Tactical => AccelRow {
                noise_ug_per_sqrt_hz: band(10.0, 100.0),
                bias_instability_ug: band(5.0, 100.0),
                scale_factor_ppm: band(100.0, 1000.0),
            },
            AccelGrade::Navigation => AccelRow {
                noise_ug_per_sqrt_hz: band(0.5, 10.0),
                bias_instability_ug: band(1.0, 10.0),
                scale_factor_ppm: band(1.0, 100.0),
            },
        }
    }

    /// The preset accelerometer of the grade.
    pub const fn preset(self) -> AccelPreset {
        match self {
            AccelGrade::Automotive => AccelPreset {
                noise_ug_per_sqrt_hz: 150.0,
                bias_instability_ug: 100.0,
                scale_factor_ppm: 3000.0,
            },
            AccelGrade::Tactical => AccelPreset {
                noise_ug_per_sqrt_hz: 40.0,
                bias_instability_ug: 25.0,
                scale_factor_ppm: 300.0,
            },
            AccelGrade::Navigation => AccelPreset {
                noise_ug_per_sqrt_hz: 5.0,
                bias_instability_ug: 5.0,
                scale_factor_ppm: 20.0,
            },
        }
    }

    /// The preset as SI effects: white noise, bias instability (default band)
    /// and a turn-on scale-factor error.
    pub fn effects(self) -> TriadEffects {
        let p = self.preset();
        TriadEffects {
            white_noise: Some([ug_per_sqrt_hz_to_si(p.noise_ug_per_sqrt_hz); 3]),
            bias_instability: Some(
                [BiasInstabilityParams::with_default_band(ug_to_mps2(p.bias_instability_ug)); 3],
            ),
            turn_on_scale: Some([ppm_to_ratio(p.scale_factor_ppm); 3]),
            ..TriadEffects::NONE
        }
    }

    /// The grade named `name` in a scene file.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == name)
    }
}
