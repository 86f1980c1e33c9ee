//! What every (I+Σ), b fit prints and writes: the estimates with their
//! standard deviations, the segment count, the residuals and the condition
//! number. Each fit adds its own method, convention and inputs.

use triad::model::TriadCalibration;

/// The frame of an upper triangular (I+Σ), in every report and file that
/// has one: what the corrected axes are in terms of the sensing axes.
pub const FRAME: &str =
    "(I+Σ) upper triangular: corrected z = the z sensing axis, corrected y in the plane \
                         of the y and z sensing axes, x completes the frame";

use crate::calib::file::vector;
use crate::plumbing::stdio::outln;

/// A fit's common statistics (borrowed from the fit).
pub struct FitReport<'a> {
    /// (I+Σ).
    pub scale_misalignment: &'a [[f64; 3]; 3],
    /// Its standard deviations, when the fit has degrees of freedom.
    pub sigma_scale_misalignment: Option<&'a [[f64; 3]; 3]>,
    /// b.
    pub bias: &'a [f64; 3],
    /// Its standard deviations.
    pub sigma_bias: Option<&'a [f64; 3]>,
    /// Segments fitted.
    pub segments: usize,
    /// Degrees of freedom of the σ's.
    pub dof: usize,
    /// RMS of the residuals.
    pub residual_rms: f64,
    /// Largest residual.
    pub residual_max: f64,
    /// Condition number of the problem.
    pub condition: f64,
}

/// The [`FitReport`] of a fit result (any of the lab's fits: they name
/// their statistics alike).
macro_rules! fit_report {
    ($fit:expr) => {
        $crate::calib::report::FitReport {
            scale_misalignment: &$fit.scale_misalignment,
            sigma_scale_misalignment: $fit.sigma_scale_misalignment.as_ref(),
            bias: &$fit.bias,
            sigma_bias: $fit.sigma_bias.as_ref(),
            segments: $fit.segments,
            dof: $fit.dof,
            residual_rms: $fit.residual_rms,
            residual_max: $fit.residual_max,
            condition: $fit.condition,
        }
    };
}
pub(crate) use fit_report;

impl FitReport<'_> {
    /// Adds (I+Σ) under `matrix_title` and b in `bias_unit` to the report
    /// `out`; without standard deviations, says why (`no_dof`).
    pub fn print(&self, out: &mut String, matrix_title: &str, bias_unit: &str, no_dof: &str) {
        outln!(out, "  {matrix_title}:");
        for line in matrix_rows(self.scale_misalignment, self.sigma_scale_misalignment) {
            outln!(out, "    {line}");
        }
        print_vector(out, &format!("b ({bias_unit})"), self.bias, self.sigma_bias);
        if self.sigma_bias.is_none() {
            outln!(out, "  (no standard deviations: {no_dof})");
        } else {
            outln!(
                out,
                "  (σ's: {} degrees of freedom, so ±2σ covers {:.1} % (Student-t), not 95.4 %; \
                 from the scatter of the segments about the fit: noise common to every \
                 segment, such as bias drift over the session, is not in them)",
                self.dof,
                100.0 * triad_lab::student_t::coverage(2.0, self.dof as f64)
            );
        }
    }

    /// The fit table's common keys: segments, residuals, condition number, σ's.
    pub fn insert_statistics(&self, table: &mut toml::Table) {
        table.insert(
            "segments".into(),
            toml::Value::Integer(self.segments as i64),
        );
        table.insert("residual_rms".into(), toml::Value::Float(self.residual_rms));
        table.insert("residual_max".into(), toml::Value::Float(self.residual_max));
        table.insert(
            "condition_number".into(),
            toml::Value::Float(self.condition),
        );
        table.insert(
            "degrees_of_freedom".into(),
            toml::Value::Integer(self.dof as i64),
        );
        if let (Some(m), Some(b)) = (self.sigma_scale_misalignment, self.sigma_bias) {
            table.insert(
                "sigma_scale_misalignment".into(),
                toml::Value::Array(m.iter().map(vector).collect()),
            );
            table.insert("sigma_bias".into(), vector(b));
        }
    }

    /// The fitted triad (no temperature terms: a fit at one temperature says
    /// nothing about them).
    pub fn triad(&self) -> TriadCalibration {
        TriadCalibration {
            scale_misalignment: *self.scale_misalignment,
            bias: *self.bias,
            temperature: None,
        }
    }
}

/// A fit table: `method`, and `convention` when there is one.
pub fn method_table(method: &str, convention: Option<&str>) -> toml::Table {
    let mut table = toml::Table::new();
    table.insert("method".into(), toml::Value::String(method.into()));
    if let Some(c) = convention {
        table.insert("convention".into(), toml::Value::String(c.into()));
    }
    table
}

/// A matrix's rows, each cell with its standard deviation when known.
pub fn matrix_rows(m: &[[f64; 3]; 3], sigma: Option<&[[f64; 3]; 3]>) -> Vec<String> {
    m.iter()
        .enumerate()
        .map(|(i, row)| {
            let cells: Vec<String> = row
                .iter()
                .enumerate()
                .map(|(j, x)| match sigma {
                    Some(s) => format!("{x:+.7} ± {:.1e}", s[i][j]),
                    None => format!("{x:+.7}"),
                })
                .collect();
            format!("[{}]", cells.join(", "))
        })
        .collect()
}

/// "  name: [x ± σ, …]".
pub fn vector_line(name: &str, v: &[f64; 3], sigma: Option<&[f64; 3]>) -> String {
    let cells: Vec<String> = v
        .iter()
        .enumerate()
        .map(|(i, x)| match sigma {
            Some(s) => format!("{x:+.6e} ± {:.1e}", s[i]),
            None => format!("{x:+.6e}"),
        })
        .collect();
    format!("  {name}: [{}]", cells.join(", "))
}

/// Adds [`vector_line`] to the report `out`.
pub fn print_vector(out: &mut String, name: &str, v: &[f64; 3], sigma: Option<&[f64; 3]>) {
    outln!(out, "{}", vector_line(name, v, sigma));
}

#[cfg(test)]
mod tests {
    use super::*;

    const M: [[f64; 3]; 3] = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    const B: [f64; 3] = [0.1, -0.2, 0.0];

    fn report(sigmas: bool) -> FitReport<'static> {
        FitReport {
            scale_misalignment: &M,
            sigma_scale_misalignment: sigmas.then_some(&M),
            bias: &B,
            sigma_bias: sigmas.then_some(&B),
            segments: 6,
            dof: 2,
            residual_rms: 1e-3,
            residual_max: 2e-3,
            condition: 5.0,
        }
    }

    #[test]
    fn the_statistics_go_in_the_fit_table() {
        let mut t = method_table("least squares", None);
        report(false).insert_statistics(&mut t);
        assert_eq!(t["segments"].as_integer(), Some(6));
        assert_eq!(t["condition_number"].as_float(), Some(5.0));
        assert_eq!(t["degrees_of_freedom"].as_integer(), Some(2));
        assert!(!t.contains_key("sigma_bias") && !t.contains_key("convention"));
        let mut t = method_table("m", Some("c"));
        report(true).insert_statistics(&mut t);
        assert_eq!(t["sigma_bias"][1].as_float(), Some(-0.2));
        assert_eq!(t["convention"].as_str(), Some("c"));
        assert_eq!(report(true).triad().bias, B);
    }

    #[test]
    fn the_report_names_the_degrees_of_freedom_and_what_2_sigma_covers() {
        let mut out = String::new();
        report(true).print(&mut out, "(I+Σ)", "m/s²", "n = 9");
        // ν = 2: P(|T| ≤ 2) = 2/√6 = 81.6 %.
        assert!(
            out.contains("2 degrees of freedom, so ±2σ covers 81.6 % (Student-t)"),
            "{out}"
        );
        assert!(
            out.contains("bias drift over the session, is not in them"),
            "{out}"
        );
        let mut out = String::new();
        report(false).print(&mut out, "(I+Σ)", "m/s²", "n = 9");
        assert!(
            out.contains("(no standard deviations: n = 9)") && !out.contains("Student"),
            "{out}"
        );
    }

    #[test]
    fn cells_carry_their_standard_deviation_when_known() {
        assert_eq!(
            vector_line("b", &B, None),
            "  b: [+1.000000e-1, -2.000000e-1, +0.000000e0]"
        );
        assert!(vector_line("b", &B, Some(&B)).contains("-2.000000e-1 ± -2.0e-1"));
        let rows = matrix_rows(&M, Some(&M));
        assert_eq!(
            rows[0],
            "[+1.0000000 ± 1.0e0, +0.5000000 ± 5.0e-1, +0.0000000 ± 0.0e0]"
        );
        assert_eq!(
            matrix_rows(&M, None)[1],
            "[+0.0000000, +1.0000000, +0.0000000]"
        );
    }
}
