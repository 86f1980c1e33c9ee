//! A fibre-optic gyro (THEORY.md, "Optical gyros"): two beams round N turns
//! of fibre on a coil of area A differ in phase by the Sagnac phase
//! ΔΦ = 8πNA·ω/(λc) — c in the denominator: a small phase per rad/s,
//! hence the kilometre of fibre of the better ones.
//!
//! - **Open loop** the detector sees 1 + cos(ΔΦ + π/2) (a phase modulation
//!   biases it to its steepest point): the output is sin(ΔΦ), most
//!   sensitive at ω = 0, compressed as the phase grows, and ambiguous
//!   beyond |ΔΦ| = π/2 (two rates give one output). The rate reported is
//!   sin(ΔΦ)/S₀, S₀ the phase per rad/s the electronics assume.
//! - **Closed loop** (a null detector: a feedback phase cancels ΔΦ and is
//!   the output) the response is linear: ΔΦ/S₀.
//!
//! Either way the scale factor follows the coil and the source: S(T) =
//! 8πN·A(T)/(λ(T)·c), the coil's area growing with temperature (fibre and
//! spool expansion) and the source's wavelength drifting with it (a
//! superluminescent diode moves by hundreds of ppm/°C unless held), so the
//! scale factor changes by (1 + α_A·ΔT)/(1 + α_λ·ΔT) from the reference
//! temperature, where S₀ holds. Bias (a non-reciprocal phase) and bias
//! instability enter before the response, as the simulator's bias effects
//! do; detector noise after, as its white noise does.

/// The speed of light in vacuum, m/s.
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;

/// How the gyro's phase is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub enum Loop {
    /// The detector's output, sin(ΔΦ).
    Open,
    /// The feedback phase that nulls the detector, ΔΦ.
    Closed,
}

/// A fibre-optic gyro's optics (the same for the three axes).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct FibreOpticParams {
    /// Turns N of fibre.
    pub turns: f64,
    /// Area A of one turn, m², at the reference temperature.
    pub coil_area: f64,
    /// Source wavelength λ, m, at the reference temperature.
    pub wavelength: f64,
    /// Open or closed loop.
    pub readout: Loop,
    /// Reference temperature, °C: where S₀ holds.
    pub reference: f64,
    /// Relative change of the coil's area per °C.
    pub area_per_degree: f64,
    /// Relative change of the source's wavelength per °C.
    pub wavelength_per_degree: f64,
}

impl FibreOpticParams {
    /// The Sagnac phase per rad/s at the reference temperature,
    /// S₀ = 8πNA/(λc), s.
    pub fn phase_per_rate(&self) -> f64 {
        8.0 * core::f64::consts::PI * self.turns * self.coil_area
            / (self.wavelength * SPEED_OF_LIGHT)
    }

    /// The scale factor at `temp` relative to the reference, S(T)/S₀.
    pub fn scale_ratio(&self, temp: f64) -> f64 {
        let dt = temp - self.reference;
        (1.0 + self.area_per_degree * dt) / (1.0 + self.wavelength_per_degree * dt)
    }

    /// The Sagnac phase of `rate` at `temp`, rad.
    pub fn phase(&self, rate: f64, temp: f64) -> f64 {
        self.phase_per_rate() * self.scale_ratio(temp) * rate
    }

    /// The rate of an open-loop gyro's output at ΔΦ = ±π/2: beyond it the
    /// response turns back (at the reference temperature), rad/s.
    pub fn open_loop_limit(&self) -> f64 {
        core::f64::consts::FRAC_PI_2 / self.phase_per_rate()
    }

    /// The rate reported for an input `rate` at `temp`.
    pub fn output(&self, rate: f64, temp: f64) -> f64 {
        let phase = self.phase(rate, temp);
        let read = match self.readout {
            Loop::Open => libm::sin(phase),
            Loop::Closed => phase,
        };
        read / self.phase_per_rate()
    }
}
