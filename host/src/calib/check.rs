//! `triad calib check`: a calibration file validated as the firmware and
//! `triad correct` use it, and what that gives per triad: the condition
//! number, the folded coefficients on SI inputs and on a 16-bit chip's raw
//! counts, and the fixed-point error bound.

use std::process::ExitCode;

use anyhow::anyhow;
use triad::model::{Corrector, FixedCorrector, Triad};
use triad::units::si_to_dps_per_g;

use super::{si_corrector, Ranges};
use crate::calib::file::CalibFile;
use crate::plumbing::stdio::{self, outln};

/// Runs `triad calib check` on a loaded file.
pub fn run(file: &CalibFile, ranges: &Ranges) -> anyhow::Result<ExitCode> {
    let si = si_corrector(file, ranges)?;
    let per_lsb = Corrector::new(&file.calibration, &ranges.scale_16_bit(), file.orientation)
        .map_err(|e| anyhow!("{}: {e}", file.path.display()))?;
    let fixed =
        FixedCorrector::new(&per_lsb).map_err(|e| anyhow!("{}: {e}", file.path.display()))?;
    let bound = fixed.error_bound();
    let mut out = String::new();
    print_file(&mut out, file, ranges);
    for (triad, bound) in [(Triad::Accel, bound[0]), (Triad::Gyro, bound[1])] {
        outln!(out);
        print_triad(&mut out, file, triad, &si, &per_lsb, bound);
    }
    stdio::print(&out)?;
    Ok(ExitCode::SUCCESS)
}

/// The file's identity, orientation and the ranges assumed.
fn print_file(out: &mut String, file: &CalibFile, ranges: &Ranges) {
    outln!(out, "{}: OK", file.path.display());
    let source = if file.id_from_parameters {
        " (CRC-32C of the parameters)"
    } else {
        ""
    };
    outln!(out, "calibration id: {:#010x}{source}", file.calibration.id);
    outln!(out, "orientation: {}", file.orientation);
    outln!(
        out,
        "ranges: ±{} g, ±{} °/s (a 16-bit chip: full scale = 32768 LSB)",
        ranges.accel_range_g,
        ranges.gyro_range_dps
    );
}

/// A triad's unit and the fixed-point format of its raw path.
fn unit_and_format(triad: Triad) -> (&'static str, &'static str) {
    match triad {
        Triad::Accel => ("m/s²", "Q16.16"),
        Triad::Gyro => ("rad/s", "Q12.20"),
    }
}

/// One triad: conditioning, temperature terms, both folds, the bound.
fn print_triad(
    out: &mut String,
    file: &CalibFile,
    triad: Triad,
    si: &Corrector,
    per_lsb: &Corrector,
    bound: f64,
) {
    let (unit, q_format) = unit_and_format(triad);
    let scale = per_lsb.scale();
    let lsb = match triad {
        Triad::Accel => scale.accel.si_per_lsb,
        Triad::Gyro => scale.gyro.si_per_lsb,
    };
    outln!(
        out,
        "[{}] condition number κ₁ = {:.6}",
        triad.name(),
        si.condition_number(triad)
    );
    if let Some(t) = &file.calibration.triad(triad).temperature {
        outln!(
            out,
            "  temperature terms around {} °C (folded here at that temperature)",
            t.reference_c
        );
    }
    let f = si.folded(triad);
    outln!(out, "  m = K·x + k with x in {unit} (triad correct):");
    print_matrix(out, "K", &f.k);
    outln!(out, "    k = {}", vector(&f.offset));
    let f = per_lsb.folded(triad);
    outln!(
        out,
        "  m = K·raw + k with raw in LSB ({lsb:e} {unit}/LSB, the firmware's fold):"
    );
    print_matrix(out, "K", &f.k);
    outln!(out, "    k = {}", vector(&f.offset));
    if let (Triad::Gyro, Some(g), Some(c_si), Some(c_lsb)) = (
        triad,
        &file.calibration.g_sensitivity,
        si.folded_g_sensitivity(),
        per_lsb.folded_g_sensitivity(),
    ) {
        outln!(
            out,
            "  g-sensitivity G in °/s per g (gyro bias per unit specific force, sensor axes):"
        );
        print_matrix(out, "G", &g.map(|row| row.map(si_to_dps_per_g)));
        outln!(
            out,
            "  + C·f + c with f the accelerometer's input in m/s² (triad correct):"
        );
        print_matrix(out, "C", &c_si.k);
        outln!(out, "    c = {}", vector(&c_si.offset));
        outln!(
            out,
            "  + C·raw + c with raw the accelerometer's LSB (the firmware's fold):"
        );
        print_matrix(out, "C", &c_lsb.k);
        outln!(out, "    c = {}", vector(&c_lsb.offset));
    }
    outln!(
        out,
        "  fixed point ({q_format}) error bound: {bound:.3e} {unit} = {:.4} LSB",
        bound / lsb
    );
}

/// A vector with 12 significant decimals and its sign.
fn vector(v: &[f64; 3]) -> String {
    // `+ 0.0` turns −0 into +0 for the reader.
    format!(
        "[{:+.12e}, {:+.12e}, {:+.12e}]",
        v[0] + 0.0,
        v[1] + 0.0,
        v[2] + 0.0
    )
}

/// The rows of a matrix, the first labelled `name =`.
fn matrix_lines(name: &str, m: &[[f64; 3]; 3]) -> Vec<String> {
    m.iter()
        .enumerate()
        .map(|(i, row)| {
            let label = if i == 0 {
                format!("{name} =")
            } else {
                " ".repeat(name.len() + 2)
            };
            format!("    {label} {}", vector(row))
        })
        .collect()
}

fn print_matrix(out: &mut String, name: &str, m: &[[f64; 3]; 3]) {
    for line in matrix_lines(name, m) {
        outln!(out, "{line}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_are_signed_and_never_negative_zero() {
        assert_eq!(
            vector(&[-0.0, 1.5, -2e-7]),
            "[+0.000000000000e0, +1.500000000000e0, -2.000000000000e-7]"
        );
    }

    #[test]
    fn matrices_label_their_first_row_and_align_the_others() {
        let lines = matrix_lines("K", &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("    K = [+1.0"));
        assert!(lines[1].starts_with("        [+0.0"));
        assert_eq!(unit_and_format(Triad::Gyro), ("rad/s", "Q12.20"));
    }
}
