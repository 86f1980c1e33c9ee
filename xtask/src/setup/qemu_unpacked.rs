//! QEMU without installing Debian's qemu-system-arm, for machines where
//! installing it would remove or downgrade a package (Debian 12's
//! qemu-system-common 7.2, which qemu-system-arm needs at its own version, is
//! broken by the qemu-utils 10 of bookworm-backports). Three steps:
//!
//! 1. apt-get installs the shared libraries the package's binary links
//!    against that are missing: its Depends, less qemu-system-common and
//!    qemu-system-data (helpers, modules for other guests and displays, ROMs
//!    and keymaps: the emulated boards boot an ELF with `-kernel` and have no
//!    display, so they use none of it), with the same plan check as any
//!    install;
//! 2. `apt-get download` fetches the package at the version those Depends
//!    were read from, into [`cache_dir`] (no root needed);
//! 3. `dpkg-deb -x` unpacks it there (the .deb is then deleted), and
//!    [`super::qemu_binary`] runs its qemu-system-arm from then on.

use super::apt;
use super::apt_cache;
use super::depends;
use super::privilege::{Privilege, Refusal};
use super::qemu_binary::{cache_dir, major_minor, unpacked, unpacked_tree, MINIMUM, NAME};
use crate::cmd::check;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The Depends the unpacked binary does without (see the module's doc).
pub const NOT_NEEDED: [&str; 2] = ["qemu-system-common", "qemu-system-data"];

/// The three steps, announced on stderr as each starts; `privilege` is needed
/// only when a library is missing.
pub fn install(privilege: Result<Privilege, Refusal>) -> Result<()> {
    let version = apt_cache::candidate(NAME)?;
    if !debian_version_is_new_enough(&version) {
        bail!(
            "apt-get's {NAME} is version {version}, older than QEMU {}.{}: install QEMU {}.{} \
             or later so that {NAME} is on PATH",
            MINIMUM.0,
            MINIMUM.1,
            MINIMUM.0,
            MINIMUM.1
        );
    }
    install_libraries(&version, privilege)?;

    let dir = cache_dir();
    if dir.exists() {
        std::fs::remove_dir_all(&dir).with_context(|| format!("emptying {}", dir.display()))?;
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let pinned = format!("{NAME}={version}");
    note!(
        "xtask: step 2/3: downloading the package {pinned} (not installing it) with \
         `apt-get download {pinned}` into {}; no root needed",
        dir.display()
    );
    let mut download = Command::new("apt-get");
    download
        .args(["download", &pinned])
        .current_dir(&dir)
        .stdin(Stdio::null());
    check(download, &format!("`apt-get download {pinned}`"))?;
    let deb = the_deb_in(&dir)?;

    let tree = unpacked_tree();
    note!(
        "xtask: step 3/3: unpacking it with `dpkg-deb -x {} {}`; xtask runs {} from there",
        deb.display(),
        tree.display(),
        unpacked().display()
    );
    let mut unpack = Command::new("dpkg-deb");
    unpack.arg("-x").arg(&deb).arg(&tree);
    check(unpack, &format!("`dpkg-deb -x {}`", deb.display()))?;
    // Unpacked, the .deb is 9 MB of nothing: the next fallback downloads afresh.
    std::fs::remove_file(&deb).with_context(|| format!("removing {}", deb.display()))?;
    check_it_runs(&unpacked())
}

/// Step 1: the missing libraries of `NAME` at `version`, through apt-get.
fn install_libraries(version: &str, privilege: Result<Privilege, Refusal>) -> Result<()> {
    let field = apt_cache::depends(NAME, version)?;
    let relations = depends::parse(&field)
        .with_context(|| format!("reading the Depends of {NAME} {version}"))?;
    let names: Vec<&str> = relations
        .iter()
        .flatten()
        .map(|d| d.name.as_str())
        .collect();
    let installed = depends::installed_versions(&names)?;
    let libraries = depends::missing(&relations, &NOT_NEEDED, &installed, depends::dpkg_allows);
    if libraries.is_empty() {
        note!("xtask: step 1/3: the shared libraries {NAME} {version} needs are installed already");
        return Ok(());
    }
    let libraries: Vec<&str> = libraries.iter().map(String::as_str).collect();
    note!(
        "xtask: step 1/3: installing with apt-get the shared libraries {NAME} {version} needs \
         that are missing: {} (its Depends less {}, which the emulated boards do not use; \
         without recommended packages, nothing removed or downgraded)",
        libraries.join(" "),
        NOT_NEEDED.join(" and ")
    );
    let privilege = privilege.map_err(|refusal| apt::needs_root(refusal, &libraries))?;
    let plan = apt::simulate(&libraries)?;
    apt::install(privilege, &libraries, &plan)
}

/// True when a Debian version (`1:7.2+dfsg-7+deb12u18+b3`) is QEMU
/// [`MINIMUM`] or later.
pub fn debian_version_is_new_enough(version: &str) -> bool {
    let upstream = version.split_once(':').map_or(version, |(_, v)| v);
    major_minor(upstream).is_some_and(|v| v >= MINIMUM)
}

/// The one .deb `apt-get download` left in `dir`.
fn the_deb_in(dir: &Path) -> Result<PathBuf> {
    let debs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("listing {}", dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "deb"))
        .collect();
    match debs.as_slice() {
        [deb] => Ok(deb.clone()),
        _ => bail!(
            "`apt-get download` left {} .deb files in {}, not one",
            debs.len(),
            dir.display()
        ),
    }
}

/// `qemu --version` runs and says QEMU [`MINIMUM`] or later; else an error
/// with what it printed (a missing library says which).
fn check_it_runs(qemu: &Path) -> Result<()> {
    let output = Command::new(qemu)
        .arg("--version")
        .stdin(Stdio::null())
        .output()
        .with_context(|| format!("starting {}", qemu.display()))?;
    let said = String::from_utf8_lossy(&output.stdout);
    if output.status.success()
        && super::qemu_binary::parse_version(&said).is_some_and(|v| v >= MINIMUM)
    {
        note!(
            "xtask: {} runs: {}",
            qemu.display(),
            said.lines().next().unwrap_or("")
        );
        return Ok(());
    }
    bail!(
        "the unpacked {} does not run as QEMU {}.{} or later ({}): {}{}",
        qemu.display(),
        MINIMUM.0,
        MINIMUM.1,
        output.status,
        said.trim(),
        String::from_utf8_lossy(&output.stderr).trim()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debian_twelve_qemu_is_new_enough_and_debian_eleven_is_not() {
        assert!(debian_version_is_new_enough("1:7.2+dfsg-7+deb12u18+b3"));
        assert!(debian_version_is_new_enough(
            "1:10.0.2+ds-2+deb13u1~bpo12+1"
        ));
        assert!(!debian_version_is_new_enough("1:5.2+dfsg-11+deb11u3"));
        assert!(!debian_version_is_new_enough("garbage"));
    }

    #[test]
    fn the_not_needed_packages_are_what_debian_twelve_qemu_conflicts_through() {
        // qemu-utils 10 Breaks qemu-system-common (<< 1:8.0+dfsg-5~); the
        // binary's own Depends pins qemu-system-common at its version.
        let field = "libfdt1 (>= 1.6.1), qemu-system-common (= 1:7.2+dfsg-7+deb12u18+b3), \
                     qemu-system-data (>> 1:7.2+dfsg~)";
        let relations = depends::parse(field).unwrap();
        let none = Default::default();
        let missing = depends::missing(&relations, &NOT_NEEDED, &none, |_, _| true);
        assert_eq!(missing, ["libfdt1"]);
    }
}
