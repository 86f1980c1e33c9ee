//! `triad units`: one specification value in every unit it is quoted in
//! (data sheet, Allan/IEEE 952, Kalibr), because per √Hz, per √s and per √h,
//! and degrees per hour against radians per second, are confused more than
//! anything else in IMU work.

mod table;

use std::process::ExitCode;

use anyhow::{anyhow, bail};
use clap::Args;

use crate::plumbing::number::readable;
use crate::plumbing::stdio::{self, outln};
use table::{find, Unit, UNITS};

/// Arguments of `triad units`.
#[derive(Args)]
#[command(
    after_help = "Units (ASCII spellings in brackets; ° µ √ ² may be typed as is):\n  \
    angle random walk: rad/s/√Hz [rad/s/sqrt(Hz)], °/s/√Hz = °/√s [deg/s/sqrt(Hz)], °/√h [deg/sqrt(h)], °/h/√Hz\n  \
    velocity random walk: m/s²/√Hz [m/s^2/sqrt(Hz)], g/√Hz, mg/√Hz, µg/√Hz [ug/sqrt(Hz)], m/s/√h, ft/s/√h\n  \
    rate (bias): rad/s, °/s [deg/s], °/h [deg/h]\n  \
    acceleration (bias): m/s² [m/s^2], g, mg, µg [ug]\n  \
    rate random walk: rad/s²/√Hz, °/s²/√Hz, °/h/√h [deg/h/sqrt(h)]\n  \
    acceleration random walk: m/s³/√Hz, µg/s/√Hz, mg/s/√Hz, µg/√h, mg/√h, m/s/h/√h\n\n\
    Examples:\n  triad units 0.15 'deg/sqrt(h)'\n  triad units 100 'ug/sqrt(Hz)' --to 'm/s/sqrt(h)'\n  triad units 10 deg/h --to rad/s"
)]
pub struct UnitsArgs {
    /// The value.
    #[arg(allow_negative_numbers = true)]
    value: f64,
    /// Its unit (see below).
    unit: String,
    /// Print only the value in this unit (a number, for scripts).
    #[arg(long, value_name = "UNIT")]
    to: Option<String>,
    /// For a noise density, also the rms resolution over this bandwidth
    /// (√(PSD × bandwidth), THEORY.md).
    #[arg(long, value_name = "HZ")]
    bandwidth: Option<f64>,
}

/// Runs `triad units`.
pub fn run(args: UnitsArgs) -> anyhow::Result<ExitCode> {
    if !args.value.is_finite() {
        bail!("{}: the value must be a finite number", args.value);
    }
    let from = find(&args.unit).ok_or_else(|| {
        anyhow!(
            "unknown unit {:?}: `triad units --help` lists the units it knows",
            args.unit
        )
    })?;
    let si = args.value * from.si;
    let mut out = String::new();
    if let Some(to) = &args.to {
        let to_unit = find(to).ok_or_else(|| {
            anyhow!("--to {to:?}: unknown unit; `triad units --help` lists the units it knows")
        })?;
        if to_unit.quantity != from.quantity {
            bail!(
                "--to {}: {} measures {}, but {} measures {}",
                to_unit.name,
                to_unit.name,
                to_unit.quantity.describe(),
                from.name,
                from.quantity.describe()
            );
        }
        outln!(out, "{}", significant(si / to_unit.si));
        stdio::print(&out)?;
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        out,
        "{} {} is {}:",
        readable(args.value),
        from.name,
        from.quantity.describe()
    );
    for unit in UNITS.iter().filter(|u| u.quantity == from.quantity) {
        let kalibr = match (unit.si == 1.0, from.quantity.kalibr()) {
            (true, Some(name)) => format!("   (Kalibr {name})"),
            _ => String::new(),
        };
        outln!(out, "  {} {}{kalibr}", significant(si / unit.si), unit.name);
    }
    if let Some(bandwidth) = args.bandwidth {
        resolution(&mut out, from, si, bandwidth)?;
    }
    stdio::print(&out)?;
    Ok(ExitCode::SUCCESS)
}

/// The rms resolution of a noise density over `bandwidth` Hz.
fn resolution(out: &mut String, from: &Unit, si: f64, bandwidth: f64) -> anyhow::Result<()> {
    let bandwidth = crate::plumbing::number::positive(
        "--bandwidth",
        bandwidth,
        "must be a positive number of Hz",
    )?;
    if !from.quantity.is_density() {
        bail!(
            "--bandwidth: {} is not a noise density (resolution = √(PSD × bandwidth) needs one)",
            from.name
        );
    }
    let rms = si * bandwidth.sqrt();
    let (si_name, others): (&str, &[(&str, f64)]) = match from.quantity {
        table::Quantity::AngleRandomWalk => ("rad/s", &[("°/s", std::f64::consts::PI / 180.0)]),
        _ => ("m/s²", &[("mg", 1e-3 * triad::units::STANDARD_GRAVITY)]),
    };
    let mut line = format!(
        "  resolution over {} Hz: {} {si_name} rms",
        readable(bandwidth),
        readable(rms)
    );
    for (name, factor) in others {
        line.push_str(&format!(" = {} {name}", readable(rms / factor)));
    }
    outln!(out, "{line}");
    Ok(())
}

/// `x` to 9 significant digits, printed short: conversions through π and
/// standard gravity leave float noise in the 16th digit (0.0024999999999999996),
/// which no specification carries.
fn significant(x: f64) -> String {
    let rounded: f64 = format!("{x:.8e}").parse().unwrap_or(x);
    readable(rounded)
}

#[cfg(test)]
mod tests {
    use super::table::*;
    use super::*;

    fn convert(value: f64, from: &str, to: &str) -> f64 {
        let (from, to) = (find(from).unwrap(), find(to).unwrap());
        assert_eq!(from.quantity, to.quantity);
        value * from.si / to.si
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn theorys_equivalences_hold() {
        // THEORY.md, "Nomenclature and unit equivalences".
        assert!(close(convert(1.0, "(°/s)/√Hz", "°/√h"), 60.0));
        assert!(close(convert(1.0, "deg/sqrt(s)", "deg/s/sqrt(Hz)"), 1.0));
        assert!(close(
            convert(1.0, "(°/s²)/√Hz", "(°/h)/√h"),
            60.0_f64.powi(3)
        ));
        assert!((convert(1.0, "°/h", "°/s") - 0.00028).abs() < 0.000_003);
        // 1 g/√Hz = 9.8 (m/s)/√s = 588 (m/s)/√h (THEORY rounds g).
        assert!(close(convert(1.0, "g/√Hz", "m/s/√h"), 9.806_65 * 60.0));
        assert!(close(
            convert(1.0, "g/sqrt(Hz)", "m/s^2/sqrt(Hz)"),
            9.806_65
        ));
        // The random-walk example: 0.99 (°/s)/√Hz = 59.4 °/√h.
        assert!(close(convert(0.99, "°/s/√Hz", "°/√h"), 59.4));
        // Kalibr's SI units.
        assert!(close(
            convert(1.0, "rad/s/sqrt(Hz)", "deg/s/sqrt(Hz)"),
            180.0 / std::f64::consts::PI
        ));
        assert!(close(
            convert(1.0, "ug/sqrt(h)", "m/s^3/sqrt(Hz)"),
            1e-6 * 9.806_65 / 60.0
        ));
    }

    #[test]
    fn every_spelling_names_one_unit_and_typed_symbols_read_as_ascii() {
        let mut seen = std::collections::HashSet::new();
        for unit in UNITS {
            for s in unit.spellings {
                assert!(seen.insert(*s), "{s} spelt twice");
                assert_eq!(normalise(s), *s, "{s} is not in normal form");
            }
            assert_eq!(
                find(unit.name).map(|u| u.name),
                Some(unit.name),
                "{}",
                unit.name
            );
        }
        assert_eq!(normalise("(°/s)/√Hz"), "deg/s/sqrthz");
        assert_eq!(normalise("µg / √Hz"), "ug/sqrthz");
        assert_eq!(normalise("m/s²"), "m/s^2");
        assert!(find("furlongs").is_none());
    }

    #[test]
    fn float_noise_is_not_printed() {
        assert_eq!(significant(0.0024999999999999996), "0.0025");
        assert_eq!(significant(588.399), "588.399");
        assert_eq!(significant(4.84813681109536e-5), "0.0000484813681");
    }
}
