//! Where each value of a scene came from in its file, so that the
//! simulator's own check ([`Scene::validate`], which knows values but not
//! files) is reported at the value's `path:line:column`, worded as the
//! scene file's readers know it ("`white_noise` = \"-40 ug/sqrt(Hz)\" must
//! not be negative").
//!
//! A value is recorded under the name [`SceneError`] gives it (its `what`,
//! and its triad); an error no recorded value answers is reported as the
//! simulator words it.

use std::ops::Range;

use toml::Spanned;
use triad::model::Triad;
use triad_sim::scenes::scene::{Scene, SceneError};

use super::parse::{Source, Value};

/// The names [`SceneError`] gives the values a scene file sets (its `what`),
/// and this module's names for the errors that carry none.
pub(super) mod what {
    /// `rate_hz` ([`SceneError::BadRate`](super::SceneError::BadRate)).
    pub const RATE: &str = "sample rate";
    pub const GRAVITY: &str = "gravity";
    pub const LATITUDE: &str = "latitude";
    pub const ATTITUDE: &str = "attitude";
    pub const TABLE_RATE: &str = "table rate";
    /// Tumble `positions` ([`SceneError::BadPositions`](super::SceneError::BadPositions)).
    pub const POSITIONS: &str = "tumble positions";
    pub const DWELL: &str = "tumble dwell";
    pub const TRANSITION: &str = "tumble transition";
    /// Hand `poses` ([`SceneError::BadHandPoses`](super::SceneError::BadHandPoses)).
    pub const HAND_POSES: &str = "hand poses";
    pub const HAND_DWELL: &str = "hand dwell";
    pub const HAND_TURN: &str = "hand turn";
    pub const SET_RUN: &str = "rate-table run";
    pub const SET_REST: &str = "rate-table rest";
    pub const SOAK_LEVEL: &str = "soak level";
    pub const SOAK_HOLD: &str = "soak hold";
    pub const DIRECTION: &str = "vibration direction";
    pub const AMPLITUDE: &str = "vibration amplitude";
    pub const FREQUENCY: &str = "vibration frequency";
    pub const TEMPERATURE: &str = "temperature";
    pub const RAMP_FROM: &str = "temperature from";
    pub const RAMP_TO: &str = "temperature to";
    pub const RAMP_START: &str = "ramp start";
    pub const RAMP_DURATION: &str = "ramp duration";
    pub const WHITE_NOISE: &str = "white_noise density";
    pub const GM_SIGMA: &str = "gauss_markov sigma";
    pub const GM_TIME: &str = "gauss_markov correlation_time";
    pub const RANDOM_WALK: &str = "random_walk coefficient";
    pub const BIAS_INSTABILITY: &str = "bias_instability";
    pub const TAU_MIN: &str = "bias_instability tau_min";
    pub const TAU_MAX: &str = "bias_instability tau_max";
    /// `band_s` ([`SceneError::BadBand`](super::SceneError::BadBand)).
    pub const BAND: &str = "bias_instability band";
    /// `terms` ([`SceneError::BadTermCount`](super::SceneError::BadTermCount)).
    pub const TERMS: &str = "bias_instability terms";
    pub const BIAS: &str = "bias";
    pub const TURN_ON_BIAS: &str = "turn_on_bias";
    pub const TURN_ON_SCALE: &str = "turn_on_scale";
    pub const G_SENSITIVITY: &str = "g_sensitivity";
    pub const INCREMENT_QUANTISATION: &str = "increment_quantisation";
    pub const OUTPUT_LSB: &str = "output_lsb";
    pub const SATURATION: &str = "saturation";
    pub const TEMPERATURE_REFERENCE: &str = "temperature reference";
    /// The optical gyro models as a whole.
    pub const OPTICS: &str = "optics";
    pub const RL_AREA: &str = "ring_laser area";
    pub const RL_PATH: &str = "ring_laser path_length";
    pub const RL_WAVELENGTH: &str = "ring_laser wavelength";
    pub const RL_LOCK_IN: &str = "ring_laser lock_in";
    pub const RL_DITHER_RATE: &str = "ring_laser dither_rate";
    pub const RL_DITHER_FREQUENCY: &str = "ring_laser dither_frequency";
    pub const FO_TURNS: &str = "fibre_optic turns";
    pub const FO_WAVELENGTH: &str = "fibre_optic wavelength";
    pub const FO_REFERENCE: &str = "fibre_optic reference";
}

/// A value as [`SceneError`] names it: its triad (None: the scene's own) and its `what`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Key {
    pub triad: Option<Triad>,
    pub what: &'static str,
}

impl Key {
    /// A value of the scene itself (motion, environment, temperature).
    pub fn scene(what: &'static str) -> Key {
        Key { triad: None, what }
    }

    /// A value of a triad's effects.
    pub fn triad(triad: Triad, what: &'static str) -> Key {
        Key {
            triad: Some(triad),
            what,
        }
    }
}

/// How the scene file's errors word a value.
#[derive(Clone, Debug, PartialEq)]
enum Says {
    /// A quantity with its unit: "`name` = "-1 mg" must not be negative";
    /// when zero where it must be positive, `not_positive`.
    Quantity { not_positive: Option<String> },
    /// A plain number: "`name` = x is not a finite number", "… must not be
    /// negative", "… must be positive".
    Number,
    /// One message, whatever is wrong.
    Fixed(String),
}

/// Where one value came from and how its errors are worded.
#[derive(Clone, Debug)]
struct Origin {
    key: Key,
    span: Range<usize>,
    name: &'static str,
    /// The value(s) in SI units, per axis where the field has three.
    values: Vec<f64>,
    /// The value(s) as written, per axis.
    shown: Vec<String>,
    says: Says,
}

/// What the simulator found wrong with a value.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Problem {
    NotFinite(f64),
    Negative(f64),
    NotPositive(f64),
    /// A count, a band or a vector that is wrong as a whole.
    Other(f64),
}

/// The origins of a scene's values, in the order they were read.
#[derive(Debug, Default)]
pub(super) struct Origins {
    list: Vec<Origin>,
}

/// The values as written, per axis: an array's items, else the value for all three.
fn shown_per_axis(v: &Value) -> Vec<String> {
    match v.get_ref() {
        toml::Value::Array(items) => items.iter().map(ToString::to_string).collect(),
        one => vec![one.to_string(); 3],
    }
}

impl Origins {
    /// A quantity field `name` read from `v` as `si` (one value per axis, or one).
    pub fn quantity(&mut self, key: Key, v: &Value, name: &'static str, si: &[f64]) {
        self.push_quantity(key, v, name, si, None);
    }

    /// A quantity that must be positive: `not_positive` is the message when it is zero.
    pub fn positive_quantity(
        &mut self,
        key: Key,
        v: &Value,
        name: &'static str,
        si: &[f64],
        not_positive: String,
    ) {
        self.push_quantity(key, v, name, si, Some(not_positive));
    }

    fn push_quantity(
        &mut self,
        key: Key,
        v: &Value,
        name: &'static str,
        si: &[f64],
        not_positive: Option<String>,
    ) {
        let shown = if si.len() == 1 {
            vec![v.get_ref().to_string()]
        } else {
            shown_per_axis(v)
        };
        self.list.push(Origin {
            key,
            span: v.span(),
            name,
            values: si.to_vec(),
            shown,
            says: Says::Quantity { not_positive },
        });
    }

    /// A plain number field `name` read from `v` (the simulator may hold it
    /// converted: `si`).
    pub fn number(&mut self, key: Key, v: &Spanned<f64>, name: &'static str, si: f64) {
        self.list.push(Origin {
            key,
            span: v.span(),
            name,
            values: vec![si],
            shown: vec![v.get_ref().to_string()],
            says: Says::Number,
        });
    }

    /// A value at `span` whose every error is `message`; `values` tell which
    /// triad's value an error without a triad is about.
    pub fn fixed(&mut self, key: Key, span: Range<usize>, values: &[f64], message: String) {
        self.list.push(Origin {
            key,
            span,
            name: "",
            values: values.to_vec(),
            shown: Vec::new(),
            says: Says::Fixed(message),
        });
    }

    /// Checks `scene` as the simulator does; its error at the file position
    /// of the value at fault, else (a value no origin answers) as it words it.
    pub fn validate(&self, src: &Source, scene: &Scene) -> anyhow::Result<()> {
        scene.validate().map_err(|e| match self.message(&e) {
            Some((span, message)) => src.error(&span, message),
            None => anyhow::anyhow!("{}: {e}", src.path.display()),
        })
    }

    /// The span and the words of `e`, if a recorded value answers it.
    fn message(&self, e: &SceneError) -> Option<(Range<usize>, String)> {
        let (triad, what, problem) = classify(e);
        let origin = self.list.iter().find(|o| {
            o.key.what == what
                && triad.is_none_or(|t| o.key.triad == t)
                && (triad.is_some() || o.values.contains(&problem.value()))
        })?;
        Some((origin.span.clone(), origin.words(problem)?))
    }
}

impl Problem {
    fn value(self) -> f64 {
        match self {
            Problem::NotFinite(v) | Problem::Negative(v) | Problem::NotPositive(v) => v,
            Problem::Other(v) => v,
        }
    }
}

/// The value an error is about: its triad (Some(None): the scene's own;
/// None: not said, told by the value), its `what`, and the problem.
fn classify(e: &SceneError) -> (Option<Option<Triad>>, &'static str, Problem) {
    let known = |t: &Option<Triad>| Some(*t);
    match *e {
        SceneError::BadRate(r) if r.is_finite() => {
            (Some(None), what::RATE, Problem::NotPositive(r))
        }
        SceneError::BadRate(r) => (Some(None), what::RATE, Problem::NotFinite(r)),
        SceneError::NotFinite { triad, what, value } => {
            (known(&triad), what, Problem::NotFinite(value))
        }
        SceneError::Negative { triad, what, value } => {
            (known(&triad), what, Problem::Negative(value))
        }
        SceneError::NotPositive { triad, what, value } => {
            (known(&triad), what, Problem::NotPositive(value))
        }
        SceneError::BadTermCount(n) => (None, what::TERMS, Problem::Other(f64::from(n))),
        SceneError::BadBand { tau_min, .. } => (None, what::BAND, Problem::Other(tau_min)),
        SceneError::BadPositions(n) => (Some(None), what::POSITIONS, Problem::Other(f64::from(n))),
        SceneError::BadHandPoses(n) => (Some(None), what::HAND_POSES, Problem::Other(f64::from(n))),
        // The file's soak count is checked where it is read (build.rs).
        SceneError::BadSoakCount(n) => (Some(None), what::SOAK_LEVEL, Problem::Other(f64::from(n))),
        SceneError::GSensitivityOnAccel => (
            Some(Some(Triad::Accel)),
            what::G_SENSITIVITY,
            Problem::Other(f64::NAN),
        ),
        SceneError::ZeroDirection => (Some(None), what::DIRECTION, Problem::Other(0.0)),
        SceneError::OpticalOnAccel => (
            Some(Some(Triad::Accel)),
            what::OPTICS,
            Problem::Other(f64::NAN),
        ),
        SceneError::TwoOpticalModels | SceneError::CountedTwice => (
            Some(Some(Triad::Gyro)),
            what::OPTICS,
            Problem::Other(f64::NAN),
        ),
    }
}

impl Origin {
    /// The words of `problem` with this value; None where they would be a guess.
    fn words(&self, problem: Problem) -> Option<String> {
        let name = self.name;
        let shown = self.shown.first();
        Some(match (&self.says, problem) {
            (Says::Fixed(message), _) => message.clone(),
            (Says::Number, Problem::NotFinite(_)) => {
                format!("`{name}` = {} is not a finite number", shown?)
            }
            (Says::Number, Problem::Negative(_)) => {
                format!("`{name}` = {} must not be negative", shown?)
            }
            (Says::Number, Problem::NotPositive(_)) => {
                format!("`{name}` = {} must be positive", shown?)
            }
            (Says::Quantity { .. }, Problem::NotFinite(_)) => {
                format!("`{name}` is not a finite number")
            }
            (Says::Quantity { not_positive }, Problem::Negative(_) | Problem::NotPositive(_)) => {
                match self.first_negative() {
                    Some(shown) => format!("`{name}` = {shown} must not be negative"),
                    None => not_positive.clone()?,
                }
            }
            (_, Problem::Other(_)) => return None,
        })
    }

    /// The first axis written negative, as written.
    fn first_negative(&self) -> Option<&String> {
        self.values
            .iter()
            .zip(&self.shown)
            .find(|(v, _)| **v < 0.0)
            .map(|(_, s)| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(text: &str, span: Range<usize>) -> Value {
        let doc: toml::Table = toml::from_str(&format!("v = {text}")).unwrap();
        Spanned::new(span, doc["v"].clone())
    }

    fn triad_error(
        make: fn(Option<Triad>, &'static str, f64) -> SceneError,
        triad: Triad,
        what: &'static str,
        value: f64,
    ) -> SceneError {
        make(Some(triad), what, value)
    }

    fn negative(triad: Option<Triad>, what: &'static str, value: f64) -> SceneError {
        SceneError::Negative { triad, what, value }
    }

    fn not_positive(triad: Option<Triad>, what: &'static str, value: f64) -> SceneError {
        SceneError::NotPositive { triad, what, value }
    }

    fn not_finite(triad: Option<Triad>, what: &'static str, value: f64) -> SceneError {
        SceneError::NotFinite { triad, what, value }
    }

    fn words(o: &Origins, e: SceneError) -> Option<String> {
        o.message(&e).map(|(_, m)| m)
    }

    #[test]
    fn a_negative_axis_is_named_as_written() {
        let mut o = Origins::default();
        let v = value("[\"1 mg\", \"-2 mg\", \"-3 mg\"]", 7..9);
        o.quantity(
            Key::triad(Triad::Accel, what::BIAS),
            &v,
            "bias",
            &[1.0, -2.0, -3.0],
        );
        let e = triad_error(negative, Triad::Accel, what::BIAS, -2.0);
        assert_eq!(
            o.message(&e),
            Some((7..9, "`bias` = \"-2 mg\" must not be negative".to_string()))
        );
        // The other triad's value is not this one.
        let e = triad_error(negative, Triad::Gyro, what::BIAS, -2.0);
        assert_eq!(o.message(&e), None);
    }

    #[test]
    fn zero_where_positive_is_needed_has_its_own_words_unless_an_axis_is_negative() {
        let mut o = Origins::default();
        let key = Key::triad(Triad::Gyro, what::SATURATION);
        let zero = value("[\"1 dps\", \"0 dps\", \"2 dps\"]", 0..1);
        o.positive_quantity(key, &zero, "saturation", &[1.0, 0.0, 2.0], "zero!".into());
        let e = triad_error(not_positive, Triad::Gyro, what::SATURATION, 0.0);
        assert_eq!(words(&o, e).as_deref(), Some("zero!"));
        let mut o = Origins::default();
        let both = value("[\"0 dps\", \"-1 dps\", \"2 dps\"]", 0..1);
        o.positive_quantity(key, &both, "saturation", &[0.0, -1.0, 2.0], "zero!".into());
        // The simulator stops at the zero; the file's readers are told of the negative axis.
        assert_eq!(
            words(&o, e).as_deref(),
            Some("`saturation` = \"-1 dps\" must not be negative")
        );
    }

    #[test]
    fn plain_numbers_are_shown_as_written() {
        let mut o = Origins::default();
        let lat = Spanned::new(3..5, f64::NAN);
        o.number(Key::scene(what::LATITUDE), &lat, "latitude_deg", f64::NAN);
        let rate = Spanned::new(0..1, -5.0);
        o.number(Key::scene(what::RATE), &rate, "rate_hz", -5.0);
        let e = not_finite(None, what::LATITUDE, f64::NAN);
        assert_eq!(
            o.message(&e),
            Some((3..5, "`latitude_deg` = NaN is not a finite number".into()))
        );
        assert_eq!(
            words(&o, SceneError::BadRate(-5.0)).as_deref(),
            Some("`rate_hz` = -5 must be positive")
        );
        assert_eq!(
            words(&o, SceneError::BadRate(f64::INFINITY)).as_deref(),
            Some("`rate_hz` = -5 is not a finite number")
        );
    }

    #[test]
    fn errors_without_a_triad_are_told_by_their_value() {
        let mut o = Origins::default();
        o.fixed(
            Key::triad(Triad::Accel, what::TERMS),
            10..11,
            &[4.0],
            "accel".into(),
        );
        o.fixed(
            Key::triad(Triad::Gyro, what::TERMS),
            20..21,
            &[0.0],
            "gyro".into(),
        );
        assert_eq!(
            o.message(&SceneError::BadTermCount(0)),
            Some((20..21, "gyro".into()))
        );
        assert_eq!(o.message(&SceneError::BadTermCount(9)), None);
    }

    #[test]
    fn an_error_no_value_answers_keeps_the_simulators_words() {
        let o = Origins::default();
        let src = Source {
            path: std::path::Path::new("s.toml"),
            text: "",
        };
        let mut scene = Scene::new(
            0.0,
            triad_sim::motion::Motion::Static { attitude: [0.0; 3] },
        );
        let err = o.validate(&src, &scene).unwrap_err().to_string();
        assert_eq!(err, format!("s.toml: {}", SceneError::BadRate(0.0)));
        scene.rate_hz = 10.0;
        assert!(o.validate(&src, &scene).is_ok());
    }
}
