//! What apt knows about a package without installing it (no root needed):
//! the version it would install (`apt-cache policy`) and what that version
//! depends on (`apt-cache show`).

use anyhow::{bail, Context, Result};
use std::process::{Command, Stdio};

/// The version `apt-get install package` would install.
pub fn candidate(package: &str) -> Result<String> {
    let text = query(&["policy", package])?;
    match parse_candidate(&text) {
        Some(version) => Ok(version),
        None => bail!(
            "`apt-cache policy {package}` names no candidate version: no apt source \
             here has {package}"
        ),
    }
}

/// The Depends field of `package` at `version`.
pub fn depends(package: &str, version: &str) -> Result<String> {
    let text = query(&["show", &format!("{package}={version}")])?;
    match parse_field(&text, "Depends") {
        Some(field) => Ok(field),
        None => bail!("`apt-cache show {package}={version}` has no Depends field"),
    }
}

/// The `Candidate:` of `apt-cache policy`'s output (C locale); `None` when
/// it is missing or `(none)`.
pub fn parse_candidate(text: &str) -> Option<String> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix("Candidate:"))
        .map(str::trim)
        .filter(|v| !v.is_empty() && *v != "(none)")
        .map(str::to_string)
}

/// Field `name` of the first stanza of `apt-cache show`'s output, its
/// continuation lines (which start with a space) joined on.
pub fn parse_field(text: &str, name: &str) -> Option<String> {
    let first_stanza = text.split("\n\n").next()?;
    let mut lines = first_stanza.lines();
    let prefix = format!("{name}:");
    let mut value = lines
        .find_map(|l| l.strip_prefix(&prefix))?
        .trim()
        .to_string();
    for more in lines.take_while(|l| l.starts_with([' ', '\t'])) {
        value.push(' ');
        value.push_str(more.trim());
    }
    Some(value)
}

fn query(args: &[&str]) -> Result<String> {
    let output = Command::new("apt-cache")
        .args(args)
        .env("LC_ALL", "C")
        .stdin(Stdio::null())
        .stderr(Stdio::inherit())
        .output()
        .with_context(|| format!("running apt-cache {}", args.join(" ")))?;
    if !output.status.success() {
        bail!("`apt-cache {}` failed ({})", args.join(" "), output.status);
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_candidate_is_read_from_the_policy() {
        let text = "qemu-system-arm:\n  Installed: (none)\n  Candidate: 1:7.2+dfsg-7+deb12u18+b3\n\
                    \x20 Version table:\n     1:7.2+dfsg-7+deb12u18+b3 500\n";
        assert_eq!(
            parse_candidate(text).as_deref(),
            Some("1:7.2+dfsg-7+deb12u18+b3")
        );
    }

    #[test]
    fn no_candidate_is_none() {
        assert_eq!(
            parse_candidate("qemu-system-arm:\n  Installed: (none)\n  Candidate: (none)\n"),
            None
        );
        assert_eq!(parse_candidate(""), None);
    }

    #[test]
    fn the_field_comes_from_the_first_stanza_with_its_continuation() {
        let text = "Package: p\nVersion: 1\nDepends: liba (>= 1),\n libb\nRecommends: c\n\n\
                    Package: p\nVersion: 1\nDepends: other\n";
        assert_eq!(
            parse_field(text, "Depends").as_deref(),
            Some("liba (>= 1), libb")
        );
        assert_eq!(parse_field(text, "Pre-Depends"), None);
    }
}
