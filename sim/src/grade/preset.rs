//! Grade presets: one sensor per grade (and, for gyros, per grade and
//! technology the notes pair: tactical FOG, aviation RLG and FOG,
//! navigation RLG), written down inside its row of the tables of
//! [`super::table`], in the tables' units. A preset's [`effects`] are what a
//! scene's `grade = "NAME"` simulates: white noise, bias instability
//! (default band) and a turn-on scale-factor error whose σ is the
//! scale-factor instability. Range and bandwidth are the preset's data-sheet
//! figures, checked against the row; the simulator applies a range only when
//! a scene names `saturation`, and has no bandwidth filter.
//!
//! An optical gyro adds its optics ([`crate::optics::ring_laser`],
//! [`crate::optics::fibre_optic`]) and the fixed bias and scale-factor error
//! THEORY.md gives for its technology ([`super::table::RLG_FIGURES`],
//! [`super::table::FOG_FIGURES`]: what a calibration removes; their
//! instability is the grade's row). A ring laser's angle random walk is the
//! one its dither leaves (Ω_L/√(KΩ_D)): no white noise is added to it.
//!
//! [`effects`]: GyroPreset::effects

use super::table::Parameter;
use super::{AccelGrade, GyroGrade};
use crate::effects::bias_instability::BiasInstabilityParams;
use crate::optics::fibre_optic::{FibreOpticParams, Loop};
use crate::optics::ring_laser::{Dither, RingLaserParams};
use crate::scenes::scene::TriadEffects;
use triad::units::{
    arw_deg_per_sqrt_h_to_si, deg_per_h_to_rad_per_s, ppm_to_ratio, ug_per_sqrt_hz_to_si,
    ug_to_mps2,
};

/// The technology a gyro preset models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technology {
    /// A MEMS gyro: its noise terms (the rate-grade and tactical presets).
    Mems,
    /// The grade's noise terms only, no technology's own effects.
    NoiseTerms,
    /// A ring laser gyro.
    RingLaser,
    /// A fibre-optic gyro.
    FibreOptic,
}

/// The optics of an optical gyro preset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Optics {
    /// A ring laser gyro's.
    RingLaser(RingLaserParams),
    /// A fibre-optic gyro's.
    FibreOptic(FibreOpticParams),
}

impl Technology {
    /// The name in listings.
    pub fn name(self) -> &'static str {
        match self {
            Technology::Mems => "MEMS",
            Technology::NoiseTerms => "noise terms only",
            Technology::RingLaser => "RLG",
            Technology::FibreOptic => "FOG",
        }
    }
}

/// One gyro, in the units of [`super::GYRO_TABLE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroPreset {
    /// The name a scene's `grade` gives.
    pub name: &'static str,
    /// The grade whose row it sits in.
    pub grade: GyroGrade,
    /// The technology modelled.
    pub technology: Technology,
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// Bias instability, °/h.
    pub bias_instability_deg_per_h: f64,
    /// Scale-factor instability (σ of the turn-on scale-factor error), %.
    pub scale_factor_instability_percent: f64,
    /// Measurement range, °/s.
    pub range_deg_per_s: f64,
    /// Bandwidth, Hz.
    pub bandwidth_hz: f64,
    /// Fixed bias, °/h (0: none).
    pub bias_deg_per_h: f64,
    /// Fixed scale-factor error, ppm (0: none).
    pub scale_factor_error_ppm: f64,
    /// An optical gyro's optics.
    pub optics: Option<Optics>,
}

/// One accelerometer, in the units of [`super::ACCEL_TABLE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelPreset {
    /// The name a scene's `grade` gives.
    pub name: &'static str,
    /// The grade whose row it sits in.
    pub grade: AccelGrade,
    /// Noise density, µg/√Hz.
    pub noise_ug_per_sqrt_hz: f64,
    /// Bias instability, µg.
    pub bias_instability_ug: f64,
    /// Scale-factor instability (σ of the turn-on scale-factor error), ppm.
    pub scale_factor_instability_ppm: f64,
    /// Measurement range, g.
    pub range_g: f64,
    /// Bandwidth, Hz.
    pub bandwidth_hz: f64,
}

/// White noise, bias instability (default band) and turn-on scale factor (SI).
fn noise_effects(white_noise: f64, bias_instability: f64, scale_ratio: f64) -> TriadEffects {
    TriadEffects {
        white_noise: Some([white_noise; 3]),
        bias_instability: Some([BiasInstabilityParams::with_default_band(bias_instability); 3]),
        turn_on_scale: Some([scale_ratio; 3]),
        ..TriadEffects::NONE
    }
}

/// Radians per degree.
const DEG: f64 = core::f64::consts::PI / 180.0;

/// The fields of a preset without optics (spread into the MEMS and
/// noise-only presets).
const NO_OPTICS: GyroPreset = GyroPreset {
    name: "",
    grade: GyroGrade::RateGrade,
    technology: Technology::NoiseTerms,
    arw_deg_per_sqrt_h: 0.0,
    bias_instability_deg_per_h: 0.0,
    scale_factor_instability_percent: 0.0,
    range_deg_per_s: 0.0,
    bandwidth_hz: 0.0,
    bias_deg_per_h: 0.0,
    scale_factor_error_ppm: 0.0,
    optics: None,
};

impl GyroPreset {
    /// Every gyro preset.
    pub const ALL: [GyroPreset; 8] = [
        GyroPreset {
            name: "rate-grade",
            grade: GyroGrade::RateGrade,
            technology: Technology::Mems,
            arw_deg_per_sqrt_h: 0.8,
            bias_instability_deg_per_h: 50.0,
            scale_factor_instability_percent: 0.3,
            range_deg_per_s: 500.0,
            bandwidth_hz: 100.0,
            ..NO_OPTICS
        },
        GyroPreset {
            name: "tactical",
            grade: GyroGrade::Tactical,
            technology: Technology::Mems,
            arw_deg_per_sqrt_h: 0.15,
            bias_instability_deg_per_h: 3.0,
            scale_factor_instability_percent: 0.03,
            range_deg_per_s: 1000.0,
            bandwidth_hz: 500.0,
            ..NO_OPTICS
        },
        GyroPreset {
            name: "aviation",
            grade: GyroGrade::Aviation,
            technology: Technology::NoiseTerms,
            arw_deg_per_sqrt_h: 0.01,
            bias_instability_deg_per_h: 0.03,
            scale_factor_instability_percent: 0.003,
            range_deg_per_s: 200.0,
            bandwidth_hz: 100.0,
            ..NO_OPTICS
        },
        GyroPreset {
            name: "navigation",
            grade: GyroGrade::Navigation,
            technology: Technology::NoiseTerms,
            arw_deg_per_sqrt_h: 0.0005,
            bias_instability_deg_per_h: 0.005,
            scale_factor_instability_percent: 0.0005,
            range_deg_per_s: 500.0,
            bandwidth_hz: 200.0,
            ..NO_OPTICS
        },
        GyroPreset {
            name: "tactical-fog",
            grade: GyroGrade::Tactical,
            technology: Technology::FibreOptic,
            arw_deg_per_sqrt_h: 0.1,
            bias_instability_deg_per_h: 2.0,
            scale_factor_instability_percent: 0.03,
            range_deg_per_s: 1000.0,
            bandwidth_hz: 500.0,
            bias_deg_per_h: 10.0,
            scale_factor_error_ppm: 1000.0,
            // 200 m of fibre on a 6 cm coil (1061 turns) at 1550 nm, closed
            // loop; the source's wavelength +20 ppm/°C (partly held), the
            // coil's area +1.1 ppm/°C (silica).
            optics: Some(Optics::FibreOptic(FibreOpticParams {
                turns: 1061.0,
                coil_area: 2.827e-3,
                wavelength: 1550e-9,
                readout: Loop::Closed,
                reference: 25.0,
                area_per_degree: 1.1e-6,
                wavelength_per_degree: 20e-6,
            })),
        },
        GyroPreset {
            name: "aviation-rlg",
            grade: GyroGrade::Aviation,
            technology: Technology::RingLaser,
            // The dither's walk: Ω_L/√(KΩ_D) (a test holds the two together).
            arw_deg_per_sqrt_h: 0.0077,
            bias_instability_deg_per_h: 0.02,
            scale_factor_instability_percent: 0.002,
            range_deg_per_s: 200.0,
            bandwidth_hz: 100.0,
            bias_deg_per_h: 0.001,
            scale_factor_error_ppm: 5.0,
            // A triangle of 6 cm sides at 632.8 nm: 3.77 arcsec a fringe;
            // lock-in 0.1 °/s, dither 100 °/s peak at 400 Hz.
            optics: Some(Optics::RingLaser(RingLaserParams {
                area: 1.558_845_7e-3,
                path_length: 0.18,
                wavelength: 632.8e-9,
                lock_in: 0.1 * DEG,
                dither: Some(Dither {
                    peak_rate: 100.0 * DEG,
                    frequency: 400.0,
                }),
            })),
        },
        GyroPreset {
            name: "aviation-fog",
            grade: GyroGrade::Aviation,
            technology: Technology::FibreOptic,
            arw_deg_per_sqrt_h: 0.02,
            bias_instability_deg_per_h: 0.05,
            scale_factor_instability_percent: 0.005,
            range_deg_per_s: 200.0,
            bandwidth_hz: 100.0,
            bias_deg_per_h: 1.0,
            scale_factor_error_ppm: 500.0,
            // 1 km of fibre on a 10 cm coil (3183 turns) at 1550 nm, closed
            // loop; a held source (+2 ppm/°C), the coil +1.1 ppm/°C.
            optics: Some(Optics::FibreOptic(FibreOpticParams {
                turns: 3183.0,
                coil_area: 7.854e-3,
                wavelength: 1550e-9,
                readout: Loop::Closed,
                reference: 25.0,
                area_per_degree: 1.1e-6,
                wavelength_per_degree: 2e-6,
            })),
        },
        GyroPreset {
            name: "navigation-rlg",
            grade: GyroGrade::Navigation,
            technology: Technology::RingLaser,
            // The dither's walk: Ω_L/√(KΩ_D).
            arw_deg_per_sqrt_h: 0.000_548,
            bias_instability_deg_per_h: 0.003,
            scale_factor_instability_percent: 0.0005,
            range_deg_per_s: 500.0,
            bandwidth_hz: 200.0,
            bias_deg_per_h: 0.001,
            scale_factor_error_ppm: 2.0,
            // A triangle of 10 cm sides at 632.8 nm: 2.26 arcsec a fringe;
            // lock-in 0.01 °/s, dither 120 °/s peak at 400 Hz.
            optics: Some(Optics::RingLaser(RingLaserParams {
                area: 4.330_127e-3,
                path_length: 0.3,
                wavelength: 632.8e-9,
                lock_in: 0.01 * DEG,
                dither: Some(Dither {
                    peak_rate: 120.0 * DEG,
                    frequency: 400.0,
                }),
            })),
        },
    ];

    /// The preset a scene names `name`.
    pub fn named(name: &str) -> Option<&'static GyroPreset> {
        Self::ALL.iter().find(|p| p.name == name)
    }

    /// The preset's value of every parameter it has, in the table's units.
    pub fn values(&self) -> [(Parameter, f64); 5] {
        [
            (Parameter::Noise, self.arw_deg_per_sqrt_h),
            (Parameter::BiasInstability, self.bias_instability_deg_per_h),
            (
                Parameter::ScaleFactorInstability,
                self.scale_factor_instability_percent,
            ),
            (Parameter::Range, self.range_deg_per_s),
            (Parameter::Bandwidth, self.bandwidth_hz),
        ]
    }

    /// The preset as SI effects: its noise terms, and an optical gyro's
    /// optics, fixed bias and scale-factor error (a ring laser's white noise
    /// being its dither's walk, none is added).
    pub fn effects(&self) -> TriadEffects {
        let mut e = noise_effects(
            arw_deg_per_sqrt_h_to_si(self.arw_deg_per_sqrt_h),
            deg_per_h_to_rad_per_s(self.bias_instability_deg_per_h),
            self.scale_factor_instability_percent / 100.0,
        );
        if self.bias_deg_per_h != 0.0 {
            e.constant_bias = Some([deg_per_h_to_rad_per_s(self.bias_deg_per_h); 3]);
        }
        if self.scale_factor_error_ppm != 0.0 {
            let s = ppm_to_ratio(self.scale_factor_error_ppm);
            e.scale_misalignment = Some([[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]]);
        }
        match self.optics {
            Some(Optics::RingLaser(p)) => {
                e.ring_laser = Some(p);
                e.white_noise = None;
            }
            Some(Optics::FibreOptic(p)) => e.fibre_optic = Some(p),
            None => {}
        }
        e
    }
}

impl AccelPreset {
    /// Every accelerometer preset.
    pub const ALL: [AccelPreset; 3] = [
        AccelPreset {
            name: "automotive",
            grade: AccelGrade::Automotive,
            noise_ug_per_sqrt_hz: 1000.0,
            bias_instability_ug: 20e3,
            scale_factor_instability_ppm: 20e3,
            range_g: 2.0,
            bandwidth_hz: 100.0,
        },
        AccelPreset {
            name: "tactical",
            grade: AccelGrade::Tactical,
            noise_ug_per_sqrt_hz: 150.0,
            bias_instability_ug: 500.0,
            scale_factor_instability_ppm: 300.0,
            range_g: 70.0,
            bandwidth_hz: 100.0,
        },
        AccelPreset {
            name: "navigation",
            grade: AccelGrade::Navigation,
            noise_ug_per_sqrt_hz: 5.0,
            bias_instability_ug: 30.0,
            scale_factor_instability_ppm: 30.0,
            range_g: 20.0,
            bandwidth_hz: 100.0,
        },
    ];

    /// The preset a scene names `name`.
    pub fn named(name: &str) -> Option<&'static AccelPreset> {
        Self::ALL.iter().find(|p| p.name == name)
    }

    /// The preset's value of every parameter it has, in the table's units.
    pub fn values(&self) -> [(Parameter, f64); 5] {
        [
            (Parameter::Noise, self.noise_ug_per_sqrt_hz),
            (Parameter::BiasInstability, self.bias_instability_ug),
            (
                Parameter::ScaleFactorInstability,
                self.scale_factor_instability_ppm,
            ),
            (Parameter::Range, self.range_g),
            (Parameter::Bandwidth, self.bandwidth_hz),
        ]
    }

    /// The preset as SI effects.
    pub fn effects(&self) -> TriadEffects {
        noise_effects(
            ug_per_sqrt_hz_to_si(self.noise_ug_per_sqrt_hz),
            ug_to_mps2(self.bias_instability_ug),
            ppm_to_ratio(self.scale_factor_instability_ppm),
        )
    }
}
