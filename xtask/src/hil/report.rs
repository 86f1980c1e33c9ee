//! The procedure's report: what was run, each step's verdict and the figures
//! behind it, as Markdown a person can read and send back.

use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

/// One step of the procedure.
pub struct Step {
    /// What it checks, e.g. "stream 3 s at 8000 Hz, W = 32: zero loss".
    pub name: String,
    /// Whether it passed.
    pub passed: bool,
    /// The figures and the reason, a line each.
    pub detail: Vec<String>,
    /// The commands it ran, as a person would type them.
    pub commands: Vec<String>,
}

/// The whole report.
pub struct Report {
    /// `name: value` lines about the run (board, port, firmware, host).
    pub facts: Vec<(String, String)>,
    /// The steps, in order.
    pub steps: Vec<Step>,
}

impl Report {
    /// True when every step passed.
    pub fn passed(&self) -> bool {
        !self.steps.is_empty() && self.steps.iter().all(|s| s.passed)
    }

    /// The report as Markdown.
    pub fn markdown(&self) -> String {
        let mut out = String::from("# triad hardware-in-the-loop report\n\n");
        for (name, value) in &self.facts {
            let _ = writeln!(out, "- {name}: {value}");
        }
        let failed = self.steps.iter().filter(|s| !s.passed).count();
        let _ = writeln!(
            out,
            "\n**Verdict: {}** ({} of {} steps passed)\n",
            if self.passed() { "PASS" } else { "FAIL" },
            self.steps.len() - failed,
            self.steps.len()
        );
        out.push_str("| # | step | verdict |\n|---|---|---|\n");
        for (i, step) in self.steps.iter().enumerate() {
            let _ = writeln!(
                out,
                "| {} | {} | {} |",
                i + 1,
                step.name,
                if step.passed { "pass" } else { "**FAIL**" }
            );
        }
        for (i, step) in self.steps.iter().enumerate() {
            let _ = writeln!(out, "\n## {}. {}\n", i + 1, step.name);
            for line in &step.detail {
                let _ = writeln!(out, "- {line}");
            }
            if !step.commands.is_empty() {
                out.push_str("\n```\n");
                for command in &step.commands {
                    let _ = writeln!(out, "{command}");
                }
                out.push_str("```\n");
            }
        }
        out
    }

    /// Writes the report to `path`, whole or not at all.
    pub fn write(&self, path: &Path) -> Result<()> {
        let part = path.with_extension("md.part");
        std::fs::write(&part, self.markdown())
            .and_then(|()| std::fs::rename(&part, path))
            .with_context(|| format!("writing the report {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(name: &str, passed: bool) -> Step {
        Step {
            name: name.into(),
            passed,
            detail: vec!["a figure".into()],
            commands: vec!["triad device info".into()],
        }
    }

    #[test]
    fn one_failed_step_fails_the_report_and_is_marked() {
        let report = Report {
            facts: vec![("board".into(), "qemu".into())],
            steps: vec![step("identify", true), step("stream", false)],
        };
        assert!(!report.passed());
        let text = report.markdown();
        assert!(text.contains("**Verdict: FAIL** (1 of 2 steps passed)"));
        assert!(text.contains("| 2 | stream | **FAIL** |"));
        assert!(text.contains("- board: qemu"));
    }

    #[test]
    fn a_report_without_steps_does_not_pass() {
        let report = Report {
            facts: vec![],
            steps: vec![],
        };
        assert!(!report.passed());
    }
}
