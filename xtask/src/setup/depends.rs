//! Which of a Debian package's dependencies are missing here: its Depends
//! field read as relations (`liba (>= 1), libb | libc`), each met when one
//! of its alternatives is installed at a version the relation allows.

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::process::{Command, Stdio};

/// One alternative of a relation: a package, perhaps with a version bound.
#[derive(Debug, PartialEq, Eq)]
pub struct Dependency {
    /// The package name (without an architecture qualifier such as `:any`).
    pub name: String,
    /// The bound, as `(operator, version)`: `(">=", "0.3.93")`.
    pub bound: Option<(String, String)>,
}

/// Alternatives, any one of which meets the relation (`a | b`).
pub type Relation = Vec<Dependency>;

/// The relations of a Depends field.
pub fn parse(field: &str) -> Result<Vec<Relation>> {
    field
        .split(',')
        .map(|relation| relation.split('|').map(parse_dependency).collect())
        .collect()
}

fn parse_dependency(text: &str) -> Result<Dependency> {
    let text = text.trim();
    let (name, bound) = match text.split_once('(') {
        None => (text, None),
        Some((name, rest)) => {
            let Some(inside) = rest.trim_end().strip_suffix(')') else {
                bail!("dependency `{text}`: its version bound has no closing parenthesis");
            };
            let inside = inside.trim();
            let operator_len = inside.len() - inside.trim_start_matches(['<', '>', '=']).len();
            let (operator, version) = inside.split_at(operator_len);
            if !matches!(operator, "<<" | "<=" | "=" | ">=" | ">>") || version.trim().is_empty() {
                bail!("dependency `{text}`: `{inside}` is not an operator and a version");
            }
            (
                name,
                Some((operator.to_string(), version.trim().to_string())),
            )
        }
    };
    let name = name.trim();
    let name = name.split_once(':').map_or(name, |(n, _)| n);
    if name.is_empty() || name.contains(char::is_whitespace) {
        bail!("dependency `{text}`: `{name}` is not a package name");
    }
    Ok(Dependency {
        name: name.to_string(),
        bound,
    })
}

/// The packages to install so that every relation is met, skipping the
/// relations that name a package in `excluded`: a relation none of whose
/// alternatives is installed at an allowed version gives its first
/// alternative (apt-get's own choice). `installed` maps package to version;
/// `allows(installed_version, (operator, version))` says whether a bound
/// holds.
pub fn missing(
    relations: &[Relation],
    excluded: &[&str],
    installed: &BTreeMap<String, String>,
    allows: impl Fn(&str, &(String, String)) -> bool,
) -> Vec<String> {
    let met = |d: &Dependency| {
        installed
            .get(&d.name)
            .is_some_and(|version| d.bound.as_ref().is_none_or(|b| allows(version, b)))
    };
    let mut names: Vec<String> = Vec::new();
    for relation in relations {
        if relation.iter().any(|d| excluded.contains(&d.name.as_str())) || relation.iter().any(met)
        {
            continue;
        }
        if let Some(first) = relation.first().filter(|d| !names.contains(&d.name)) {
            names.push(first.name.clone());
        }
    }
    names
}

/// The installed version of each of `names` that dpkg has installed (not
/// merely known, or removed with its configuration kept).
pub fn installed_versions(names: &[&str]) -> Result<BTreeMap<String, String>> {
    // dpkg-query exits 1 when some name is unknown; what it prints still holds.
    let output = Command::new("dpkg-query")
        .args(["-W", "-f", "${Package}\t${db:Status-Status}\t${Version}\n"])
        .args(names)
        .env("LC_ALL", "C")
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .context("running dpkg-query")?;
    Ok(parse_installed(&String::from_utf8_lossy(&output.stdout)))
}

/// dpkg-query's `package<TAB>status<TAB>version` lines, the installed ones.
pub fn parse_installed(text: &str) -> BTreeMap<String, String> {
    text.lines()
        .filter_map(|l| {
            let mut fields = l.split('\t');
            let (name, status, version) = (fields.next()?, fields.next()?, fields.next()?);
            (status == "installed").then(|| (name.to_string(), version.to_string()))
        })
        .collect()
}

/// `dpkg --compare-versions installed operator version`: whether the
/// installed version meets the bound (false when dpkg cannot tell).
pub fn dpkg_allows(installed: &str, (operator, version): &(String, String)) -> bool {
    let operator = match operator.as_str() {
        "<<" => "lt",
        "<=" => "le",
        "=" => "eq",
        ">=" => "ge",
        ">>" => "gt",
        _ => return false,
    };
    Command::new("dpkg")
        .args(["--compare-versions", installed, operator, version])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Part of qemu-system-arm 1:7.2+dfsg-7+deb12u18+b3's Depends (Debian 12).
    const QEMU_DEPENDS: &str = "libaio1 (>= 0.3.93), libc6 (>= 2.34), libcapstone4 (>= 4), \
        libfdt1 (>= 1.6.1), libglib2.0-0 (>= 2.67.3), libslirp0 (>= 4.7.0), \
        qemu-system-common (= 1:7.2+dfsg-7+deb12u18+b3), qemu-system-data (>> 1:7.2+dfsg~)";

    /// A stand-in for dpkg's comparison, enough for the versions below: their
    /// numbers in order (`2.36-9+deb12u14` is 2, 36, 9, 12, 14).
    fn at_least(installed: &str, (operator, version): &(String, String)) -> bool {
        assert_eq!(operator, ">=", "the tests use >= bounds only");
        let numbers = |v: &str| -> Vec<u64> {
            v.split(|c: char| !c.is_ascii_digit())
                .filter_map(|n| n.parse().ok())
                .collect()
        };
        numbers(installed) >= numbers(version)
    }

    fn installed(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
        pairs
            .iter()
            .map(|(n, v)| (n.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn a_field_parses_into_names_and_bounds() {
        let relations = parse(QEMU_DEPENDS).unwrap();
        assert_eq!(relations.len(), 8);
        assert_eq!(
            relations[0],
            [Dependency {
                name: "libaio1".into(),
                bound: Some((">=".into(), "0.3.93".into()))
            }]
        );
        assert_eq!(
            relations[7][0].bound,
            Some((">>".into(), "1:7.2+dfsg~".into()))
        );
    }

    #[test]
    fn alternatives_and_arch_qualifiers_parse() {
        let relations = parse("python3:any, libjpeg62-turbo | libjpeg8 (>= 8c)").unwrap();
        assert_eq!(relations[0][0].name, "python3");
        assert_eq!(relations[0][0].bound, None);
        assert_eq!(relations[1].len(), 2);
        assert_eq!(relations[1][1].name, "libjpeg8");
    }

    #[test]
    fn a_malformed_bound_is_an_error_naming_it() {
        let error = parse("libfoo (>= 1").unwrap_err().to_string();
        assert!(error.contains("libfoo (>= 1"), "{error}");
        let error = parse("libfoo (~ 1)").unwrap_err().to_string();
        assert!(error.contains("`~ 1` is not an operator"), "{error}");
        assert!(parse("libfoo, , libbar").is_err());
    }

    #[test]
    fn the_missing_are_the_uninstalled_minus_the_excluded() {
        let relations = parse(QEMU_DEPENDS).unwrap();
        let here = installed(&[
            ("libaio1", "0.3.113-4"),
            ("libc6", "2.36-9+deb12u14"),
            ("libglib2.0-0", "2.74.6-2+deb12u8"),
        ]);
        let excluded = ["qemu-system-common", "qemu-system-data"];
        assert_eq!(
            missing(&relations, &excluded, &here, at_least),
            ["libcapstone4", "libfdt1", "libslirp0"]
        );
    }

    #[test]
    fn an_installed_package_too_old_for_its_bound_is_missing() {
        let relations = parse("libc6 (>= 2.34), libaio1 (>= 0.3.93)").unwrap();
        let here = installed(&[("libc6", "2.31-13"), ("libaio1", "0.3.113-4")]);
        assert_eq!(missing(&relations, &[], &here, at_least), ["libc6"]);
    }

    #[test]
    fn one_installed_alternative_meets_its_relation() {
        let relations = parse("libjpeg62-turbo | libjpeg8, libpng16-16").unwrap();
        let here = installed(&[("libjpeg8", "8d")]);
        assert_eq!(missing(&relations, &[], &here, at_least), ["libpng16-16"]);
    }

    #[test]
    fn only_installed_packages_count() {
        let text = "libaio1\tinstalled\t0.3.113-4\nlibfdt1\tconfig-files\t1.6.1-4\n\
                    libslirp0\tnot-installed\t\n";
        assert_eq!(
            parse_installed(text),
            installed(&[("libaio1", "0.3.113-4")])
        );
    }
}
