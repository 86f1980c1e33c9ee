//! One field's value in SI units: a quantity written with its unit (the
//! dimension checked against the field's), one per axis or three, or a 3×3
//! matrix. Whether the number is allowed (sign, range) is the simulator's
//! check ([`Scene::validate`](triad_sim::scenes::scene::Scene::validate)), not this one's.

use toml::Spanned;

use super::parse::{Source, Value};
use super::unit::{parse_quantity, Dim, Quantity};

/// What a field needs: its name, its dimension, and units shown when the unit is wrong.
#[derive(Clone, Copy, Debug)]
pub(super) struct Field {
    pub name: &'static str,
    pub dim: Dim,
    /// Examples of units shown when the unit is wrong.
    pub example: &'static str,
}

/// A field named `name` of dimension `dim` (units such as `example`).
pub(super) fn field(name: &'static str, dim: Dim, example: &'static str) -> Field {
    Field { name, dim, example }
}

impl Source<'_> {
    /// A quantity in SI units: a string "VALUE UNIT" of the field's
    /// dimension, or a plain number for a dimensionless field. Finite.
    pub fn quantity(&self, v: &Value, field: Field) -> anyhow::Result<f64> {
        let span = v.span();
        let q = match v.get_ref() {
            toml::Value::String(s) => parse_quantity(s)
                .map_err(|e| self.error(&span, format!("`{}`: {e}", field.name)))?,
            toml::Value::Float(x) if field.dim == Dim::ONE => Quantity {
                si: *x,
                dim: Dim::ONE,
            },
            toml::Value::Integer(x) if field.dim == Dim::ONE => Quantity {
                si: *x as f64,
                dim: Dim::ONE,
            },
            other => {
                return Err(self.error(
                    &span,
                    format!(
                        "`{}` = {other}: give a value with its unit as a string, e.g. \"1.5 {}\"",
                        field.name,
                        field.example.split(',').next().unwrap_or("")
                    ),
                ))
            }
        };
        // Misalignments may be written as angles (small-angle: rad = ratio).
        let dim_ok = q.dim == field.dim || (field.dim == Dim::ONE && q.dim == Dim::ANGLE);
        if !dim_ok {
            return Err(self.error(
                &span,
                format!(
                    "`{}`: the unit has dimension {}, but this field needs {} (units such as {})",
                    field.name, q.dim, field.dim, field.example
                ),
            ));
        }
        if !q.si.is_finite() {
            return Err(self.error(&span, format!("`{}` is not a finite number", field.name)));
        }
        Ok(q.si)
    }

    /// One quantity for all three axes, or an array of three.
    pub fn per_axis(&self, v: &Value, field: Field) -> anyhow::Result<[f64; 3]> {
        match v.get_ref() {
            toml::Value::Array(items) => {
                if items.len() != 3 {
                    return Err(self.error(
                        &v.span(),
                        format!(
                            "`{}` has {} values; give one or three (x, y, z)",
                            field.name,
                            items.len()
                        ),
                    ));
                }
                let mut out = [0.0; 3];
                for (o, item) in out.iter_mut().zip(items) {
                    *o = self.quantity(&Spanned::new(v.span(), item.clone()), field)?;
                }
                Ok(out)
            }
            _ => Ok([self.quantity(v, field)?; 3]),
        }
    }

    /// A 3×3 matrix: one quantity (times I), three (diagonal) or three rows of three.
    pub fn matrix(&self, v: &Value, field: Field) -> anyhow::Result<[[f64; 3]; 3]> {
        if let toml::Value::Array(rows) = v.get_ref() {
            if rows.iter().all(|r| r.is_array()) {
                if rows.len() != 3 {
                    return Err(self.error(&v.span(), format!("`{}` needs three rows", field.name)));
                }
                let mut m = [[0.0; 3]; 3];
                for (mi, row) in m.iter_mut().zip(rows) {
                    *mi = self.per_axis(&Spanned::new(v.span(), row.clone()), field)?;
                }
                return Ok(m);
            }
        }
        let d = self.per_axis(v, field)?;
        Ok([[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const TEXT: &str = "x = 1";

    fn src() -> Source<'static> {
        Source {
            path: Path::new("f.toml"),
            text: TEXT,
        }
    }

    fn value(text: &str) -> Value {
        let doc: toml::Table = toml::from_str(&format!("v = {text}")).unwrap();
        Spanned::new(4..5, doc["v"].clone())
    }

    const RATE: Field = Field {
        name: "rate",
        dim: Dim::RATE,
        example: "deg/s, rad/s",
    };

    #[test]
    fn quantities_convert_and_their_dimension_is_checked() {
        let deg = std::f64::consts::PI / 180.0;
        assert!((src().quantity(&value("\"-3600 deg/h\""), RATE).unwrap() + deg).abs() < 1e-15);
        let err = src()
            .quantity(&value("\"1 g\""), RATE)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("f.toml:1:5: `rate`: the unit has dimension"),
            "{err}"
        );
        let err = src().quantity(&value("2.0"), RATE).unwrap_err().to_string();
        assert!(err.contains("e.g. \"1.5 deg/s\""), "{err}");
        let err = src().quantity(&value("\"1e999 rad/s\""), RATE).unwrap_err();
        assert!(err.to_string().ends_with("`rate` is not a finite number"));
        // Plain numbers and angles are ratios.
        let ratio = field("m", Dim::ONE, "ppm");
        assert_eq!(src().quantity(&value("3"), ratio).unwrap(), 3.0);
        assert_eq!(src().quantity(&value("\"2 mrad\""), ratio).unwrap(), 2e-3);
    }

    #[test]
    fn per_axis_takes_one_or_three_values() {
        let ratio = field("s", Dim::ONE, "ppm");
        assert_eq!(src().per_axis(&value("\"5 %\""), ratio).unwrap(), [0.05; 3]);
        let three = src()
            .per_axis(&value("[1, \"2 ppm\", -3.0]"), ratio)
            .unwrap();
        assert_eq!(three, [1.0, 2e-6, -3.0]);
        let err = src()
            .per_axis(&value("[1, 2]"), ratio)
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with("`s` has 2 values; give one or three (x, y, z)"),
            "{err}"
        );
    }

    #[test]
    fn matrices_are_a_scalar_a_diagonal_or_three_rows() {
        let ratio = field("m", Dim::ONE, "ppm");
        let m = src().matrix(&value("[1, 2, 3]"), ratio).unwrap();
        assert_eq!(m, [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]);
        let m = src()
            .matrix(&value("[[0, 1, 0], [2, 0, 0], [0, 0, 3]]"), ratio)
            .unwrap();
        assert_eq!(m[1][0], 2.0);
        let err = src().matrix(&value("[[0, 1, 0]]"), ratio).unwrap_err();
        assert!(err.to_string().ends_with("`m` needs three rows"));
    }
}
