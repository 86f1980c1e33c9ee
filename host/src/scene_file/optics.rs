//! `[gyro.ring_laser]`, `[gyro.fibre_optic]` → an optical gyro's optics
//! ([`RingLaserParams`], [`FibreOpticParams`]), replacing a preset's: the
//! cavity, lock-in and dither of a ring laser (no `dither_*` keys: an
//! undithered one, locked below `lock_in`); the coil, source and readout
//! (`open` or `closed` loop) of a fibre-optic gyro.

use triad::model::Triad;
use triad_sim::optics::fibre_optic::{FibreOpticParams, Loop};
use triad_sim::optics::ring_laser::{Dither, RingLaserParams};
use triad_sim::scenes::scene::TriadEffects;

use super::build::Builder;
use super::field::field;
use super::origin::{what, Key};
use super::parse::{FibreOpticFile, RingLaserFile, TriadFile, Value};
use super::unit::Dim;

/// A ring laser's wavelength when the file gives none: the helium-neon line.
const HELIUM_NEON: f64 = 632.8e-9;

/// The reference temperature of a fibre-optic gyro when the file gives none, °C.
const REFERENCE_C: f64 = 25.0;

impl Builder<'_> {
    /// The optics sections of `[gyro]` (an error in `[accel]`), each
    /// replacing whatever optics the preset had.
    pub(super) fn optics(
        &mut self,
        t: &TriadFile,
        triad: Triad,
        e: &mut TriadEffects,
    ) -> anyhow::Result<()> {
        let first = t.ring_laser.as_ref().map(|r| (&r.area, "ring_laser")).or(t
            .fibre_optic
            .as_ref()
            .map(|f| (&f.coil_diameter, "fibre_optic")));
        if let (Triad::Accel, Some((v, name))) = (triad, first) {
            let message = format!("`{name}` is a gyro model; accelerometers cannot have it");
            return Err(self.src.error(&v.span(), message));
        }
        if let (Some(_), Some(f)) = (&t.ring_laser, &t.fibre_optic) {
            let message = "a gyro is a ring laser or a fibre-optic gyro, not both";
            return Err(self.src.error(&f.coil_diameter.span(), message));
        }
        if let Some(r) = &t.ring_laser {
            e.ring_laser = Some(self.ring_laser(r)?);
            e.fibre_optic = None;
        }
        if let Some(f) = &t.fibre_optic {
            e.fibre_optic = Some(self.fibre_optic(f)?);
            e.ring_laser = None;
        }
        Ok(())
    }

    /// One quantity of a gyro's optics, recorded as the simulator's `what`
    /// (all must be positive but the lock-in rate, which may be 0).
    fn optic(
        &mut self,
        v: &Value,
        name: &'static str,
        dim: Dim,
        units: &'static str,
        what: &'static str,
    ) -> anyhow::Result<f64> {
        let x = self.src.quantity(v, field(name, dim, units))?;
        let key = Key::triad(Triad::Gyro, what);
        if what == what::RL_LOCK_IN {
            self.origins.quantity(key, v, name, &[x]);
        } else {
            let message = format!("`{name}` = {} must be positive", v.get_ref());
            self.origins.positive_quantity(key, v, name, &[x], message);
        }
        Ok(x)
    }

    fn ring_laser(&mut self, r: &RingLaserFile) -> anyhow::Result<RingLaserParams> {
        let area_dim = Dim::LENGTH.mul(Dim::LENGTH);
        let area = self.optic(
            &r.area,
            "ring_laser.area",
            area_dim,
            "cm^2, m^2",
            what::RL_AREA,
        )?;
        let path_length = self.optic(
            &r.path_length,
            "ring_laser.path_length",
            Dim::LENGTH,
            "cm, m",
            what::RL_PATH,
        )?;
        let wavelength = match &r.wavelength {
            Some(v) => self.optic(
                v,
                "ring_laser.wavelength",
                Dim::LENGTH,
                "nm",
                what::RL_WAVELENGTH,
            )?,
            None => HELIUM_NEON,
        };
        let lock_in = self.optic(
            &r.lock_in,
            "ring_laser.lock_in",
            Dim::RATE,
            "deg/s, deg/h",
            what::RL_LOCK_IN,
        )?;
        let dither = match (&r.dither_rate, &r.dither_frequency_hz) {
            (None, None) => None,
            (Some(rate), Some(f)) => {
                let peak_rate = self.optic(
                    rate,
                    "ring_laser.dither_rate",
                    Dim::RATE,
                    "deg/s",
                    what::RL_DITHER_RATE,
                )?;
                let frequency = *f.get_ref();
                let key = Key::triad(Triad::Gyro, what::RL_DITHER_FREQUENCY);
                self.origins
                    .number(key, f, "dither_frequency_hz", frequency);
                Some(Dither {
                    peak_rate,
                    frequency,
                })
            }
            (Some(v), None) => {
                return Err(self.src.error(
                    &v.span(),
                    "`dither_rate` needs `dither_frequency_hz` (both, or neither: no dither)",
                ))
            }
            (None, Some(f)) => {
                return Err(self.src.error(
                    &f.span(),
                    "`dither_frequency_hz` needs `dither_rate` (both, or neither: no dither)",
                ))
            }
        };
        Ok(RingLaserParams {
            area,
            path_length,
            wavelength,
            lock_in,
            dither,
        })
    }

    fn fibre_optic(&mut self, f: &FibreOpticFile) -> anyhow::Result<FibreOpticParams> {
        let turns = *f.turns.get_ref();
        self.origins.number(
            Key::triad(Triad::Gyro, what::FO_TURNS),
            &f.turns,
            "turns",
            turns,
        );
        let diameter = self.src.quantity(
            &f.coil_diameter,
            field("fibre_optic.coil_diameter", Dim::LENGTH, "cm, m"),
        )?;
        if diameter <= 0.0 {
            return Err(self
                .src
                .error(&f.coil_diameter.span(), "`coil_diameter` must be positive"));
        }
        let wavelength = self.optic(
            &f.wavelength,
            "fibre_optic.wavelength",
            Dim::LENGTH,
            "nm",
            what::FO_WAVELENGTH,
        )?;
        let readout = match f.readout.get_ref().as_str() {
            "open" => Loop::Open,
            "closed" => Loop::Closed,
            other => {
                let message =
                    format!("readout = \"{other}\": expected \"open\" or \"closed\" (loop)");
                return Err(self.src.error(&f.readout.span(), message));
            }
        };
        let reference = f.reference_c.as_ref().map_or(REFERENCE_C, |r| *r.get_ref());
        if let Some(r) = &f.reference_c {
            let key = Key::triad(Triad::Gyro, what::FO_REFERENCE);
            self.origins.number(key, r, "reference_c", reference);
        }
        let per_degree = Dim::ONE.per_kelvin();
        let coefficient = |b: &Self, v: &Option<Value>, name| match v {
            Some(v) => b.src.quantity(v, field(name, per_degree, "ppm/degC")),
            None => Ok(0.0),
        };
        Ok(FibreOpticParams {
            turns,
            coil_area: std::f64::consts::PI * diameter * diameter / 4.0,
            wavelength,
            readout,
            reference,
            area_per_degree: coefficient(self, &f.area_per_degree, "fibre_optic.area_per_degree")?,
            wavelength_per_degree: coefficient(
                self,
                &f.wavelength_per_degree,
                "fibre_optic.wavelength_per_degree",
            )?,
        })
    }
}
