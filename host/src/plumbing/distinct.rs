//! A command's outputs are never one of its inputs, nor each other:
//! `allan x.csv --out x.csv` or `sim --out t.csv --truth t.csv` would
//! destroy the input or mix two outputs in one file. Paths are compared as
//! files: canonicalised (symbolic links and `..` resolved; for an output
//! that does not exist yet, its directory canonicalised), and on Unix by
//! device and inode too (hard links).

use std::path::{Path, PathBuf};

use anyhow::bail;

use crate::plumbing::outfile::is_stdout;

/// A path with the option (or argument) that gave it, for messages.
#[derive(Clone, Copy, Debug)]
pub struct Named<'a> {
    /// `--out`, `input`, ….
    pub what: &'a str,
    /// The path as given.
    pub path: &'a Path,
}

/// `what` `path` as a [`Named`].
pub fn named<'a>(what: &'a str, path: &'a Path) -> Named<'a> {
    Named { what, path }
}

/// What identifies a file.
#[derive(Debug, PartialEq)]
struct Identity {
    canonical: Option<PathBuf>,
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn of(path: &Path) -> Identity {
        let canonical = std::fs::canonicalize(path).ok().or_else(|| {
            // Not there yet: its directory canonicalised, then its name.
            let name = path.file_name()?;
            let parent = match path.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            Some(std::fs::canonicalize(parent).ok()?.join(name))
        });
        Identity {
            canonical,
            inode: inode(path),
        }
    }

    fn same(&self, other: &Identity) -> bool {
        fn both<T: PartialEq>(a: &Option<T>, b: &Option<T>) -> bool {
            a.is_some() && a == b
        }
        both(&self.canonical, &other.canonical) || both(&self.inode, &other.inode)
    }
}

#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(path).ok()?;
    // Devices (/dev/null) are shared by design: not compared by inode.
    m.is_file().then(|| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn inode(_: &Path) -> Option<(u64, u64)> {
    None
}

/// Refuses an output that is an input or another output; at most one
/// output may be standard output (`-`).
pub fn check(inputs: &[Named], outputs: &[Named]) -> anyhow::Result<()> {
    let ins: Vec<(Named, Identity)> = inputs
        .iter()
        .filter(|n| !is_stdout(n.path))
        .map(|n| (*n, Identity::of(n.path)))
        .collect();
    let mut seen: Vec<(Named, Option<Identity>)> = Vec::new();
    for out in outputs {
        if is_stdout(out.path) {
            if let Some((other, _)) = seen.iter().find(|(o, _)| is_stdout(o.path)) {
                bail!(
                    "{} - and {} -: only one output can go to standard output",
                    other.what,
                    out.what
                );
            }
            seen.push((*out, None));
            continue;
        }
        let id = Identity::of(out.path);
        if let Some((input, _)) = ins.iter().find(|(_, i)| i.same(&id)) {
            bail!(
                "{} {} is the same file as the {} {}: refusing to write over an input",
                out.what,
                out.path.display(),
                input.what,
                input.path.display()
            );
        }
        if let Some((other, _)) = seen
            .iter()
            .find(|(_, i)| i.as_ref().is_some_and(|i| i.same(&id)))
        {
            bail!(
                "{} {} and {} {} are the same file: give each output its own path",
                other.what,
                other.path.display(),
                out.what,
                out.path.display()
            );
        }
        seen.push((*out, Some(id)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("triad-distinct-{}", std::process::id()));
        std::fs::create_dir_all(d.join("sub")).unwrap();
        std::fs::write(d.join("in.csv"), "t\n").unwrap();
        d
    }

    #[test]
    fn an_output_over_an_input_is_refused_by_any_spelling() {
        let d = dir();
        let input = d.join("in.csv");
        let other_spelling = d.join("sub/../in.csv");
        let err = check(
            &[named("input", &input)],
            &[named("--out", &other_spelling)],
        )
        .unwrap_err()
        .to_string();
        assert!(err.starts_with("--out "), "{err}");
        assert!(err.contains("is the same file as the input"), "{err}");
        #[cfg(unix)]
        {
            let link = d.join("hard.csv");
            let _ = std::fs::remove_file(&link);
            std::fs::hard_link(&input, &link).unwrap();
            assert!(check(&[named("input", &input)], &[named("--out", &link)]).is_err());
        }
        assert!(check(
            &[named("input", &input)],
            &[named("--out", &d.join("o.csv"))]
        )
        .is_ok());
    }

    #[test]
    fn two_outputs_must_differ_even_before_they_exist() {
        let d = dir();
        let a = d.join("new.csv");
        let b = d.join("sub/../new.csv");
        let err = check(&[], &[named("--out", &a), named("--truth", &b)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("are the same file: give each output its own path"),
            "{err}"
        );
        let dash = Path::new("-");
        let err = check(&[], &[named("--out", dash), named("--truth", dash)])
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "--out - and --truth -: only one output can go to standard output"
        );
        // Standard input and standard output are not files.
        assert!(check(&[named("input", dash)], &[named("--out", dash)]).is_ok());
    }
}
