//! Embeds what `triad` ships: every `scenes/*.toml`, `scenes/scripts/*.toml`
//! and `scenes/units/*.toml` of the repository, written as tables of
//! `(name, include_str!(file))` into `$OUT_DIR/shipped_scenes.rs` (read by
//! `src/shipped.rs`). A binary built here, installed or copied anywhere,
//! carries the files it was built with; a file added to those directories
//! is picked up by the next build.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Appends `pub const NAME: &[(&str, &str)]`, the `*.toml` files of `dir`
/// sorted by name, to `table`.
fn embed(table: &mut String, name: &str, what: &str, dir: &Path) {
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.extension().is_some_and(|x| x == "toml"))
        .collect();
    // Sorted, so the table (and `triad sim --list`) is the same on every machine.
    files.sort();
    writeln!(
        table,
        "/// The shipped {what}: (name, TOML text), sorted by name."
    )
    .expect("writing to a String");
    writeln!(table, "pub const {name}: &[(&str, &str)] = &[").expect("writing to a String");
    for path in &files {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_else(|| panic!("{}: file names are UTF-8", path.display()));
        let absolute = path
            .canonicalize()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("cargo:rerun-if-changed={}", absolute.display());
        writeln!(
            table,
            "    ({stem:?}, include_str!({:?})),",
            absolute.display().to_string()
        )
        .expect("writing to a String");
    }
    table.push_str("];\n");
}

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let scenes = manifest.join("../scenes");
    let mut table = String::new();
    embed(&mut table, "SCENES", "scenes", &scenes);
    embed(&mut table, "SCRIPTS", "scripts", &scenes.join("scripts"));
    embed(&mut table, "UNITS", "units", &scenes.join("units"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("set by cargo"));
    std::fs::write(out.join("shipped_scenes.rs"), table).expect("writing shipped_scenes.rs");
}
