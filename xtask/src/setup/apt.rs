//! One Debian package installed with apt-get, never at the cost of another:
//! apt-get first simulates the install (`-s`, which needs no root), and a plan
//! that removes or downgrades an installed package is refused with a message
//! naming them and the command the user can run if they accept it. The real
//! install carries `--no-remove` as well, and apt-get's `-y` never
//! downgrades without `--allow-downgrades`, so nothing the simulation missed
//! can remove or downgrade either. apt-get's output goes to stderr.

use super::privilege::{self, Privilege};
use crate::cmd::{check, runs};
use anyhow::{bail, Context, Result};
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

/// Installs `package` and what it depends on (not what it recommends).
pub fn install(package: &str) -> Result<()> {
    if !runs("apt-get") {
        bail!(
            "{package} is missing and apt-get is not on PATH: install {package} \
             (or your system's package of it) with your package manager, then run this again"
        );
    }
    let update = "apt-get update".to_string();
    let by_hand = format!("apt-get install --no-install-recommends --no-remove {package}");
    let privilege = match privilege::detect() {
        Ok(privilege) => privilege,
        Err(refusal) => bail!(
            "installing {package} needs root, and {}. Run\n    {}\nthen run this command again",
            match refusal {
                privilege::Refusal::SudoAsks => "sudo asks for a password",
                privilege::Refusal::NoSudo => "there is no sudo",
            },
            refusal.instead(&[update, by_hand])
        ),
    };
    run(privilege, &["update"])?;

    let plan = simulate(package)?;
    if !plan.remove.is_empty() || !plan.downgrade.is_empty() {
        bail!("{}", refusal_message(package, &plan, privilege));
    }
    eprintln!(
        "xtask: apt-get installs {} package(s): {}",
        plan.install.len(),
        plan.install.join(" ")
    );
    run(
        privilege,
        &[
            "install",
            "-y",
            "--no-install-recommends",
            "--no-remove",
            package,
        ],
    )
}

/// The message of a refused plan: what would go, and what to run instead.
fn refusal_message(package: &str, plan: &Plan, privilege: Privilege) -> String {
    let mut harm = Vec::new();
    if !plan.remove.is_empty() {
        harm.push(format!("remove {}", plan.remove.join(", ")));
    }
    if !plan.downgrade.is_empty() {
        harm.push(format!("downgrade {}", plan.downgrade.join(", ")));
    }
    let sudo = match privilege {
        Privilege::Root => "",
        Privilege::Sudo => "sudo ",
    };
    format!(
        "installing {package} would {}, and xtask never removes or downgrades an installed \
         package. See what apt-get would do with\n    \
         apt-get install -s --no-install-recommends {package}\n\
         and if you accept it, run\n    \
         {sudo}apt-get install --no-install-recommends {package}\n\
         (or install {package} another way); then run this command again",
        harm.join(" and ")
    )
}

/// apt-get's simulation of installing `package`.
fn simulate(package: &str) -> Result<Plan> {
    let output = Command::new("apt-get")
        .args(["install", "-s", "--no-install-recommends", package])
        .env("LC_ALL", "C")
        .stderr(Stdio::inherit())
        .output()
        .context("running apt-get install -s")?;
    if !output.status.success() {
        bail!(
            "`apt-get install -s --no-install-recommends {package}` failed ({}): apt-get \
             cannot install {package} here",
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
        assert!(plan.remove.is_empty() && plan.downgrade.is_empty());
    }

    #[test]
    fn the_refusal_names_the_conflict_and_the_command() {
        let plan = parse_simulation(REMOVES);
        let message = refusal_message("qemu-system-arm", &plan, Privilege::Sudo);
        assert!(message.starts_with("installing qemu-system-arm would remove qemu-utils,"));
        assert!(message
            .contains("\n    sudo apt-get install --no-install-recommends qemu-system-arm\n"));
    }
}
