//! `[motion]` → [`Motion`]: the kind, the fields it takes (a field of
//! another kind is an error, not silently ignored), and each field's value.

use std::ops::Range;

use toml::Spanned;
use triad::units::deg_to_rad;
use triad_sim::motion::hand_poses::MIN_HAND_POSES;
use triad_sim::motion::{Axis, Motion, MAX_POSITIONS};

use super::build::Builder;
use super::field::field;
use super::origin::{what, Key};
use super::parse::MotionFile;
use super::unit::Dim;

/// The motion kinds of scene files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Static,
    RateTable,
    Tumble,
    Vibration,
    Hand,
    RateTableSet,
}

impl Kind {
    fn from_name(name: &str) -> Option<Kind> {
        Some(match name {
            "static" => Kind::Static,
            "rate-table" => Kind::RateTable,
            "tumble" => Kind::Tumble,
            "vibration" => Kind::Vibration,
            "hand" => Kind::Hand,
            "rate-table-set" => Kind::RateTableSet,
            _ => return None,
        })
    }

    /// The fields the kind takes.
    fn fields(self) -> &'static [&'static str] {
        match self {
            Kind::Static => &["attitude_deg"],
            Kind::RateTable => &["axis", "rate"],
            Kind::Tumble => &["positions", "dwell_s", "transition_s"],
            Kind::Vibration => &["attitude_deg", "direction", "amplitude", "frequency_hz"],
            Kind::Hand => &["poses", "seed", "dwell_s", "turn_s"],
            Kind::RateTableSet => &["rate", "run_s", "rest_s"],
        }
    }
}

/// Each motion field and where it is, if present.
fn present(m: &MotionFile) -> [(&'static str, Option<Range<usize>>); 14] {
    [
        ("attitude_deg", m.attitude_deg.as_ref().map(|v| v.span())),
        ("axis", m.axis.as_ref().map(|v| v.span())),
        ("rate", m.rate.as_ref().map(|v| v.span())),
        ("positions", m.positions.as_ref().map(|v| v.span())),
        ("dwell_s", m.dwell_s.as_ref().map(|v| v.span())),
        ("transition_s", m.transition_s.as_ref().map(|v| v.span())),
        ("direction", m.direction.as_ref().map(|v| v.span())),
        ("amplitude", m.amplitude.as_ref().map(|v| v.span())),
        ("frequency_hz", m.frequency_hz.as_ref().map(|v| v.span())),
        ("poses", m.poses.as_ref().map(|v| v.span())),
        ("seed", m.seed.as_ref().map(|v| v.span())),
        ("turn_s", m.turn_s.as_ref().map(|v| v.span())),
        ("run_s", m.run_s.as_ref().map(|v| v.span())),
        ("rest_s", m.rest_s.as_ref().map(|v| v.span())),
    ]
}

/// A rate table's axis: `+x` (or `x`), `-x`, … `-z`.
fn parse_axis(s: &str) -> Option<Axis> {
    Some(match s {
        "+x" | "x" => Axis::PlusX,
        "-x" => Axis::MinusX,
        "+y" | "y" => Axis::PlusY,
        "-y" => Axis::MinusY,
        "+z" | "z" => Axis::PlusZ,
        "-z" => Axis::MinusZ,
        _ => return None,
    })
}

impl Builder<'_> {
    /// The motion of `[motion]`.
    pub(super) fn motion(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let name = m.kind.get_ref().as_str();
        let kind = Kind::from_name(name).ok_or_else(|| {
            self.src.error(
                &m.kind.span(),
                format!("unknown motion kind \"{name}\" (expected static, rate-table, tumble, vibration, hand or rate-table-set)"),
            )
        })?;
        for (field, span) in present(m) {
            if let Some(span) = span.filter(|_| !kind.fields().contains(&field)) {
                return Err(self.src.error(
                    &span,
                    format!("`{field}` does not apply to motion kind \"{name}\""),
                ));
            }
        }
        match kind {
            Kind::Static => Ok(Motion::Static {
                attitude: self.attitude(m),
            }),
            Kind::RateTable => self.rate_table(m),
            Kind::Tumble => self.tumble(m),
            Kind::Vibration => self.vibration(m),
            Kind::Hand => self.hand(m),
            Kind::RateTableSet => self.rate_table_set(m),
        }
    }

    /// A field the motion's kind needs.
    fn needed<'m, T>(&self, m: &MotionFile, v: &'m Option<T>, name: &str) -> anyhow::Result<&'m T> {
        v.as_ref().ok_or_else(|| {
            self.src.error(
                &m.kind.span(),
                format!("motion kind \"{}\" needs `{name}`", m.kind.get_ref()),
            )
        })
    }

    /// `attitude_deg` in radians (default level).
    fn attitude(&mut self, m: &MotionFile) -> [f64; 3] {
        let Some(a) = &m.attitude_deg else {
            return [0.0; 3];
        };
        let rad = a.get_ref().map(deg_to_rad);
        let message = "`attitude_deg` must be finite".to_string();
        self.origins
            .fixed(Key::scene(what::ATTITUDE), a.span(), &rad, message);
        rad
    }

    /// A table rate, `rate`, in rad/s.
    fn table_rate(&mut self, m: &MotionFile) -> anyhow::Result<f64> {
        let v = self.needed(m, &m.rate, "rate")?;
        let rate = self
            .src
            .quantity(v, field("rate", Dim::RATE, "deg/s, rad/s, dps"))?;
        self.origins
            .quantity(Key::scene(what::TABLE_RATE), v, "rate", &[rate]);
        Ok(rate)
    }

    fn hand(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let p = self.needed(m, &m.poses, "poses")?;
        let poses = *p.get_ref();
        let message = format!(
            "poses = {poses}: expected {}..={MAX_POSITIONS} (a rig-free fit wants at least {} gravity directions)",
            MIN_HAND_POSES, MIN_HAND_POSES
        );
        self.origins.fixed(
            Key::scene(what::HAND_POSES),
            p.span(),
            &[f64::from(poses)],
            message,
        );
        let seed = *self.needed(m, &m.seed, "seed")?.get_ref();
        let dwell = self.needed(m, &m.dwell_s, "dwell_s")?;
        let turn = self.needed(m, &m.turn_s, "turn_s")?;
        Ok(Motion::Hand {
            poses,
            seed,
            dwell: self.number(dwell, "dwell_s", what::HAND_DWELL),
            turn: self.number(turn, "turn_s", what::HAND_TURN),
        })
    }

    fn rate_table_set(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let rate = self.table_rate(m)?;
        let run = self.needed(m, &m.run_s, "run_s")?;
        let rest = self.needed(m, &m.rest_s, "rest_s")?;
        Ok(Motion::RateTableSet {
            rate,
            run: self.number(run, "run_s", what::SET_RUN),
            rest: self.number(rest, "rest_s", what::SET_REST),
        })
    }

    fn rate_table(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let axis = self.needed(m, &m.axis, "axis")?;
        let axis = parse_axis(axis.get_ref()).ok_or_else(|| {
            self.src.error(
                &axis.span(),
                format!(
                    "axis \"{}\": expected one of +x, -x, +y, -y, +z, -z",
                    axis.get_ref()
                ),
            )
        })?;
        let rate = self.table_rate(m)?;
        Ok(Motion::RateTable { axis, rate })
    }

    fn tumble(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let p = self.needed(m, &m.positions, "positions")?;
        let positions = *p.get_ref();
        let message = format!("positions = {positions}: expected 6, 12 or 24");
        let key = Key::scene(what::POSITIONS);
        self.origins
            .fixed(key, p.span(), &[f64::from(positions)], message);
        let dwell = self.needed(m, &m.dwell_s, "dwell_s")?;
        let transition = self.needed(m, &m.transition_s, "transition_s")?;
        Ok(Motion::Tumble {
            positions,
            dwell: self.number(dwell, "dwell_s", what::DWELL),
            transition: self.number(transition, "transition_s", what::TRANSITION),
        })
    }

    fn vibration(&mut self, m: &MotionFile) -> anyhow::Result<Motion> {
        let d: &Spanned<[f64; 3]> = self.needed(m, &m.direction, "direction")?;
        let direction = *d.get_ref();
        let message = "`direction` must be a finite, non-zero vector".to_string();
        self.origins
            .fixed(Key::scene(what::DIRECTION), d.span(), &direction, message);
        let a = self.needed(m, &m.amplitude, "amplitude")?;
        let amplitude = self
            .src
            .quantity(a, field("amplitude", Dim::ACCEL, "g, mg, m/s^2"))?;
        self.origins
            .quantity(Key::scene(what::AMPLITUDE), a, "amplitude", &[amplitude]);
        let frequency = self.needed(m, &m.frequency_hz, "frequency_hz")?;
        Ok(Motion::Vibration {
            attitude: self.attitude(m),
            direction,
            amplitude,
            frequency: self.number(frequency, "frequency_hz", what::FREQUENCY),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_axes_have_their_file_names() {
        assert_eq!(Kind::from_name("rate-table"), Some(Kind::RateTable));
        assert_eq!(Kind::from_name("Static"), None);
        assert!(Kind::Vibration.fields().contains(&"attitude_deg"));
        assert!(!Kind::Tumble.fields().contains(&"attitude_deg"));
        assert_eq!(parse_axis("z"), Some(Axis::PlusZ));
        assert_eq!(parse_axis("-y"), Some(Axis::MinusY));
        assert_eq!(parse_axis("w"), None);
    }
}
