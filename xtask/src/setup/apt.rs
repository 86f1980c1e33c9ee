//! Debian packages installed with apt-get, never at the cost of another:
//! apt-get first simulates the install (`-s`, which needs no root), and a plan
//! that removes or downgrades an installed package is refused with a message
//! naming them and the command the user can run if they accept it. The real
//! install carries `--no-remove` as well, and apt-get's `-y` never
//! downgrades without `--allow-downgrades`, so nothing the simulation missed
//! can remove or downgrade either. apt-get's output goes to stderr.

use super::privilege::{Privilege, Refusal};
use crate::cmd::{check, runs};
use anyhow::{anyhow, bail, Context, Result};
use std::process::{Command, Stdio};

/// What an `apt-get install -s` would do.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Plan {
    /// Packages installed or upgraded (`Inst` lines).
    pub install: Vec<String>,
    /// Installed packages it would remove.
    pub remove: Vec<String>,
    /// Installed packages it would downgrade.
    pub downgrade: Vec<String>,
}

/// A heading of apt-get's summary ("The following packages will be ...").
#[derive(Clone, Copy)]
enum Heading {
    Removed,
    Downgraded,
    Other,
}

/// Reads the plan from apt-get's simulation output (in the C locale): the
/// `Inst` and `Remv` lines, and the package lists under "will be REMOVED"
/// and "will be DOWNGRADED" (apt-get marks a downgrade only there).
pub fn parse_simulation(text: &str) -> Plan {
    let mut plan = Plan::default();
    // The list under the last heading: indented lines are its package names.
    let mut section = Heading::Other;
    for line in text.lines() {
        if line.starts_with(' ') {
            let names = line.split_whitespace().map(|n| n.trim_end_matches('*'));
            match section {
                Heading::Removed => plan.remove.extend(names.map(str::to_string)),
                Heading::Downgraded => plan.downgrade.extend(names.map(str::to_string)),
                Heading::Other => {}
            }
            continue;
        }
        section = Heading::Other;
        let first_word = |rest: &str| rest.split_whitespace().next().map(str::to_string);
        if let Some(rest) = line.strip_prefix("Inst ") {
            plan.install.extend(first_word(rest));
        } else if let Some(rest) = line.strip_prefix("Remv ") {
            plan.remove.extend(first_word(rest));
        } else if line.starts_with("The following packages will be REMOVED") {
            section = Heading::Removed;
        } else if line.starts_with("The following packages will be DOWNGRADED") {
            section = Heading::Downgraded;
        }
    }
    for list in [&mut plan.remove, &mut plan.downgrade] {
        list.sort();
        list.dedup();
    }
    plan
}

impl Plan {
    /// True when the plan removes or downgrades an installed package.
    pub fn harms(&self) -> bool {
        !self.remove.is_empty() || !self.downgrade.is_empty()
    }

    /// What it would remove and downgrade: "remove qemu-utils".
    pub fn harm(&self) -> String {
        let mut harm = Vec::new();
        if !self.remove.is_empty() {
            harm.push(format!("remove {}", self.remove.join(", ")));
        }
        if !self.downgrade.is_empty() {
            harm.push(format!("downgrade {}", self.downgrade.join(", ")));
        }
        harm.join(" and ")
    }
}

/// Fails, saying what to do instead, when apt-get is not on PATH.
pub fn require(what: &str) -> Result<()> {
    if !runs("apt-get") {
        bail!(
            "{what} is missing and apt-get is not on PATH: install {what} \
             (or your system's package of it) with your package manager, then run this again"
        );
    }
    Ok(())
}

/// The error for installing `packages` without root: which commands to run
/// as root instead (`apt-get update`, then the install), and why xtask
/// cannot.
pub fn needs_root(refusal: Refusal, packages: &[&str]) -> anyhow::Error {
    let packages = packages.join(" ");
    let commands = [
        "apt-get update".to_string(),
        format!("apt-get install --no-install-recommends --no-remove {packages}"),
    ];
    anyhow!(
        "installing {packages} needs root, and {}. Run\n    {}\nthen run this command again",
        match refusal {
            Refusal::SudoAsks => "sudo asks for a password",
            Refusal::NoSudo => "there is no sudo",
        },
        refusal.instead(&commands)
    )
}

/// `apt-get update`: the package lists the plan is made from.
pub fn update(privilege: Privilege) -> Result<()> {
    run(privilege, &["update"])
}

/// Installs `packages` and what they depend on (not what they recommend)
/// following `plan`, their simulation: a plan that removes or downgrades is
/// refused with [`refusal_message`].
pub fn install(privilege: Privilege, packages: &[&str], plan: &Plan) -> Result<()> {
    if plan.harms() {
        bail!("{}", refusal_message(packages, plan, privilege));
    }
    note!(
        "xtask: apt-get installs {} package(s): {}",
        plan.install.len(),
        plan.install.join(" ")
    );
    let mut args = vec!["install", "-y", "--no-install-recommends", "--no-remove"];
    args.extend(packages);
    run(privilege, &args)
}

/// The message of a refused plan: what would go, and what to run instead.
fn refusal_message(packages: &[&str], plan: &Plan, privilege: Privilege) -> String {
    let sudo = match privilege {
        Privilege::Root => "",
        Privilege::Sudo => "sudo ",
    };
    let packages = packages.join(" ");
    format!(
        "installing {packages} would {}, and xtask never removes or downgrades an installed \
         package. See what apt-get would do with\n    \
         apt-get install -s --no-install-recommends {packages}\n\
         and if you accept it, run\n    \
         {sudo}apt-get install --no-install-recommends {packages}\n\
         (or install {packages} another way); then run this command again",
        plan.harm()
    )
}

/// apt-get's simulation of installing `packages` (no root needed).
pub fn simulate(packages: &[&str]) -> Result<Plan> {
    let output = Command::new("apt-get")
        .args(["install", "-s", "--no-install-recommends"])
        .args(packages)
        .env("LC_ALL", "C")
        .stderr(Stdio::inherit())
        .output()
        .context("running apt-get install -s")?;
    let packages = packages.join(" ");
    if !output.status.success() {
        bail!(
            "`apt-get install -s --no-install-recommends {packages}` failed ({}): apt-get \
             cannot install {packages} here",
            output.status
        );
    }
    Ok(parse_simulation(&String::from_utf8_lossy(&output.stdout)))
}

/// `apt-get ARGS` as root, unattended, its output on stderr.
fn run(privilege: Privilege, args: &[&str]) -> Result<()> {
    let mut command = privilege.command("apt-get");
    command
        .args(args)
        .env("DEBIAN_FRONTEND", "noninteractive")
        .stdin(Stdio::null());
    check(command, &format!("`apt-get {}`", args.join(" ")))
        .context("apt-get stopped, and nothing was removed")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// apt-get 2.6's simulation (Debian 12, LC_ALL=C) of a plan that removes.
    const REMOVES: &str = "\
Reading package lists...
Building dependency tree...
Reading state information...
The following additional packages will be installed:
  qemu-system-common qemu-system-data
The following packages will be REMOVED:
  qemu-utils*
The following NEW packages will be installed:
  qemu-system-arm qemu-system-common qemu-system-data
0 upgraded, 3 newly installed, 1 to remove and 132 not upgraded.
Remv qemu-utils [1:7.2+dfsg-7+deb12u18+b3]
Inst qemu-system-data (1:7.2+dfsg-7+deb12u18 Debian:12.13/stable [all])
Inst qemu-system-common (1:7.2+dfsg-7+deb12u18+b3 Debian:12.13/stable [amd64])
Inst qemu-system-arm (1:7.2+dfsg-7+deb12u18+b3 Debian:12.13/stable [amd64])
Conf qemu-system-data (1:7.2+dfsg-7+deb12u18 Debian:12.13/stable [all])
";

    #[test]
    fn a_removal_is_read_from_the_list_and_the_remv_line() {
        let plan = parse_simulation(REMOVES);
        assert_eq!(plan.remove, ["qemu-utils"]);
        assert!(plan.downgrade.is_empty());
        assert_eq!(
            plan.install,
            ["qemu-system-data", "qemu-system-common", "qemu-system-arm"]
        );
    }

    #[test]
    fn a_removal_or_a_downgrade_harms_and_says_which() {
        let plan = parse_simulation(REMOVES);
        assert!(plan.harms());
        assert_eq!(plan.harm(), "remove qemu-utils");
        let both = Plan {
            remove: vec!["a".into()],
            downgrade: vec!["b".into(), "c".into()],
            ..Plan::default()
        };
        assert_eq!(both.harm(), "remove a and downgrade b, c");
    }

    #[test]
    fn a_downgrade_is_read_from_its_list() {
        let text = "The following packages will be DOWNGRADED:\n  libfdt1 libslirp0\n\
                    0 upgraded, 0 newly installed, 2 downgraded, 0 to remove.\n\
                    Inst libfdt1 [1.7.0] (1.6.1 Debian:12 [amd64])\n";
        let plan = parse_simulation(text);
        assert_eq!(plan.downgrade, ["libfdt1", "libslirp0"]);
        assert!(plan.remove.is_empty());
    }

    #[test]
    fn a_clean_plan_neither_removes_nor_downgrades() {
        let text = "The following NEW packages will be installed:\n  qemu-system-arm\n\
                    Inst qemu-system-arm (1:7.2 Debian:12 [amd64])\n";
        let plan = parse_simulation(text);
        assert_eq!(plan.install, ["qemu-system-arm"]);
        assert!(!plan.harms());
    }

    #[test]
    fn the_refusal_names_the_conflict_and_the_command() {
        let plan = parse_simulation(REMOVES);
        let message = refusal_message(&["qemu-system-arm"], &plan, Privilege::Sudo);
        assert!(message.starts_with("installing qemu-system-arm would remove qemu-utils,"));
        assert!(message
            .contains("\n    sudo apt-get install --no-install-recommends qemu-system-arm\n"));
    }
}
