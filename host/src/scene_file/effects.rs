//! `[accel]`, `[gyro]` → [`TriadEffects`]: a grade preset, then each effect
//! the file names (overriding the preset's), in the triad's units.

use triad::model::Triad;
use triad_sim::effects::bias_instability::{BiasInstabilityParams, MAX_TERMS};
use triad_sim::effects::temperature_dependence::TemperatureDependence;
use triad_sim::grade::{AccelPreset, GyroPreset};
use triad_sim::scenes::scene::{GaussMarkovParams, TriadEffects};

use super::build::Builder;
use super::field::{field, Field};
use super::origin::{what, Key};
use super::parse::{
    BiasInstabilityFile, GaussMarkovFile, TemperatureDependenceFile, TriadFile, Value,
};
use super::unit::Dim;

/// A triad's units: its dimension and examples of its units, of its noise
/// densities and of its random walks (shown when a unit is wrong).
#[derive(Clone, Copy, Debug)]
struct Units {
    dim: Dim,
    example: &'static str,
    density: &'static str,
    random_walk: &'static str,
}

fn units(triad: Triad) -> Units {
    match triad {
        Triad::Accel => Units {
            dim: Dim::ACCEL,
            example: "mg, ug, m/s^2",
            density: "ug/sqrt(Hz), m/s/sqrt(h)",
            random_walk: "m/s/h/sqrt(h), ug/sqrt(s)",
        },
        Triad::Gyro => Units {
            dim: Dim::RATE,
            example: "deg/h, deg/s, rad/s",
            density: "deg/sqrt(h), deg/s/sqrt(Hz)",
            random_walk: "deg/h/sqrt(h), deg/s/sqrt(s)",
        },
    }
}

/// The effects of the grade preset `name` of `triad`, if there is one.
fn preset(triad: Triad, name: &str) -> Option<TriadEffects> {
    match triad {
        Triad::Accel => AccelPreset::named(name).map(AccelPreset::effects),
        Triad::Gyro => GyroPreset::named(name).map(GyroPreset::effects),
    }
}

/// The names of `triad`'s grades.
fn grade_names(triad: Triad) -> Vec<&'static str> {
    match triad {
        Triad::Accel => AccelPreset::ALL.iter().map(|p| p.name).collect(),
        Triad::Gyro => GyroPreset::ALL.iter().map(|p| p.name).collect(),
    }
}

impl Builder<'_> {
    /// The effects of `[accel]` or `[gyro]`.
    pub(super) fn effects(&mut self, t: &TriadFile, triad: Triad) -> anyhow::Result<TriadEffects> {
        if let Some(v) = &t.turn_on_misalignment {
            return Err(self.src.error(
                &v.span(),
                "`turn_on_misalignment` is a unit file's key (drawn once from the unit's seed): \
                 a scene draws no misalignment; give it in --unit UNIT.toml",
            ));
        }
        let mut e = self.grade(t, triad)?;
        self.noise(t, triad, &mut e)?;
        self.scale_misalignment(t, &mut e)?;
        self.g_sensitivity(t, triad, &mut e)?;
        self.optics(t, triad, &mut e)?;
        self.range(t, triad, &mut e)?;
        if let Some(gm) = &t.gauss_markov {
            e.gauss_markov = Some(self.gauss_markov(gm, triad)?);
        }
        if let Some(bi) = &t.bias_instability {
            e.bias_instability = Some(self.bias_instability(bi, triad)?);
        }
        if let Some(td) = &t.temperature {
            e.temperature = Some(self.temperature_dependence(td, triad)?);
        }
        Ok(e)
    }

    /// The grade's effects (none without a grade).
    fn grade(&self, t: &TriadFile, triad: Triad) -> anyhow::Result<TriadEffects> {
        let Some(g) = &t.grade else {
            return Ok(TriadEffects::NONE);
        };
        let name = g.get_ref().as_str();
        preset(triad, name).ok_or_else(|| {
            self.src.error(
                &g.span(),
                format!(
                    "unknown {} grade \"{name}\" (expected {})",
                    triad.name(),
                    grade_names(triad).join(", ")
                ),
            )
        })
    }

    /// A per-axis quantity of `triad`, recorded as the simulator's `what`.
    fn axes(
        &mut self,
        v: &Value,
        f: Field,
        triad: Triad,
        what: &'static str,
    ) -> anyhow::Result<[f64; 3]> {
        let x = self.src.per_axis(v, f)?;
        self.origins
            .quantity(Key::triad(triad, what), v, f.name, &x);
        Ok(x)
    }

    /// White noise, random walk, constant and turn-on biases, turn-on scale.
    fn noise(&mut self, t: &TriadFile, triad: Triad, e: &mut TriadEffects) -> anyhow::Result<()> {
        let u = units(triad);
        let (q, ex) = (u.dim, u.example);
        let fields = [
            (
                &t.white_noise,
                field("white_noise", q.per_sqrt_hz(), u.density),
                what::WHITE_NOISE,
            ),
            (
                &t.random_walk,
                field("random_walk", q.per_sqrt_s(), u.random_walk),
                what::RANDOM_WALK,
            ),
            (&t.bias, field("bias", q, ex), what::BIAS),
            (
                &t.turn_on_bias,
                field("turn_on_bias", q, ex),
                what::TURN_ON_BIAS,
            ),
            (
                &t.turn_on_scale,
                field("turn_on_scale", Dim::ONE, "ppm, %"),
                what::TURN_ON_SCALE,
            ),
        ];
        let mut read = [None; 5];
        for ((v, f, what), out) in fields.into_iter().zip(&mut read) {
            if let Some(v) = v {
                *out = Some(self.axes(v, f, triad, what)?);
            }
        }
        let [white_noise, random_walk, bias, turn_on_bias, turn_on_scale] = read;
        e.white_noise = white_noise.or(e.white_noise);
        e.random_walk = random_walk.or(e.random_walk);
        e.constant_bias = bias.or(e.constant_bias);
        e.turn_on_bias = turn_on_bias.or(e.turn_on_bias);
        e.turn_on_scale = turn_on_scale.or(e.turn_on_scale);
        Ok(())
    }

    /// Σ of (I+Σ): `scale_factor` on the diagonal, `misalignment` off it.
    fn scale_misalignment(&mut self, t: &TriadFile, e: &mut TriadEffects) -> anyhow::Result<()> {
        if t.scale_factor.is_none() && t.misalignment.is_none() {
            return Ok(());
        }
        let mut sigma = [[0.0; 3]; 3];
        if let Some(v) = &t.misalignment {
            let m = self
                .src
                .matrix(v, field("misalignment", Dim::ONE, "mrad, deg, ppm"))?;
            if (0..3).any(|i| m[i][i] != 0.0) {
                return Err(self.src.error(
                    &v.span(),
                    "`misalignment` must have a zero diagonal (scale factors go in `scale_factor`)",
                ));
            }
            sigma = m;
        }
        if let Some(v) = &t.scale_factor {
            let s = self
                .src
                .per_axis(v, field("scale_factor", Dim::ONE, "ppm, %"))?;
            for (i, si) in s.into_iter().enumerate() {
                sigma[i][i] = si;
            }
        }
        e.scale_misalignment = Some(sigma);
        Ok(())
    }

    /// The gyro's g-sensitivity (the simulator refuses the accelerometer's).
    fn g_sensitivity(
        &mut self,
        t: &TriadFile,
        triad: Triad,
        e: &mut TriadEffects,
    ) -> anyhow::Result<()> {
        let Some(v) = &t.g_sensitivity else {
            return Ok(());
        };
        let f = field(
            "g_sensitivity",
            Dim::RATE.div(Dim::ACCEL),
            "deg/s/g, deg/h/g",
        );
        let g = self.src.matrix(v, f)?;
        if triad == Triad::Accel {
            // What the simulator's refusal says in this file's words.
            let message = "`g_sensitivity` is a gyro effect; accelerometers cannot have it";
            let key = Key::triad(triad, what::G_SENSITIVITY);
            self.origins
                .fixed(key, v.span(), g.as_flattened(), message.to_string());
        }
        e.g_sensitivity = Some(g);
        Ok(())
    }

    /// Angle or velocity quantisation, the output register's LSB and the
    /// measurement range.
    fn range(&mut self, t: &TriadFile, triad: Triad, e: &mut TriadEffects) -> anyhow::Result<()> {
        let u = units(triad);
        let (key, other, step) = match triad {
            Triad::Gyro => (
                &t.angle_quantisation,
                &t.velocity_quantisation,
                (
                    "angle_quantisation",
                    "arcsec, urad",
                    "velocity_quantisation",
                ),
            ),
            Triad::Accel => (
                &t.velocity_quantisation,
                &t.angle_quantisation,
                ("velocity_quantisation", "mm/s, m/s", "angle_quantisation"),
            ),
        };
        if let Some(v) = other {
            return Err(self.src.error(
                &v.span(),
                format!(
                    "`{}` is not a {} key: its integral is quantised by `{}`",
                    step.2,
                    triad.name(),
                    step.0
                ),
            ));
        }
        if let (Some(v), Some(_)) = (key, e.ring_laser) {
            return Err(self.src.error(
                &v.span(),
                format!(
                    "`{}`: this grade's ring laser counts its fringes itself (at Lλ/4A)",
                    step.0
                ),
            ));
        }
        if let Some(v) = key {
            let f = field(step.0, u.dim.mul(Dim::TIME), step.1);
            e.increment_quantisation =
                Some(self.axes(v, f, triad, what::INCREMENT_QUANTISATION)?);
        }
        let lsb = match (&t.output_lsb, &t.quantisation) {
            (Some(_), Some(old)) => {
                return Err(self.src.error(
                    &old.span(),
                    "`quantisation` is the old name of `output_lsb`: give one of them",
                ))
            }
            (Some(v), None) => Some((v, "output_lsb")),
            (None, Some(v)) => Some((v, "quantisation")),
            (None, None) => None,
        };
        if let Some((v, name)) = lsb {
            let f = field(name, u.dim, u.example);
            e.output_lsb = Some(self.axes(v, f, triad, what::OUTPUT_LSB)?);
        }
        if let Some(v) = &t.saturation {
            let r = self
                .src
                .per_axis(v, field("saturation", u.dim, u.example))?;
            let message = "`saturation` (the measurement range) must be positive".to_string();
            let key = Key::triad(triad, what::SATURATION);
            self.origins
                .positive_quantity(key, v, "saturation", &r, message);
            e.saturation = Some(r);
        }
        Ok(())
    }

    fn gauss_markov(
        &mut self,
        gm: &GaussMarkovFile,
        triad: Triad,
    ) -> anyhow::Result<GaussMarkovParams> {
        let u = units(triad);
        let f = field("gauss_markov.sigma", u.dim, u.example);
        let sigma = self.axes(&gm.sigma, f, triad, what::GM_SIGMA)?;
        let name = "gauss_markov.correlation_time";
        let f = field(name, Dim::TIME, "s, min, h");
        let tc = self.src.per_axis(&gm.correlation_time, f)?;
        let message = "`correlation_time` must be positive".to_string();
        let key = Key::triad(triad, what::GM_TIME);
        self.origins
            .positive_quantity(key, &gm.correlation_time, name, &tc, message);
        Ok(GaussMarkovParams {
            sigma,
            correlation_time: tc,
        })
    }

    fn bias_instability(
        &mut self,
        bi: &BiasInstabilityFile,
        triad: Triad,
    ) -> anyhow::Result<[BiasInstabilityParams; 3]> {
        let u = units(triad);
        let f = field("bias_instability.value", u.dim, u.example);
        let b = self.axes(&bi.value, f, triad, what::BIAS_INSTABILITY)?;
        let mut p = BiasInstabilityParams::with_default_band(0.0);
        if let Some(band) = &bi.band_s {
            let [lo, hi] = *band.get_ref();
            let message = format!("band_s = [{lo}, {hi}]: need 0 < shortest ≤ longest (seconds)");
            for what in [what::BAND, what::TAU_MIN, what::TAU_MAX] {
                let key = Key::triad(triad, what);
                self.origins
                    .fixed(key, band.span(), &[lo, hi], message.clone());
            }
            (p.tau_min, p.tau_max) = (lo, hi);
        }
        if let Some(n) = &bi.terms {
            p.terms = *n.get_ref();
            let message = format!("terms = {}: expected 1..={MAX_TERMS}", p.terms);
            let key = Key::triad(triad, what::TERMS);
            self.origins
                .fixed(key, n.span(), &[f64::from(p.terms)], message);
        }
        Ok(b.map(|b| BiasInstabilityParams { b, ..p }))
    }

    fn temperature_dependence(
        &mut self,
        td: &TemperatureDependenceFile,
        triad: Triad,
    ) -> anyhow::Result<TemperatureDependence> {
        let reference = *td.reference_c.get_ref();
        let key = Key::triad(triad, what::TEMPERATURE_REFERENCE);
        self.origins
            .number(key, &td.reference_c, "reference_c", reference);
        let per_degree = |v: &Option<Value>, f: Field| match v {
            Some(v) => self.src.per_axis(v, f),
            None => Ok([0.0; 3]),
        };
        let u = units(triad);
        let bias = field(
            "temperature.bias",
            u.dim.per_kelvin(),
            "ug/degC, deg/h/degC",
        );
        let scale = field("temperature.scale", Dim::ONE.per_kelvin(), "ppm/degC");
        Ok(TemperatureDependence {
            reference,
            bias_per_degree: per_degree(&td.bias, bias)?,
            scale_per_degree: per_degree(&td.scale, scale)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_and_grade_names_follow_the_triad() {
        assert!(preset(Triad::Gyro, "rate-grade").is_some());
        assert!(preset(Triad::Accel, "rate-grade").is_none());
        assert!(preset(Triad::Accel, "automotive").is_some());
        assert_eq!(
            grade_names(Triad::Accel),
            ["automotive", "tactical", "navigation"]
        );
        assert_eq!(grade_names(Triad::Gyro).len(), 8);
        assert!(preset(Triad::Gyro, "navigation-rlg").is_some_and(|e| e.ring_laser.is_some()));
        assert!(preset(Triad::Accel, "aviation-fog").is_none());
    }

    #[test]
    fn the_units_follow_the_triad() {
        assert_eq!(units(Triad::Gyro).dim, Dim::RATE);
        assert_eq!(units(Triad::Accel).dim, Dim::ACCEL);
        assert!(units(Triad::Gyro).density.starts_with("deg/sqrt(h)"));
        assert!(units(Triad::Accel).random_walk.starts_with("m/s/h/sqrt(h)"));
    }
}
