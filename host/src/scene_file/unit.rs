//! Quantities with data-sheet units: "0.15 deg/sqrt(h)", "40 ug/sqrt(Hz)",
//! "10 (deg/h)/sqrt(h)", "300 ppm", "5 ug/degC".
//!
//! A small unit algebra: each unit name has an SI factor and a dimension
//! (metre, second, radian, kelvin exponents, kept doubled so √Hz and √h are
//! whole numbers); products, quotients, powers and square roots combine them.
//! A field then checks that the dimension is the one it needs, so "0.2 deg/h"
//! given where a noise density belongs is an error, not a silent misreading.

use std::fmt;

/// Dimension exponents ×2 (so that square roots of Hz and h stay integral).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim {
    m: i8,
    s: i8,
    rad: i8,
    k: i8,
}

impl Dim {
    /// Dimensionless.
    pub const ONE: Dim = Dim::new(0, 0, 0, 0);
    /// Angular rate, rad/s.
    pub const RATE: Dim = Dim::new(0, -2, 2, 0);
    /// Acceleration, m/s².
    pub const ACCEL: Dim = Dim::new(2, -4, 0, 0);
    /// Time, s.
    pub const TIME: Dim = Dim::new(0, 2, 0, 0);
    /// Angle, rad.
    pub const ANGLE: Dim = Dim::new(0, 0, 2, 0);
    /// Length, m.
    pub const LENGTH: Dim = Dim::new(2, 0, 0, 0);

    /// From doubled exponents.
    pub const fn new(m: i8, s: i8, rad: i8, k: i8) -> Self {
        Dim { m, s, rad, k }
    }

    /// self·other.
    pub const fn mul(self, o: Dim) -> Dim {
        Dim::new(self.m + o.m, self.s + o.s, self.rad + o.rad, self.k + o.k)
    }

    /// self/other.
    pub const fn div(self, o: Dim) -> Dim {
        Dim::new(self.m - o.m, self.s - o.s, self.rad - o.rad, self.k - o.k)
    }

    /// A quantity per √Hz (a noise density): ×s^½.
    pub const fn per_sqrt_hz(self) -> Dim {
        Dim::new(self.m, self.s + 1, self.rad, self.k)
    }

    /// A quantity per √s (a random-walk coefficient): ×s^−½.
    pub const fn per_sqrt_s(self) -> Dim {
        Dim::new(self.m, self.s - 1, self.rad, self.k)
    }

    /// A quantity per kelvin (a temperature coefficient).
    pub const fn per_kelvin(self) -> Dim {
        Dim::new(self.m, self.s, self.rad, self.k - 2)
    }

    fn pow(self, n: i8) -> Option<Dim> {
        Some(Dim::new(
            self.m.checked_mul(n)?,
            self.s.checked_mul(n)?,
            self.rad.checked_mul(n)?,
            self.k.checked_mul(n)?,
        ))
    }

    fn sqrt(self) -> Option<Dim> {
        let half = |x: i8| (x % 2 == 0).then_some(x / 2);
        Some(Dim::new(
            half(self.m)?,
            half(self.s)?,
            half(self.rad)?,
            half(self.k)?,
        ))
    }
}

impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        for (name, e) in [
            ("m", self.m),
            ("s", self.s),
            ("rad", self.rad),
            ("K", self.k),
        ] {
            match e {
                0 => {}
                2 => parts.push(name.to_string()),
                e if e % 2 == 0 => parts.push(format!("{name}^{}", e / 2)),
                e => parts.push(format!("{name}^{}/2", e)),
            }
        }
        if parts.is_empty() {
            write!(f, "dimensionless")
        } else {
            write!(f, "{}", parts.join("·"))
        }
    }
}

const G: f64 = triad::units::STANDARD_GRAVITY;
const DEG: f64 = std::f64::consts::PI / 180.0;

/// The unit names: (names, SI factor, dimension).
const UNITS: &[(&[&str], f64, Dim)] = &[
    (&["m"], 1.0, Dim::new(2, 0, 0, 0)),
    (&["cm"], 1e-2, Dim::new(2, 0, 0, 0)),
    (&["mm"], 1e-3, Dim::new(2, 0, 0, 0)),
    (&["um", "µm"], 1e-6, Dim::new(2, 0, 0, 0)),
    (&["nm"], 1e-9, Dim::new(2, 0, 0, 0)),
    (&["s", "sec"], 1.0, Dim::TIME),
    (&["ms"], 1e-3, Dim::TIME),
    (&["min"], 60.0, Dim::TIME),
    (&["h", "hr", "hour"], 3600.0, Dim::TIME),
    (&["Hz"], 1.0, Dim::new(0, -2, 0, 0)),
    (&["kHz"], 1e3, Dim::new(0, -2, 0, 0)),
    (&["rad"], 1.0, Dim::ANGLE),
    (&["mrad"], 1e-3, Dim::ANGLE),
    (&["urad", "µrad"], 1e-6, Dim::ANGLE),
    (&["deg", "°"], DEG, Dim::ANGLE),
    (&["arcsec"], DEG / 3600.0, Dim::ANGLE),
    (&["dps"], DEG, Dim::RATE),
    (&["mdps"], 1e-3 * DEG, Dim::RATE),
    (&["g"], G, Dim::ACCEL),
    (&["mg"], 1e-3 * G, Dim::ACCEL),
    (&["ug", "µg"], 1e-6 * G, Dim::ACCEL),
    (&["ppm"], 1e-6, Dim::ONE),
    (&["%"], 1e-2, Dim::ONE),
    (&["degC", "°C", "K"], 1.0, Dim::new(0, 0, 0, 2)),
];

/// A value in SI units with its dimension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantity {
    /// The value in SI units.
    pub si: f64,
    /// Its dimension.
    pub dim: Dim,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Name(String),
    Int(i8),
    Op(char),
}

fn lex(unit: &str) -> Result<Vec<Token>, String> {
    let mut tokens = Vec::new();
    let mut chars = unit.chars().peekable();
    while let Some(&c) = chars.peek() {
        if c.is_whitespace() {
            chars.next();
        } else if "/*·^()√".contains(c) {
            tokens.push(Token::Op(c));
            chars.next();
        } else if c.is_ascii_digit() || c == '-' {
            let mut s = String::new();
            s.push(c);
            chars.next();
            while let Some(&d) = chars.peek().filter(|d| d.is_ascii_digit()) {
                s.push(d);
                chars.next();
            }
            let n = s
                .parse::<i8>()
                .map_err(|_| format!("`{s}` is not a small whole number"))?;
            tokens.push(Token::Int(n));
        } else {
            let mut s = String::new();
            while let Some(&d) = chars.peek() {
                if d.is_whitespace() || "/*·^()√".contains(d) {
                    break;
                }
                s.push(d);
                chars.next();
            }
            tokens.push(Token::Name(s));
        }
    }
    Ok(tokens)
}

struct Parser {
    tokens: Vec<Token>,
    at: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.at)
    }

    fn next(&mut self) -> Option<Token> {
        let t = self.tokens.get(self.at).cloned();
        self.at += 1;
        t
    }

    fn expr(&mut self) -> Result<(f64, Dim), String> {
        let (mut f, mut d) = self.term()?;
        while let Some(Token::Op(op @ ('/' | '*' | '·'))) = self.peek().cloned() {
            self.next();
            let (g, e) = self.term()?;
            if op == '/' {
                f /= g;
                d = d.div(e);
            } else {
                f *= g;
                d = d.mul(e);
            }
        }
        Ok((f, d))
    }

    fn term(&mut self) -> Result<(f64, Dim), String> {
        let (f, d) = self.primary()?;
        if let Some(Token::Op('^')) = self.peek() {
            self.next();
            match self.next() {
                Some(Token::Int(n)) => {
                    let d = d.pow(n).ok_or("exponent too large")?;
                    Ok((f.powi(n as i32), d))
                }
                _ => Err("`^` must be followed by a whole number".into()),
            }
        } else {
            Ok((f, d))
        }
    }

    fn sqrt(f: f64, d: Dim) -> Result<(f64, Dim), String> {
        let d = d
            .sqrt()
            .ok_or("square root of a unit that is already a square root")?;
        Ok((f.sqrt(), d))
    }

    fn primary(&mut self) -> Result<(f64, Dim), String> {
        match self.next() {
            Some(Token::Op('(')) => {
                let v = self.expr()?;
                match self.next() {
                    Some(Token::Op(')')) => Ok(v),
                    _ => Err("missing `)`".into()),
                }
            }
            Some(Token::Op('√')) => {
                let (f, d) = self.primary()?;
                Self::sqrt(f, d)
            }
            Some(Token::Int(1)) => Ok((1.0, Dim::ONE)),
            Some(Token::Name(n)) if n == "sqrt" => match self.next() {
                Some(Token::Op('(')) => {
                    let (f, d) = self.expr()?;
                    match self.next() {
                        Some(Token::Op(')')) => Self::sqrt(f, d),
                        _ => Err("missing `)` after sqrt(".into()),
                    }
                }
                _ => Err("`sqrt` must be followed by `(`".into()),
            },
            Some(Token::Name(n)) => UNITS
                .iter()
                .find(|(names, _, _)| names.contains(&n.as_str()))
                .map(|&(_, f, d)| (f, d))
                .ok_or_else(|| format!("unknown unit `{n}`")),
            Some(t) => Err(format!("unexpected `{}`", token_text(&t))),
            None => Err("the unit ends too early".into()),
        }
    }
}

fn token_text(t: &Token) -> String {
    match t {
        Token::Name(n) => n.clone(),
        Token::Int(i) => i.to_string(),
        Token::Op(c) => c.to_string(),
    }
}

/// Parses a unit expression into its SI factor and dimension.
pub fn parse_unit(unit: &str) -> Result<(f64, Dim), String> {
    let mut p = Parser {
        tokens: lex(unit)?,
        at: 0,
    };
    if p.tokens.is_empty() {
        return Ok((1.0, Dim::ONE));
    }
    let v = p.expr()?;
    match p.peek() {
        None => Ok(v),
        Some(t) => Err(format!("unexpected `{}` in unit `{unit}`", token_text(t))),
    }
}

/// Parses "VALUE UNIT" (the unit may be empty for a plain number).
pub fn parse_quantity(text: &str) -> Result<Quantity, String> {
    let text = text.trim();
    let split = text
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || ((c == '-' || c == '+')
                    && (i == 0 || matches!(text.as_bytes()[i - 1], b'e' | b'E')))
                || ((c == 'e' || c == 'E') && i > 0 && text.as_bytes()[i - 1].is_ascii_digit()))
        })
        .map(|(i, _)| i)
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let value: f64 = number
        .parse()
        .map_err(|_| format!("`{text}` does not start with a number"))?;
    let (factor, dim) = parse_unit(unit)?;
    Ok(Quantity {
        si: value * factor,
        dim,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn si(text: &str) -> (f64, Dim) {
        let q = parse_quantity(text).unwrap();
        (q.si, q.dim)
    }

    #[test]
    fn data_sheet_units_convert_to_si() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * b.abs();
        let (v, d) = si("60 deg/sqrt(h)");
        assert!(close(v, DEG) && d == Dim::RATE.per_sqrt_hz());
        let (v, d) = si("1 (deg/s)/sqrt(Hz)");
        assert!(close(v, DEG) && d == Dim::RATE.per_sqrt_hz());
        let (v, d) = si("1 g/sqrt(Hz)");
        assert!(close(v, G) && d == Dim::ACCEL.per_sqrt_hz());
        let (v, d) = si("588.399 m/s/sqrt(h)");
        assert!(close(v, G) && d == Dim::ACCEL.per_sqrt_hz());
        let (v, d) = si("3600 deg/h");
        assert!(close(v, DEG) && d == Dim::RATE);
        let (v, d) = si("216000 deg/h/sqrt(h)");
        assert!(close(v, DEG) && d == Dim::RATE.per_sqrt_s());
        let (v, d) = si("-5e2 ppm/°C");
        assert!(close(v, -5e-4) && d == Dim::ONE.per_kelvin());
        let (v, d) = si("2 m/s^2");
        assert!(v == 2.0 && d == Dim::ACCEL);
        let (v, d) = si("1 °/√h");
        assert!(close(v, DEG / 60.0) && d == Dim::RATE.per_sqrt_hz());
        let (v, d) = si("0.5");
        assert!(v == 0.5 && d == Dim::ONE);
    }

    #[test]
    fn bad_units_are_named() {
        assert!(parse_quantity("1 furlong").unwrap_err().contains("furlong"));
        assert!(parse_quantity("deg/h").unwrap_err().contains("number"));
        assert!(parse_quantity("1 sqrt(sqrt(Hz))").is_err());
        assert!(parse_quantity("1 deg/(s").is_err());
    }
}
