//! Root for the package manager: being root, or sudo that asks no password
//! (xtask runs unattended, and a password prompt would hang in a pipe).

use std::process::{Command, Stdio};

/// How a command runs as root.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Privilege {
    /// xtask is root.
    Root,
    /// `sudo -n` works without a password.
    Sudo,
}

/// Why root cannot be had, for the message that says what to run instead.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// sudo is there but wants a password (or refuses).
    SudoAsks,
    /// Not root, and no sudo.
    NoSudo,
}

/// The privilege at hand, or why there is none.
pub fn detect() -> Result<Privilege, Refusal> {
    if is_root() {
        return Ok(Privilege::Root);
    }
    let sudo = Command::new("sudo")
        .args(["-n", "true"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    match sudo {
        Ok(status) if status.success() => Ok(Privilege::Sudo),
        Ok(_) => Err(Refusal::SudoAsks),
        Err(_) => Err(Refusal::NoSudo),
    }
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .stderr(Stdio::null())
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0")
}

impl Privilege {
    /// `program` to be run as root.
    pub fn command(self, program: &str) -> Command {
        match self {
            Privilege::Root => Command::new(program),
            Privilege::Sudo => {
                let mut command = Command::new("sudo");
                command.args(["-n", program]);
                command
            }
        }
    }
}

impl Refusal {
    /// How the user runs `commands` (each `program args`) as root: with sudo
    /// when it is there, else as root.
    pub fn instead(self, commands: &[String]) -> String {
        match self {
            Refusal::SudoAsks => commands
                .iter()
                .map(|c| format!("sudo {c}"))
                .collect::<Vec<_>>()
                .join(" && "),
            Refusal::NoSudo => format!("(as root) {}", commands.join(" && ")),
        }
    }
}
