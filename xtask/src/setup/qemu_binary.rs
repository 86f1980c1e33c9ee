//! Which qemu-system-arm runs the emulated boards: the one on PATH when it is
//! QEMU 7.2 or later (the version the emulated board's timing was checked
//! on), else the one unpacked from Debian's package into the workspace's
//! `target/` (see [`super::qemu_unpacked`]).

use crate::cmd::root;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The program's name, on PATH and in Debian's package.
pub const NAME: &str = "qemu-system-arm";

/// The oldest QEMU (major, minor) the emulated board runs on.
pub const MINIMUM: (u32, u32) = (7, 2);

/// The qemu-system-arm to run: [`find`]'s answer, else the bare name (so a
/// missing QEMU fails with "starting qemu-system-arm" where it is spawned).
pub fn qemu() -> PathBuf {
    find().unwrap_or_else(|| PathBuf::from(NAME))
}

/// PATH's qemu-system-arm when it runs and is [`MINIMUM`] or later, else the
/// unpacked one when it does; `None` when neither.
pub fn find() -> Option<PathBuf> {
    [PathBuf::from(NAME), unpacked()]
        .into_iter()
        .find(|program| version_of(program).is_some_and(|v| v >= MINIMUM))
}

/// Where xtask unpacks Debian's package: `XTASK_QEMU_DIR` when set (relative
/// to the workspace root), else `target/qemu-deb/` in the workspace root,
/// beside xtask's other artefacts (whatever `CARGO_TARGET_DIR` says, like
/// them), so a clean clone makes it and the next run finds it.
pub fn cache_dir() -> PathBuf {
    match std::env::var_os("XTASK_QEMU_DIR") {
        Some(dir) => root().join(dir),
        None => root().join("target/qemu-deb"),
    }
}

/// The unpacked package's tree (`dpkg-deb -x` writes it).
pub fn unpacked_tree() -> PathBuf {
    cache_dir().join("root")
}

/// The qemu-system-arm in [`unpacked_tree`].
pub fn unpacked() -> PathBuf {
    unpacked_tree().join("usr/bin").join(NAME)
}

/// The (major, minor) `program --version` reports; `None` when it does not
/// run, fails, or says something else.
pub fn version_of(program: &Path) -> Option<(u32, u32)> {
    let output = Command::new(program)
        .arg("--version")
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    parse_version(&String::from_utf8_lossy(&output.stdout))
}

/// The (major, minor) of QEMU's `--version` text, whose first line is
/// `QEMU emulator version 7.2.19 (Debian 1:7.2+dfsg-7+deb12u18+b3)`.
pub fn parse_version(text: &str) -> Option<(u32, u32)> {
    let first = text.lines().next()?;
    let (_, rest) = first.split_once("version ")?;
    major_minor(rest)
}

/// The (major, minor) at the start of `text` ("7.2.19 (Debian ...)", "7.2+dfsg").
pub fn major_minor(text: &str) -> Option<(u32, u32)> {
    let number = |s: &str| -> Option<(u32, usize)> {
        let digits = s.len() - s.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        Some((s[..digits].parse().ok()?, digits))
    };
    let (major, used) = number(text)?;
    let rest = text[used..].strip_prefix('.')?;
    let (minor, _) = number(rest)?;
    Some((major, minor))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debian_twelve_qemu_reads_as_seven_two() {
        let text = "QEMU emulator version 7.2.19 (Debian 1:7.2+dfsg-7+deb12u18+b3)\n\
                    Copyright (c) 2003-2022 Fabrice Bellard and the QEMU Project developers\n";
        assert_eq!(parse_version(text), Some((7, 2)));
    }

    #[test]
    fn an_older_qemu_is_below_the_minimum_and_a_newer_one_above() {
        let old = parse_version("QEMU emulator version 6.2.0 (Debian 1:6.2+dfsg-2ubuntu6)");
        let new = parse_version("QEMU emulator version 10.0.2 (Debian 1:10.0.2+ds-2)");
        assert!(old.unwrap() < MINIMUM);
        assert_eq!(new, Some((10, 0)));
        assert!(new.unwrap() >= MINIMUM);
    }

    #[test]
    fn text_without_a_version_has_none() {
        assert_eq!(parse_version("qemu-system-arm: command not found"), None);
        assert_eq!(parse_version("QEMU emulator version seven"), None);
        assert_eq!(major_minor("7"), None);
        assert_eq!(major_minor("7.x"), None);
    }

    #[test]
    fn the_unpacked_binary_is_in_the_unpacked_tree() {
        assert!(unpacked().starts_with(cache_dir()));
        assert!(unpacked().ends_with("root/usr/bin/qemu-system-arm"));
    }
}
