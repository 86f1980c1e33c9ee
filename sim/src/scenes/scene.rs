//! A scene: motion, environment, temperature, sample rate and, per triad, the
//! error effects it calls for. Every effect is an `Option`: one that is `None`
//! is not computed at all. All parameters are SI (converted from data-sheet
//! units once, where the scene is loaded).

use super::temperature_profile::{TemperatureProfile, MAX_SOAK_LEVELS};
use crate::effects::bias_instability::{BiasInstabilityParams, MAX_TERMS};
use crate::effects::temperature_dependence::TemperatureDependence;
use crate::motion::hand_poses::MIN_HAND_POSES;
use crate::motion::{Environment, Motion, MAX_POSITIONS};
use crate::optics::fibre_optic::FibreOpticParams;
use crate::optics::ring_laser::RingLaserParams;

/// Parameters of a first-order Gauss–Markov bias, per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct GaussMarkovParams {
    /// Stationary standard deviation σ (SI units of the triad).
    pub sigma: [f64; 3],
    /// Correlation time 1/α, seconds.
    pub correlation_time: [f64; 3],
}

/// The error effects of one triad. SI units: m/s² for accelerometers, rad/s
/// for gyros ("U" below).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct TriadEffects {
    /// White-noise density N, U/√Hz (ARW or VRW).
    pub white_noise: Option<[f64; 3]>,
    /// First-order Gauss–Markov bias.
    pub gauss_markov: Option<GaussMarkovParams>,
    /// Random-walk coefficient K, U/√s (rate or acceleration random walk).
    pub random_walk: Option<[f64; 3]>,
    /// Bias instability (flicker floor), one set of parameters per axis.
    pub bias_instability: Option<[BiasInstabilityParams; 3]>,
    /// Constant bias, U.
    pub constant_bias: Option<[f64; 3]>,
    /// Standard deviation of the turn-on bias, U (drawn once per run).
    pub turn_on_bias: Option<[f64; 3]>,
    /// Σ of (I + Σ): scale-factor errors on the diagonal, misalignments off it.
    pub scale_misalignment: Option<[[f64; 3]; 3]>,
    /// Standard deviation of the turn-on scale-factor error (ratio; drawn once per run).
    pub turn_on_scale: Option<[f64; 3]>,
    /// Temperature coefficients of bias and scale factor.
    pub temperature: Option<TemperatureDependence>,
    /// Gyro g-sensitivity G, (rad/s)/(m/s²); gyros only.
    pub g_sensitivity: Option<[[f64; 3]; 3]>,
    /// A ring laser gyro's optics: lock-in, dither, fringe counting; gyros only.
    pub ring_laser: Option<RingLaserParams>,
    /// A fibre-optic gyro's optics: open- or closed-loop response,
    /// temperature of the scale factor; gyros only.
    pub fibre_optic: Option<FibreOpticParams>,
    /// Angle (gyro) or velocity (accel) quantisation: the step S of the
    /// counted integral, rad or m/s ([`crate::effects::increment_quantisation`]; IEEE
    /// 952's Q = S/√12).
    pub increment_quantisation: Option<[f64; 3]>,
    /// The output register's LSB: each sample rounded to it, U
    /// ([`crate::effects::output_lsb`]).
    pub output_lsb: Option<[f64; 3]>,
    /// Measurement range, ±U.
    pub saturation: Option<[f64; 3]>,
}

impl TriadEffects {
    /// No effect at all: the triad measures the truth exactly.
    pub const NONE: Self = Self {
        white_noise: None,
        gauss_markov: None,
        random_walk: None,
        bias_instability: None,
        constant_bias: None,
        turn_on_bias: None,
        scale_misalignment: None,
        turn_on_scale: None,
        temperature: None,
        g_sensitivity: None,
        ring_laser: None,
        fibre_optic: None,
        increment_quantisation: None,
        output_lsb: None,
        saturation: None,
    };

    /// True when no effect is named.
    pub fn is_none(&self) -> bool {
        *self == Self::NONE
    }
}

/// Everything the simulator needs to produce samples.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "scene-blob", derive(serde::Serialize, serde::Deserialize))]
pub struct Scene {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// The motion.
    pub motion: Motion,
    /// Gravity and Earth rate.
    pub environment: Environment,
    /// Temperature over time.
    pub temperature: TemperatureProfile,
    /// Accelerometer effects.
    pub accel: TriadEffects,
    /// Gyro effects.
    pub gyro: TriadEffects,
}

impl Scene {
    /// A scene at `rate_hz` with `motion` in the standard environment at 25 °C
    /// and no error effects.
    pub fn new(rate_hz: f64, motion: Motion) -> Self {
        Self {
            rate_hz,
            motion,
            environment: Environment::default(),
            temperature: TemperatureProfile::Constant(25.0),
            accel: TriadEffects::NONE,
            gyro: TriadEffects::NONE,
        }
    }
}

/// Which triad a scene error is about: the core's one accel/gyro enum.
pub use triad::model::Triad;

/// Why a scene cannot be simulated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneError {
    /// The sample rate is not a positive finite number.
    BadRate(f64),
    /// A parameter is NaN or infinite.
    NotFinite {
        /// Which triad (None: the scene itself).
        triad: Option<Triad>,
        /// The parameter.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter that must not be negative is.
    Negative {
        /// Which triad (None: the scene itself).
        triad: Option<Triad>,
        /// The parameter.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter that must be positive is zero or negative.
    NotPositive {
        /// Which triad (None: the scene itself).
        triad: Option<Triad>,
        /// The parameter.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// Bias instability with a number of terms outside 1..=MAX_TERMS.
    BadTermCount(u8),
    /// Bias-instability band with τ_max < τ_min.
    BadBand {
        /// Shortest averaging time.
        tau_min: f64,
        /// Longest averaging time.
        tau_max: f64,
    },
    /// A tumble with a position count other than 6, 12 or 24.
    BadPositions(u8),
    /// A hand motion with fewer than 12 or more than 24 poses.
    BadHandPoses(u8),
    /// A soak profile with fewer than 2 or more than 4 levels.
    BadSoakCount(u8),
    /// g-sensitivity given for the accelerometers.
    GSensitivityOnAccel,
    /// A zero vibration direction.
    ZeroDirection,
    /// An optical gyro model (`ring_laser`, `fibre_optic`) given for the accelerometers.
    OpticalOnAccel,
    /// Both optical gyro models at once.
    TwoOpticalModels,
    /// A ring laser gyro with `increment_quantisation`: it counts its fringes itself.
    CountedTwice,
}

fn finite(triad: Option<Triad>, what: &'static str, value: f64) -> Result<(), SceneError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(SceneError::NotFinite { triad, what, value })
    }
}

fn non_negative(triad: Option<Triad>, what: &'static str, value: f64) -> Result<(), SceneError> {
    finite(triad, what, value)?;
    if value < 0.0 {
        Err(SceneError::Negative { triad, what, value })
    } else {
        Ok(())
    }
}

fn positive(triad: Option<Triad>, what: &'static str, value: f64) -> Result<(), SceneError> {
    finite(triad, what, value)?;
    if value <= 0.0 {
        Err(SceneError::NotPositive { triad, what, value })
    } else {
        Ok(())
    }
}

fn all(
    triad: Option<Triad>,
    what: &'static str,
    values: &[f64],
    check: fn(Option<Triad>, &'static str, f64) -> Result<(), SceneError>,
) -> Result<(), SceneError> {
    values.iter().try_for_each(|&v| check(triad, what, v))
}

impl TriadEffects {
    /// Checks every named effect's parameters.
    pub fn validate(&self, triad: Triad) -> Result<(), SceneError> {
        let t = Some(triad);
        if let Some(n) = &self.white_noise {
            all(t, "white_noise density", n, non_negative)?;
        }
        if let Some(gm) = &self.gauss_markov {
            all(t, "gauss_markov sigma", &gm.sigma, non_negative)?;
            all(
                t,
                "gauss_markov correlation_time",
                &gm.correlation_time,
                positive,
            )?;
        }
        if let Some(k) = &self.random_walk {
            all(t, "random_walk coefficient", k, non_negative)?;
        }
        if let Some(bi) = &self.bias_instability {
            for p in bi {
                non_negative(t, "bias_instability", p.b)?;
                positive(t, "bias_instability tau_min", p.tau_min)?;
                positive(t, "bias_instability tau_max", p.tau_max)?;
                if p.tau_max < p.tau_min {
                    return Err(SceneError::BadBand {
                        tau_min: p.tau_min,
                        tau_max: p.tau_max,
                    });
                }
                if p.terms == 0 || p.terms as usize > MAX_TERMS {
                    return Err(SceneError::BadTermCount(p.terms));
                }
            }
        }
        if let Some(b) = &self.constant_bias {
            all(t, "bias", b, finite)?;
        }
        if let Some(s) = &self.turn_on_bias {
            all(t, "turn_on_bias", s, non_negative)?;
        }
        if let Some(m) = &self.scale_misalignment {
            all(t, "scale_misalignment", m.as_flattened(), finite)?;
        }
        if let Some(s) = &self.turn_on_scale {
            all(t, "turn_on_scale", s, non_negative)?;
        }
        if let Some(td) = &self.temperature {
            finite(t, "temperature reference", td.reference)?;
            all(
                t,
                "temperature bias coefficient",
                &td.bias_per_degree,
                finite,
            )?;
            all(
                t,
                "temperature scale coefficient",
                &td.scale_per_degree,
                finite,
            )?;
        }
        if let Some(g) = &self.g_sensitivity {
            if triad == Triad::Accel {
                return Err(SceneError::GSensitivityOnAccel);
            }
            all(t, "g_sensitivity", g.as_flattened(), finite)?;
        }
        self.validate_optics(triad)?;
        if let Some(q) = &self.increment_quantisation {
            all(t, "increment_quantisation", q, non_negative)?;
        }
        if let Some(q) = &self.output_lsb {
            all(t, "output_lsb", q, non_negative)?;
        }
        if let Some(r) = &self.saturation {
            all(t, "saturation", r, positive)?;
        }
        Ok(())
    }
}

impl TriadEffects {
    /// Checks the optical gyro models: gyros only, one at a time, each
    /// parameter in range.
    fn validate_optics(&self, triad: Triad) -> Result<(), SceneError> {
        let t = Some(triad);
        let optical = self.ring_laser.is_some() || self.fibre_optic.is_some();
        if optical && triad == Triad::Accel {
            return Err(SceneError::OpticalOnAccel);
        }
        if self.ring_laser.is_some() && self.fibre_optic.is_some() {
            return Err(SceneError::TwoOpticalModels);
        }
        if let Some(r) = &self.ring_laser {
            if self.increment_quantisation.is_some() {
                return Err(SceneError::CountedTwice);
            }
            positive(t, "ring_laser area", r.area)?;
            positive(t, "ring_laser path_length", r.path_length)?;
            positive(t, "ring_laser wavelength", r.wavelength)?;
            non_negative(t, "ring_laser lock_in", r.lock_in)?;
            if let Some(d) = &r.dither {
                positive(t, "ring_laser dither_rate", d.peak_rate)?;
                positive(t, "ring_laser dither_frequency", d.frequency)?;
            }
        }
        if let Some(f) = &self.fibre_optic {
            positive(t, "fibre_optic turns", f.turns)?;
            positive(t, "fibre_optic coil_area", f.coil_area)?;
            positive(t, "fibre_optic wavelength", f.wavelength)?;
            finite(t, "fibre_optic reference", f.reference)?;
            finite(t, "fibre_optic area_per_degree", f.area_per_degree)?;
            finite(
                t,
                "fibre_optic wavelength_per_degree",
                f.wavelength_per_degree,
            )?;
        }
        Ok(())
    }
}

impl Scene {
    /// Checks the whole scene.
    pub fn validate(&self) -> Result<(), SceneError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return Err(SceneError::BadRate(self.rate_hz));
        }
        positive(None, "gravity", self.environment.gravity)?;
        if let Some(lat) = self.environment.latitude {
            finite(None, "latitude", lat)?;
        }
        match self.motion {
            Motion::Static { attitude } => all(None, "attitude", &attitude, finite)?,
            Motion::RateTable { rate, .. } => finite(None, "table rate", rate)?,
            Motion::Tumble {
                positions,
                dwell,
                transition,
            } => {
                if !matches!(positions, 6 | 12 | 24) || positions as usize > MAX_POSITIONS {
                    return Err(SceneError::BadPositions(positions));
                }
                positive(None, "tumble dwell", dwell)?;
                non_negative(None, "tumble transition", transition)?;
            }
            Motion::Vibration {
                attitude,
                direction,
                amplitude,
                frequency,
            } => {
                all(None, "attitude", &attitude, finite)?;
                all(None, "vibration direction", &direction, finite)?;
                if direction == [0.0; 3] {
                    return Err(SceneError::ZeroDirection);
                }
                non_negative(None, "vibration amplitude", amplitude)?;
                non_negative(None, "vibration frequency", frequency)?;
            }
            Motion::Hand {
                poses, dwell, turn, ..
            } => {
                if !(MIN_HAND_POSES..=MAX_POSITIONS as u8).contains(&poses) {
                    return Err(SceneError::BadHandPoses(poses));
                }
                positive(None, "hand dwell", dwell)?;
                positive(None, "hand turn", turn)?;
            }
            Motion::RateTableSet { rate, run, rest } => {
                finite(None, "table rate", rate)?;
                positive(None, "rate-table run", run)?;
                non_negative(None, "rate-table rest", rest)?;
            }
        }
        match self.temperature {
            TemperatureProfile::Constant(c) => finite(None, "temperature", c)?,
            TemperatureProfile::Ramp {
                from,
                to,
                start,
                duration,
            } => {
                finite(None, "temperature from", from)?;
                finite(None, "temperature to", to)?;
                non_negative(None, "ramp start", start)?;
                non_negative(None, "ramp duration", duration)?;
            }
            TemperatureProfile::Soak {
                levels,
                count,
                hold,
            } => {
                if !(2..=MAX_SOAK_LEVELS as u8).contains(&count) {
                    return Err(SceneError::BadSoakCount(count));
                }
                all(None, "soak level", &levels[..count as usize], finite)?;
                positive(None, "soak hold", hold)?;
            }
        }
        self.accel.validate(Triad::Accel)?;
        self.gyro.validate(Triad::Gyro)
    }
}

impl core::fmt::Display for SceneError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let triad = |t: &Option<Triad>| match t {
            Some(Triad::Accel) => "accel ",
            Some(Triad::Gyro) => "gyro ",
            None => "",
        };
        match self {
            SceneError::BadRate(r) => write!(f, "sample rate {r} Hz is not a positive number"),
            SceneError::NotFinite { triad: t, what, value } => {
                write!(f, "{}{what} = {value} is not a finite number", triad(t))
            }
            SceneError::Negative { triad: t, what, value } => {
                write!(f, "{}{what} = {value} must not be negative", triad(t))
            }
            SceneError::NotPositive { triad: t, what, value } => {
                write!(f, "{}{what} = {value} must be positive", triad(t))
            }
            SceneError::BadTermCount(n) => {
                write!(f, "bias_instability terms = {n}: must be 1..={MAX_TERMS}")
            }
            SceneError::BadBand { tau_min, tau_max } => write!(
                f,
                "bias_instability band [{tau_min}, {tau_max}] s: the longest time is below the shortest"
            ),
            SceneError::BadPositions(n) => write!(f, "tumble positions = {n}: must be 6, 12 or 24"),
            SceneError::BadHandPoses(n) => write!(
                f,
                "hand poses = {n}: must be {MIN_HAND_POSES}..={MAX_POSITIONS}"
            ),
            SceneError::BadSoakCount(n) => {
                write!(f, "soak levels: {n} given, must be 2..={MAX_SOAK_LEVELS}")
            }
            SceneError::GSensitivityOnAccel => {
                write!(f, "g_sensitivity is a gyro effect; the accelerometers cannot have it")
            }
            SceneError::ZeroDirection => write!(f, "vibration direction is the zero vector"),
            SceneError::OpticalOnAccel => write!(
                f,
                "ring_laser and fibre_optic are gyro models; the accelerometers cannot have them"
            ),
            SceneError::TwoOpticalModels => {
                write!(f, "a gyro is a ring laser or a fibre-optic gyro, not both")
            }
            SceneError::CountedTwice => write!(
                f,
                "a ring laser gyro counts its fringes itself: increment_quantisation would count them twice"
            ),
        }
    }
}
