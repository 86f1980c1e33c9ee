//! `triad --version`, `triad completions SHELL` and `triad man`: generated
//! from the argument definitions the binary parses.

use std::process::Command;

fn triad(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_triad"))
        .args(args)
        .output()
        .unwrap();
    (out.status.success(), String::from_utf8(out.stdout).unwrap())
}

/// The subcommands every completion and man page must know.
const SUBCOMMANDS: [&str; 8] = [
    "decode",
    "device",
    "correct",
    "calib",
    "sim",
    "allan",
    "completions",
    "man",
];

#[test]
fn the_version_names_the_formats_it_speaks() {
    let (ok, text) = triad(&["--version"]);
    assert!(ok);
    let expected = format!(
        "triad {} (stream protocol v{}, calibration blob v{}, scene blob v{})\n",
        env!("CARGO_PKG_VERSION"),
        triad::protocol::packet::VERSION,
        triad::model::blob::VERSION,
        triad_sim::scenes::scene_blob::VERSION
    );
    assert_eq!(text, expected);
}

#[test]
fn completions_know_every_subcommand_and_option() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let (ok, script) = triad(&["completions", shell]);
        assert!(ok, "{shell}");
        for name in SUBCOMMANDS.iter().chain(&["--scene", "--list"]) {
            let name = name.trim_start_matches('-');
            assert!(script.contains(name), "{shell} completes {name}");
        }
    }
    let (ok, _) = triad(&["completions", "tcsh"]);
    assert!(!ok, "an unknown shell is refused");
}

#[test]
fn man_pages_cover_every_command() {
    let (ok, page) = triad(&["man"]);
    assert!(ok);
    assert!(page.contains(".TH triad 1"), "{page}");
    for name in SUBCOMMANDS {
        assert!(page.contains(name), "triad.1 names {name}");
    }

    let dir = std::env::temp_dir().join(format!("triad-man-{}", std::process::id()));
    let (ok, _) = triad(&["man", "--out-dir", dir.to_str().unwrap()]);
    assert!(ok);
    let mut pages: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    pages.sort();
    for name in [
        "triad.1",
        "triad-sim.1",
        "triad-calib-fit-accel.1",
        "triad-man.1",
    ] {
        assert!(pages.iter().any(|p| p == name), "{name} in {pages:?}");
    }
    let sim = std::fs::read_to_string(dir.join("triad-sim.1")).unwrap();
    assert!(sim.contains("scene") && sim.contains("list"), "{sim}");
    std::fs::remove_dir_all(&dir).unwrap();
}
