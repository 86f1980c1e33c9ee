//! Grade presets: one sensor per grade (and, for gyros, per grade and
//! technology the notes pair), written down inside its row of the tables of
//! [`super::table`], in the tables' units. A preset's [`effects`] are what a
//! scene's `grade = "NAME"` simulates: white noise, bias instability
//! (default band) and a turn-on scale-factor error whose σ is the
//! scale-factor instability. Range and bandwidth are the preset's data-sheet
//! figures, checked against the row; the simulator applies a range only when
//! a scene names `saturation`, and has no bandwidth filter.
//!
//! [`effects`]: GyroPreset::effects

use super::table::Parameter;
use super::{AccelGrade, GyroGrade};
use crate::bias_instability::BiasInstabilityParams;
use crate::scene::TriadEffects;
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
}

impl Technology {
    /// The name in listings.
    pub fn name(self) -> &'static str {
        match self {
            Technology::Mems => "MEMS",
            Technology::NoiseTerms => "noise terms only",
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

impl GyroPreset {
    /// Every gyro preset.
    pub const ALL: [GyroPreset; 4] = [
        GyroPreset {
            name: "rate-grade",
            grade: GyroGrade::RateGrade,
            technology: Technology::Mems,
            arw_deg_per_sqrt_h: 0.8,
            bias_instability_deg_per_h: 50.0,
            scale_factor_instability_percent: 0.3,
            range_deg_per_s: 500.0,
            bandwidth_hz: 100.0,
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

    /// The preset as SI effects.
    pub fn effects(&self) -> TriadEffects {
        noise_effects(
            arw_deg_per_sqrt_h_to_si(self.arw_deg_per_sqrt_h),
            deg_per_h_to_rad_per_s(self.bias_instability_deg_per_h),
            self.scale_factor_instability_percent / 100.0,
        )
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
