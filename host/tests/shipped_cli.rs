//! What the binary carries (src/shipped.rs): every scene of scenes/ and the
//! default calibration, usable from a directory that has neither.

use std::path::{Path, PathBuf};
use std::process::Command;

fn triad() -> Command {
    Command::new(env!("CARGO_BIN_EXE_triad"))
}

fn checkout(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// An empty directory outside the checkout.
fn elsewhere(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("triad-shipped-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `--list` names every scene of scenes/ (built into the binary) with its
/// description, and a listed name runs from a directory without scenes/.
#[test]
fn the_list_names_every_shipped_scene_and_each_runs_anywhere() {
    let output = triad().args(["sim", "--list"]).output().unwrap();
    assert!(output.status.success());
    let list = String::from_utf8(output.stdout).unwrap();
    let elsewhere = elsewhere("scenes");
    for entry in std::fs::read_dir(checkout("scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        let description = text.parse::<toml::Table>().unwrap()["description"]
            .as_str()
            .unwrap()
            .to_string();
        assert!(
            list.lines()
                .any(|l| l.trim_start().starts_with(&format!("{name} "))
                    && l.ends_with(&description)),
            "{name}: {description} in\n{list}"
        );
        let out = elsewhere.join(format!("{name}.csv"));
        let status = triad()
            .current_dir(&elsewhere)
            .args(["sim", "--scene", &name, "--seconds", "0.1", "--out"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "{name} from {}", elsewhere.display());
    }
}

/// `default` is calibrations/default.toml: `calib check` says the same of
/// both (bar the name in the first line), and `calib pack` writes the blob
/// the firmware embeds, calibrations/default.bin, byte for byte.
#[test]
fn the_default_calibration_is_the_checked_in_file() {
    let dir = elsewhere("calibration");
    let check = |arg: &Path| {
        let out = triad()
            .current_dir(&dir)
            .args(["calib", "check"])
            .arg(arg)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        let (first, rest) = text.split_once('\n').unwrap();
        (first.to_string(), rest.to_string())
    };
    let (shipped_first, shipped) = check(Path::new("default"));
    let (file_first, file) = check(&checkout("calibrations/default.toml"));
    assert_eq!(shipped_first, "shipped:default: OK");
    assert!(file_first.ends_with("default.toml: OK"), "{file_first}");
    assert_eq!(shipped, file);

    let blob = dir.join("default.bin");
    let status = triad()
        .current_dir(&dir)
        .args(["calib", "pack", "default", "-o"])
        .arg(&blob)
        .status()
        .unwrap();
    assert!(status.success());
    let checked_in = std::fs::read(checkout("calibrations/default.bin")).unwrap();
    assert!(std::fs::read(&blob).unwrap() == checked_in);
}
