//! Fields → [`Scene`]: each value converted to SI (its unit checked) and
//! recorded where it came from, then the scene checked as the simulator
//! checks it, its errors at the file's positions ([`origin`](super::origin)).
//! Only what is about the file itself is checked here: which fields a kind
//! takes, names (kinds, axes, grades), units, and the latitude's range.

use anyhow::bail;
use toml::Spanned;
use triad::model::Triad;
use triad::units::{deg_to_rad, STANDARD_GRAVITY};
use triad_sim::motion::Environment;
use triad_sim::scenes::scene::{Scene, TriadEffects};
use triad_sim::scenes::temperature_profile::{TemperatureProfile, MAX_SOAK_LEVELS};

use super::field::field;
use super::origin::{what, Key, Origins};
use super::parse::{SceneFile, Source, TemperatureFile};
use super::unit::Dim;

/// Reads a scene's fields into a scene, remembering where each value came from.
pub(super) struct Builder<'a> {
    pub src: Source<'a>,
    pub origins: Origins,
}

impl<'a> Builder<'a> {
    /// A builder over the file `src`.
    pub fn new(src: Source<'a>) -> Self {
        Builder {
            src,
            origins: Origins::default(),
        }
    }

    /// The scene of `file`, checked.
    pub fn scene(&mut self, file: &SceneFile) -> anyhow::Result<Scene> {
        let rate_hz = *file.rate_hz.get_ref();
        self.origins
            .number(Key::scene(what::RATE), &file.rate_hz, "rate_hz", rate_hz);
        let scene = Scene {
            rate_hz,
            environment: self.environment(file)?,
            motion: self.motion(&file.motion)?,
            temperature: match &file.temperature {
                Some(t) => self.temperature(t)?,
                None => TemperatureProfile::Constant(25.0),
            },
            accel: self.triad_or_none(file.accel.as_ref(), Triad::Accel)?,
            gyro: self.triad_or_none(file.gyro.as_ref(), Triad::Gyro)?,
        };
        self.origins.validate(&self.src, &scene)?;
        Ok(scene)
    }

    /// The file's default length, `duration_s`, if any.
    pub fn duration(&self, file: &SceneFile) -> anyhow::Result<Option<f64>> {
        file.duration_s
            .as_ref()
            .map(|d| self.src.positive(d, "duration_s"))
            .transpose()
    }

    pub(super) fn triad_or_none(
        &mut self,
        t: Option<&super::parse::TriadFile>,
        triad: Triad,
    ) -> anyhow::Result<TriadEffects> {
        match t {
            Some(t) => self.effects(t, triad),
            None => Ok(TriadEffects::NONE),
        }
    }

    /// Gravity (default standard) and the latitude (the Earth rate, when given).
    fn environment(&mut self, file: &SceneFile) -> anyhow::Result<Environment> {
        let gravity = match &file.gravity {
            Some(g) => {
                let f = field("gravity", Dim::ACCEL, "m/s^2, g");
                let x = self.src.quantity(g, f)?;
                let not_positive = "gravity must be positive".to_string();
                let key = Key::scene(what::GRAVITY);
                self.origins
                    .positive_quantity(key, g, "gravity", &[x], not_positive);
                x
            }
            None => STANDARD_GRAVITY,
        };
        let latitude = file
            .latitude_deg
            .as_ref()
            .map(|l| self.latitude(l))
            .transpose()?;
        Ok(Environment { gravity, latitude })
    }

    /// The latitude in radians; within ±90° (when finite: the simulator
    /// refuses the others).
    fn latitude(&mut self, l: &Spanned<f64>) -> anyhow::Result<f64> {
        let x = *l.get_ref();
        if x.is_finite() && x.abs() > 90.0 {
            bail!(self
                .src
                .error(&l.span(), format!("latitude_deg = {x} is outside −90..90")));
        }
        let rad = deg_to_rad(x);
        self.origins
            .number(Key::scene(what::LATITUDE), l, "latitude_deg", rad);
        Ok(rad)
    }

    /// `[temperature]`: constant or a ramp.
    fn temperature(&mut self, t: &TemperatureFile) -> anyhow::Result<TemperatureProfile> {
        match t.kind.get_ref().as_str() {
            "constant" => Ok(TemperatureProfile::Constant(self.temperature_number(
                t,
                &t.celsius,
                "celsius",
                what::TEMPERATURE,
            )?)),
            "ramp" => Ok(TemperatureProfile::Ramp {
                from: self.temperature_number(t, &t.from_c, "from_c", what::RAMP_FROM)?,
                to: self.temperature_number(t, &t.to_c, "to_c", what::RAMP_TO)?,
                start: match &t.start_s {
                    Some(s) => self.number(s, "start_s", what::RAMP_START),
                    None => 0.0,
                },
                duration: self.temperature_number(
                    t,
                    &t.duration_s,
                    "duration_s",
                    what::RAMP_DURATION,
                )?,
            }),
            "soak" => self.soak(t),
            other => Err(self.src.error(
                &t.kind.span(),
                format!("unknown temperature kind \"{other}\" (expected constant, ramp or soak)"),
            )),
        }
    }

    /// `soak`: `levels_c` (2 to 4 temperatures), each held `hold_s`.
    fn soak(&mut self, t: &TemperatureFile) -> anyhow::Result<TemperatureProfile> {
        let l = t.levels_c.as_ref().ok_or_else(|| {
            self.src
                .error(&t.kind.span(), "temperature kind \"soak\" needs `levels_c`")
        })?;
        let given = l.get_ref();
        if !(2..=MAX_SOAK_LEVELS).contains(&given.len()) {
            bail!(self.src.error(
                &l.span(),
                format!(
                    "levels_c has {} temperatures: a soak has 2..={MAX_SOAK_LEVELS}",
                    given.len()
                )
            ));
        }
        let mut levels = [0.0; MAX_SOAK_LEVELS];
        levels[..given.len()].copy_from_slice(given);
        let message = "`levels_c` must be finite temperatures".to_string();
        self.origins
            .fixed(Key::scene(what::SOAK_LEVEL), l.span(), given, message);
        Ok(TemperatureProfile::Soak {
            levels,
            count: given.len() as u8,
            hold: self.temperature_number(t, &t.hold_s, "hold_s", what::SOAK_HOLD)?,
        })
    }

    /// A number the temperature's kind needs.
    fn temperature_number(
        &mut self,
        t: &TemperatureFile,
        v: &Option<Spanned<f64>>,
        name: &'static str,
        what: &'static str,
    ) -> anyhow::Result<f64> {
        let v = v.as_ref().ok_or_else(|| {
            self.src.error(
                &t.kind.span(),
                format!("temperature kind \"{}\" needs `{name}`", t.kind.get_ref()),
            )
        })?;
        Ok(self.number(v, name, what))
    }

    /// A plain number of the scene itself, as written.
    pub fn number(&mut self, v: &Spanned<f64>, name: &'static str, what: &'static str) -> f64 {
        let x = *v.get_ref();
        self.origins.number(Key::scene(what), v, name, x);
        x
    }
}
