//! What a fit says about the gyroscope's g-sensitivity G and about its
//! poses' consistency test ([`triad_lab::calib_fit::fits::g_sensitivity`]): the
//! report's lines (G in °/s per g, the SI unit of the file at the edge only)
//! and the `[fit.gyro]` entries.

use triad::units::si_to_dps_per_g;
use triad_lab::calib_fit::fits::g_sensitivity::{
    Consistency, NotSupported, Support, MAX_CONDITION, POSE_FAMILY_LEVEL, SIGNIFICANCE,
};

use super::report::matrix_rows;
use crate::plumbing::stdio::outln;

/// The report's G section and the line that states the poses' check.
pub fn print(out: &mut String, support: &Support, check: &Consistency, poses: usize) {
    match support {
        Support::NotSupported(NotSupported::TooFewPoses { poses, needed }) => outln!(
            out,
            "  g-sensitivity G: not supported: {poses} poses, {needed} needed (G and the bias are 4 unknowns per axis)"
        ),
        Support::NotSupported(NotSupported::Directions { condition, limit }) => outln!(
            out,
            "  g-sensitivity G: not supported: the poses' gravity directions do not span three dimensions \
             (condition number {condition:.3e}, limit {limit}); pose the unit along three independent \
             directions and at least one opposite to fit it"
        ),
        Support::Fitted(fit) => {
            let per_g = |m: &[[f64; 3]; 3]| m.map(|row| row.map(si_to_dps_per_g));
            let verdict = if fit.significant {
                "shown by the poses: in the calibration"
            } else {
                "consistent with zero: left out of the calibration"
            };
            outln!(
                out,
                "  g-sensitivity G, °/s per g (gyro bias per unit specific force; rows the gyro's axes, \
                 columns the accelerometer's corrected axes), {} degrees of freedom: {verdict}",
                fit.dof
            );
            for row in matrix_rows(&per_g(&fit.g), Some(&per_g(&fit.sigma_g))) {
                outln!(out, "    {row}");
            }
            outln!(
                out,
                "    F-test per row (the row is zero): p = {:.2e}, {:.2e}, {:.2e} (family-wise level {SIGNIFICANCE} \
                 over the rows); condition number {:.2} (limit {MAX_CONDITION})",
                fit.p_values[0],
                fit.p_values[1],
                fit.p_values[2],
                fit.condition
            );
        }
    }
    if check.dof == 0 {
        outln!(
            out,
            "  poses' consistency: not checked ({poses} poses leave no degree of freedom to predict one from the others)"
        );
    } else {
        outln!(
            out,
            "  poses' consistency: each pose's gyro mean within {:.2} σ of what the other poses predict \
             (their bias{}; σ from their scatter, {} degrees of freedom, and the pose's standard error; \
             Student-t at a family-wise level of {POSE_FAMILY_LEVEL} over {poses} poses × 3 axes); \
             the largest: pose {} {} at {:.2} σ",
            check.sigmas,
            if check.with_g { " and g-sensitivity" } else { "" },
            check.dof,
            check.worst.0 + 1,
            ["x", "y", "z"][check.worst.1.min(2)],
            check.worst.2
        );
    }
}

/// The `[fit.gyro]` entries: `g_sensitivity` (how it was decided, its σ's
/// in SI, the degrees of freedom) and `pose_consistency_sigmas`.
pub fn insert(table: &mut toml::Table, support: &Support, check: &Consistency) {
    let matrix = |m: &[[f64; 3]; 3]| {
        toml::Value::Array(
            m.iter()
                .map(|row| toml::Value::Array(row.iter().map(|&x| toml::Value::Float(x)).collect()))
                .collect(),
        )
    };
    let mut g = toml::Table::new();
    match support {
        Support::NotSupported(_) => {
            g.insert(
                "status".into(),
                toml::Value::String("not supported by the poses".into()),
            );
        }
        Support::Fitted(fit) => {
            let status = if fit.significant {
                "fitted: in [gyro].g_sensitivity"
            } else {
                "consistent with zero: not applied"
            };
            g.insert("status".into(), toml::Value::String(status.into()));
            g.insert("unit".into(), toml::Value::String("(rad/s)/(m/s²)".into()));
            g.insert("value".into(), matrix(&fit.g));
            g.insert("sigma".into(), matrix(&fit.sigma_g));
            g.insert(
                "degrees_of_freedom".into(),
                toml::Value::Integer(fit.dof as i64),
            );
            g.insert(
                "row_p_values".into(),
                toml::Value::Array(
                    fit.p_values
                        .iter()
                        .map(|&p| toml::Value::Float(p))
                        .collect(),
                ),
            );
        }
    }
    table.insert("g_sensitivity".into(), toml::Value::Table(g));
    if check.dof > 0 {
        table.insert(
            "pose_consistency_sigmas".into(),
            toml::Value::Float(check.sigmas),
        );
    }
}
