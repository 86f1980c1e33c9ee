//! A ring laser gyro (THEORY.md, "Optical gyros"): two beams round a closed
//! path of area A and length L beat at Δf = 4A/(Lλ)·ω, and each fringe
//! counted is an angle increment Δθ = Lλ/(4A) (2–5 arc-seconds for the usual
//! cavities at λ = 632.8 nm). Three effects of the optics, per axis:
//!
//! 1. **Lock-in.** Backscatter couples the beams: the phase ψ between them
//!    (2π a fringe) obeys Adler's equation dψ/dt = K(ω − Ω_L·sin ψ), K = 2π·4A/(Lλ)
//!    (Aronowitz, "The laser gyro", in Laser Applications vol. 1, 1971).
//!    Undithered, a steady input below the lock-in rate Ω_L gives no
//!    fringes, and above it the beat is √(ω² − Ω_L²) (the equation's mean):
//!    the output is that, for each sample's mean rate.
//! 2. **Mechanical dither** of peak rate Ω_D at f_d breaks the lock-in: the
//!    input is counted linearly, but each of the 2·f_d passages of the
//!    dithered rate through zero a second adds an angle error. Near a
//!    passage the rate is ω ≈ Ω̇·s (Ω̇ = 2π·f_d·Ω_D), and to first order in
//!    Ω_L the phase error is −KΩ_L∫sin(ψ_c + KΩ̇s²/2)ds, a Fresnel integral:
//!    the angle error δθ = −Ω_L·√(2π/(KΩ̇))·sin(ψ_c + π/4), ψ_c the phase at
//!    the passage. The dither's amplitude is randomised (as in practice,
//!    against dynamic lock-in), so ψ_c is uniform and independent from one
//!    passage to the next: the errors are a random walk of the angle, with
//!    variance Ω_L²/(KΩ_D) per second, an angle random walk
//!    N = Ω_L/√(K·Ω_D) (sim/tests/ring_laser.rs checks the per-passage
//!    error against Adler's equation integrated). Passages are drawn one by
//!    one; above [`CLT_PASSAGES`] in a sample their sum is drawn as one
//!    normal deviate of the same variance.
//! 3. **Fringe counting.** The rate a sample reports is the whole fringes
//!    counted over the period times Δθ. Dithered, the counter counts the
//!    dithered angle and the dither (known from its pick-off) is
//!    subtracted: the fraction of a fringe the dither adds at each sample is
//!    uniform and fresh, so the counting error is uniform, white and
//!    independent of the input (subtractive dither): IEEE 952's
//!    quantisation term with Q = Δθ/√12. Undithered, the counter counts the
//!    input alone ([`crate::effects::increment_quantisation`]).
//!
//! Scale-factor error, bias, bias instability and other noise are the
//! simulator's other effects (the presets of `grade::preset` set them).

use crate::effects::rng::Rng;

/// Passages in one sample above which their summed error is drawn as one
/// normal deviate (the sum of n arcsine-distributed errors: its excess
/// kurtosis is −1.5/n, under 0.1 from here).
pub const CLT_PASSAGES: u64 = 16;

/// Mechanical dither.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct Dither {
    /// Peak dither rate Ω_D, rad/s.
    pub peak_rate: f64,
    /// Dither frequency f_d, Hz.
    pub frequency: f64,
}

/// A ring laser gyro's optics (the same for the three axes).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct RingLaserParams {
    /// Area A enclosed by the beams, m².
    pub area: f64,
    /// Path length L round the cavity, m.
    pub path_length: f64,
    /// Wavelength λ, m.
    pub wavelength: f64,
    /// Lock-in rate Ω_L, rad/s.
    pub lock_in: f64,
    /// Mechanical dither; None: undithered (lock-in holds below Ω_L).
    pub dither: Option<Dither>,
}

impl RingLaserParams {
    /// The Sagnac scale factor 4A/(Lλ): fringes per radian.
    pub fn fringes_per_rad(&self) -> f64 {
        4.0 * self.area / (self.path_length * self.wavelength)
    }

    /// The angle of one fringe, Lλ/(4A), rad.
    pub fn fringe_angle(&self) -> f64 {
        self.path_length * self.wavelength / (4.0 * self.area)
    }

    /// IEEE 952's quantisation coefficient of the fringe count, Δθ/√12, rad.
    pub fn quantisation(&self) -> f64 {
        self.fringe_angle() / libm::sqrt(12.0)
    }

    /// Adler's K: radians of phase between the beams per radian turned.
    fn phase_per_rad(&self) -> f64 {
        2.0 * core::f64::consts::PI * self.fringes_per_rad()
    }

    /// The amplitude of the angle error of one dither passage,
    /// Ω_L·√(2π/(KΩ̇)), rad (0 undithered).
    pub fn passage_error_amplitude(&self) -> f64 {
        match self.dither {
            Some(d) => {
                let slope = 2.0 * core::f64::consts::PI * d.frequency * d.peak_rate;
                let k = self.phase_per_rad();
                self.lock_in * libm::sqrt(2.0 * core::f64::consts::PI / (k * slope))
            }
            None => 0.0,
        }
    }

    /// The angle random walk the dither's passages leave, Ω_L/√(K·Ω_D),
    /// rad/√s (0 undithered).
    pub fn dither_random_walk(&self) -> f64 {
        match self.dither {
            Some(d) => self.lock_in / libm::sqrt(self.phase_per_rad() * d.peak_rate),
            None => 0.0,
        }
    }

    /// The mean output of a steady input `rate` without dither: 0 within
    /// the lock-in band, sign(ω)·√(ω² − Ω_L²) outside it.
    pub fn locked_rate(&self, rate: f64) -> f64 {
        let excess = rate * rate - self.lock_in * self.lock_in;
        if excess > 0.0 {
            libm::copysign(libm::sqrt(excess), rate)
        } else {
            0.0
        }
    }
}

/// One axis of a ring laser gyro: its dither's timing, its fringe counter
/// and its random stream.
#[derive(Clone, Copy, Debug)]
pub struct RingLaser {
    params: RingLaserParams,
    /// Passages of the dithered rate through zero, as a fraction of the
    /// next one: [0, 1).
    passage_phase: f64,
    /// The counted angle's part of a fringe, in fringes: [0, 1).
    fraction: f64,
    /// The dither's fraction of a fringe at the last sample, and the
    /// whole fringe it then added to the count (0 or 1).
    last_offset: f64,
    last_extra: f64,
    rng: Rng,
}

impl RingLaser {
    /// An axis with `params`, drawing from `rng` (its own stream).
    pub fn new(params: RingLaserParams, mut rng: Rng) -> Self {
        let dithered = params.dither.is_some();
        let passage_phase = if dithered { rng.uniform() } else { 0.0 };
        let last_offset = if dithered { rng.uniform() } else { 0.5 };
        Self {
            params,
            passage_phase,
            fraction: 0.0,
            last_offset,
            last_extra: libm::floor(last_offset),
            rng,
        }
    }

    /// The rate the optics sense over one period of `ts` s whose mean input
    /// is `rate`: the lock-in's (undithered), or the input plus the dither
    /// passages' angle errors over the period.
    pub fn sense(&mut self, rate: f64, ts: f64) -> f64 {
        let Some(d) = self.params.dither else {
            return self.params.locked_rate(rate);
        };
        let moved = self.passage_phase + 2.0 * d.frequency * ts;
        let passages = libm::floor(moved);
        self.passage_phase = moved - passages;
        let a = self.params.passage_error_amplitude();
        if a == 0.0 || passages < 1.0 {
            return rate;
        }
        let n = passages as u64;
        let error = if n > CLT_PASSAGES {
            a * libm::sqrt(passages / 2.0) * self.rng.gaussian()
        } else {
            (0..n)
                .map(|_| a * libm::sin(2.0 * core::f64::consts::PI * self.rng.uniform()))
                .sum()
        };
        rate + error / ts
    }

    /// The fringes counted over one period of `ts` s in which the sensed
    /// rate's mean is `rate` (dithered: counted with the dither, whose
    /// fraction of a fringe is then subtracted), and the rate reported.
    pub fn count(&mut self, rate: f64, ts: f64) -> (f64, f64) {
        let moved = self.fraction + rate * ts * self.params.fringes_per_rad();
        let whole = libm::floor(moved);
        self.fraction = moved - whole;
        let offset = if self.params.dither.is_some() {
            self.rng.uniform()
        } else {
            self.last_offset
        };
        let extra = libm::floor(self.fraction + offset);
        let counts = whole + extra - self.last_extra;
        let stripped = counts - (offset - self.last_offset);
        self.last_offset = offset;
        self.last_extra = extra;
        (counts, stripped * self.params.fringe_angle() / ts)
    }
}
