//! Embeds what `triad` ships: every `scenes/*.toml` of the repository,
//! written as a table of `(name, include_str!(file))` into
//! `$OUT_DIR/shipped_scenes.rs` (read by `src/shipped.rs`). A binary built
//! here, installed or copied anywhere, carries the scenes it was built with;
//! a scene added to `scenes/` is picked up by the next build.

use std::fmt::Write as _;
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let scenes = manifest.join("../scenes");
    println!("cargo:rerun-if-changed={}", scenes.display());
    let mut files: Vec<PathBuf> = std::fs::read_dir(&scenes)
        .unwrap_or_else(|e| panic!("reading {}: {e}", scenes.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.extension().is_some_and(|x| x == "toml"))
        .collect();
    // Sorted, so the table (and `triad sim --list`) is the same on every machine.
    files.sort();
    let mut table = String::from("/// The shipped scenes: (name, TOML text), sorted by name.\n");
    table.push_str("pub const SCENES: &[(&str, &str)] = &[\n");
    for path in &files {
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_else(|| panic!("{}: scene names are UTF-8", path.display()));
        let absolute = path
            .canonicalize()
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("cargo:rerun-if-changed={}", absolute.display());
        writeln!(
            table,
            "    ({name:?}, include_str!({:?})),",
            absolute.display().to_string()
        )
        .expect("writing to a String");
    }
    table.push_str("];\n");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("set by cargo"));
    std::fs::write(out.join("shipped_scenes.rs"), table).expect("writing shipped_scenes.rs");
}
