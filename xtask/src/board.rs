//! The boards and buses xtask can build and run, and what it must know of
//! each. A firmware build is one board with one bus, chosen by cargo features
//! (`triad-board-<name>` and its `bus-*`; see firmware/Cargo.toml, where the
//! boards are listed, and each board crate's metadata); the firmware finds its
//! chip on the bus. The emulated board's chip model is one of the core's
//! chips (`triad::sensor::CHIP_NAMES`), named at build by TRIAD_EMULATED_CHIP.

/// A board crate under boards/, as firmware/Cargo.toml lists it (an
/// optional dependency `triad-board-<name>`: the one place boards are
/// listed) with what its own Cargo.toml says of it under
/// `[package.metadata.triad-board]`: `target` (the Rust target of its core),
/// `emulated` (true for a board xtask runs in QEMU) and, for hardware,
/// `probe-rs-chip` (the chip probe-rs flashes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Board {
    name: &'static str,
    target: &'static str,
    emulated: bool,
    probe_rs_chip: Option<&'static str>,
}

impl Board {
    /// Every board listed, the emulated one first, then by name; read once. A
    /// list that cannot be read stops xtask naming the file and why.
    pub fn all() -> &'static [Board] {
        static ALL: OnceLock<Vec<Board>> = OnceLock::new();
        ALL.get_or_init(|| match listed(&root()) {
            Ok(boards) => boards,
            Err(error) => {
                eprintln!("xtask: the board list: {error:#}");
                std::process::exit(2)
            }
        })
    }

    /// The board named `name` (a folder under boards/), for `--board`.
    pub fn parse(name: &str) -> Result<Board, String> {
        Board::all()
            .iter()
            .copied()
            .find(|b| b.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Board::all().iter().map(|b| b.name).collect();
                format!(
                    "no board {name:?} in firmware/Cargo.toml: one of {}",
                    names.join(", ")
                )
            })
    }

    /// The emulated board (the first listed with `emulated = true`).
    pub fn emulated() -> Board {
        Board::all()
            .iter()
            .copied()
            .find(|b| b.emulated)
            .unwrap_or_else(|| {
                eprintln!("xtask: firmware/Cargo.toml lists no emulated board");
                std::process::exit(2)
            })
    }

    /// The folder name under boards/ (the crate is `triad-board-<name>`).
    pub fn name(self) -> &'static str {
        self.name
    }

    /// The board crate's package name, which is also the firmware's feature
    /// that selects it.
    pub fn package(self) -> String {
        format!("{BOARD_PREFIX}{}", self.name)
    }

    /// The Rust target of the board's core.
    pub fn target(self) -> &'static str {
        self.target
    }

    /// True for the board xtask runs in QEMU.
    pub fn is_emulated(self) -> bool {
        self.emulated
    }

    /// The chip probe-rs flashes on a hardware board.
    pub fn probe_rs_chip(self) -> Option<&'static str> {
        self.probe_rs_chip
    }
}

/// The prefix of a board crate's name.
const BOARD_PREFIX: &str = "triad-board-";

/// The boards firmware/Cargo.toml lists under `root`, each with its crate's metadata.
fn listed(root: &Path) -> anyhow::Result<Vec<Board>> {
    let path = root.join("firmware/Cargo.toml");
    let manifest = read_toml(&path)?;
    let mut boards = Vec::new();
    let dependencies = manifest
        .get("dependencies")
        .and_then(|d| d.as_table())
        .with_context(|| format!("{}: no [dependencies] table", path.display()))?;
    for package in dependencies.keys() {
        let Some(name) = package.strip_prefix(BOARD_PREFIX) else {
            continue;
        };
        let crate_manifest = root.join("boards").join(name).join("Cargo.toml");
        boards.push(
            described(name, &read_toml(&crate_manifest)?).with_context(|| {
                format!(
                    "{}: [package.metadata.triad-board]",
                    crate_manifest.display()
                )
            })?,
        );
    }
    if boards.is_empty() {
        bail!("{}: no {BOARD_PREFIX}* dependency", path.display());
    }
    // The emulated board first (the default build), the rest by name.
    boards.sort_by_key(|b| !b.emulated);
    Ok(boards)
}

/// A board named `name` as its crate's manifest describes it.
fn described(name: &str, manifest: &toml::Table) -> anyhow::Result<Board> {
    let meta = manifest
        .get("package")
        .and_then(|p| p.get("metadata"))
        .and_then(|m| m.get("triad-board"))
        .context("missing")?;
    let text = |key: &str| -> anyhow::Result<Option<&'static str>> {
        match meta.get(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(&*Box::leak(s.clone().into_boxed_str()))),
            Some(other) => bail!("{key} = {other}: not a string"),
        }
    };
    let emulated = match meta.get("emulated") {
        None => false,
        Some(toml::Value::Boolean(b)) => *b,
        Some(other) => bail!("emulated = {other}: not true or false"),
    };
    let probe_rs_chip = text("probe-rs-chip")?;
    if !emulated && probe_rs_chip.is_none() {
        bail!("a hardware board needs probe-rs-chip (the chip probe-rs flashes)");
    }
    Ok(Board {
        name: Box::leak(name.to_owned().into_boxed_str()),
        target: text("target")?.context("target (the Rust target of its core) is missing")?,
        emulated,
        probe_rs_chip,
    })
}

/// `path` parsed as TOML.
fn read_toml(path: &Path) -> anyhow::Result<toml::Table> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    text.parse()
        .with_context(|| format!("{}: not valid TOML", path.display()))
}

/// The bus between the microcontroller and the chip.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Bus {
    /// SPI (the default).
    Spi,
    /// I²C.
    I2c,
}

impl Bus {
    /// Every bus.
    pub const ALL: [Bus; 2] = [Bus::Spi, Bus::I2c];

    /// The cargo feature suffix, and the name `TRIAD_E2E_BUS` carries.
    pub fn name(self) -> &'static str {
        match self {
            Bus::Spi => "spi",
            Bus::I2c => "i2c",
        }
    }
}

/// One firmware build: a board with a bus, and for the emulated board the
/// chip model it serves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Firmware {
    /// The board.
    pub board: Board,
    /// The bus.
    pub bus: Bus,
    /// The emulated board's chip model (one of `triad::sensor::CHIP_NAMES`);
    /// `None` on hardware, where the firmware finds whichever chip is fitted.
    pub emulated_chip: Option<&'static str>,
    /// The sample rate and FIFO watermark the firmware asks of the chip.
    pub sampling: Sampling,
}

/// The firmware's sampling settings at build (firmware/build.rs):
/// `TRIAD_SAMPLE_RATE_HZ`, `TRIAD_ACCEL_RATE_HZ` or `TRIAD_GYRO_RATE_HZ`,
/// `TRIAD_FIFO_WATERMARK` and `TRIAD_FIFO_HIGH_RESOLUTION`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sampling {
    /// The chip's output data rate, Hz (the faster sensor's when `slower`
    /// is set); `None`: the driver's default.
    pub rate_hz: Option<u32>,
    /// One sensor at a lower rate, Hz; `None`: both at `rate_hz`.
    pub slower: Option<(Triad, u32)>,
    /// Samples per interrupt; `None` (or 1): one, FIFO off.
    pub watermark: Option<u16>,
    /// The chip's high-resolution FIFO format (the ICM-42688-P's 20-bit
    /// packets; needs a watermark above 1).
    pub high_resolution: bool,
}

impl Firmware {
    /// Every build: each bus of each board, the emulated board with each chip model.
    pub fn all() -> impl Iterator<Item = Firmware> {
        Board::all().iter().copied().flat_map(|board| {
            let chips: Vec<Option<&'static str>> = match board.is_emulated() {
                true => CHIP_NAMES.iter().copied().map(Some).collect(),
                false => vec![None],
            };
            chips.into_iter().flat_map(move |emulated_chip| {
                Bus::ALL.into_iter().map(move |bus| Firmware {
                    board,
                    bus,
                    emulated_chip,
                    sampling: Sampling::default(),
                })
            })
        })
    }

    /// The emulated board with the first listed chip on SPI.
    pub fn default_emulated() -> Firmware {
        Firmware {
            board: Board::emulated(),
            bus: Bus::Spi,
            emulated_chip: Some(CHIP_NAMES[0]),
            sampling: Sampling::default(),
        }
    }

    /// The cargo features that select this build: the board crate (an
    /// optional dependency of the firmware) and its bus.
    pub fn features(self) -> String {
        let board = self.board.package();
        format!("{board},{board}/bus-{}", self.bus.name())
    }

    /// The environment the build reads besides its features.
    pub fn build_env(self) -> Vec<(&'static str, String)> {
        let mut env = Vec::new();
        if let Some(chip) = self.emulated_chip {
            env.push(("TRIAD_EMULATED_CHIP", chip.to_string()));
        }
        if let Some(hz) = self.sampling.rate_hz {
            env.push(("TRIAD_SAMPLE_RATE_HZ", hz.to_string()));
        }
        match self.sampling.slower {
            Some((Triad::Accel, hz)) => env.push(("TRIAD_ACCEL_RATE_HZ", hz.to_string())),
            Some((Triad::Gyro, hz)) => env.push(("TRIAD_GYRO_RATE_HZ", hz.to_string())),
            None => {}
        }
        if let Some(w) = self.sampling.watermark {
            env.push(("TRIAD_FIFO_WATERMARK", w.to_string()));
        }
        if self.sampling.high_resolution {
            env.push(("TRIAD_FIFO_HIGH_RESOLUTION", "1".to_string()));
        }
        env
    }

    /// A short name: `qemu/lsm6dsox/i2c`, `nucleo-f401re/spi`, and the
    /// sampling settings when set: `qemu/icm42688/spi at 8000 Hz, W = 32`.
    pub fn label(self) -> String {
        let mut label = match self.emulated_chip {
            Some(chip) => format!("{}/{chip}/{}", self.board.name(), self.bus.name()),
            None => format!("{}/{}", self.board.name(), self.bus.name()),
        };
        if let Some(hz) = self.sampling.rate_hz {
            label += &format!(" at {hz} Hz");
        }
        if let Some((triad, hz)) = self.sampling.slower {
            label += &format!(" ({} at {hz} Hz)", slower_name(triad));
        }
        if let Some(w) = self.sampling.watermark {
            label += &format!(", W = {w}");
        }
        if self.sampling.high_resolution {
            label += ", high-resolution FIFO";
        }
        label
    }

    /// A file-name stem for this build's artefacts: `lsm6dsox-i2c`, `spi`,
    /// `icm42688-spi-8000hz-w32` with sampling settings.
    pub fn stem(self) -> String {
        let mut stem = match self.emulated_chip {
            Some(chip) => format!("{chip}-{}", self.bus.name()),
            None => self.bus.name().to_owned(),
        };
        if let Some(hz) = self.sampling.rate_hz {
            stem += &format!("-{hz}hz");
        }
        if let Some((triad, hz)) = self.sampling.slower {
            stem += &format!("-{}{hz}hz", slower_name(triad));
        }
        if let Some(w) = self.sampling.watermark {
            stem += &format!("-w{w}");
        }
        if self.sampling.high_resolution {
            stem += "-hires";
        }
        stem
    }
}

/// The name of a triad in labels and file names.
fn slower_name(triad: Triad) -> &'static str {
    match triad {
        Triad::Accel => "accel",
        Triad::Gyro => "gyro",
    }
}

use triad::model::Triad;

use crate::cmd::root;
use anyhow::{bail, Context};
use std::path::Path;
use std::sync::OnceLock;
use triad::sensor::CHIP_NAMES;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_build_once_each_chip_model_on_the_emulated_board() {
        let all: Vec<Firmware> = Firmware::all().collect();
        assert_eq!(
            all.len(),
            CHIP_NAMES.len() * Bus::ALL.len() + Bus::ALL.len()
        );
        assert!(all.contains(&Firmware {
            board: Board::emulated(),
            bus: Bus::I2c,
            emulated_chip: Some("lsm6dsox"),
            sampling: Sampling::default(),
        }));
        assert_eq!(
            all[0],
            Firmware::default_emulated(),
            "the default comes first"
        );
        assert_eq!(
            all[0].features(),
            "triad-board-qemu,triad-board-qemu/bus-spi"
        );
        assert_eq!(
            all[0].build_env(),
            [("TRIAD_EMULATED_CHIP", "icm42688".to_string())]
        );
        let hardware = all.iter().find(|f| !f.board.is_emulated()).unwrap();
        assert!(
            hardware.build_env().is_empty(),
            "hardware has no chip model"
        );
    }

    #[test]
    fn boards_come_from_the_firmware_manifest_with_their_metadata() {
        let boards = listed(&root()).unwrap();
        let names: Vec<&str> = boards.iter().map(|b| b.name()).collect();
        assert_eq!(names, ["qemu", "nucleo-f401re"]);
        assert!(boards[0].is_emulated() && boards[0].probe_rs_chip().is_none());
        assert!(!boards[1].is_emulated());
        assert_eq!(boards[1].probe_rs_chip(), Some("STM32F401RETx"));
        assert_eq!(Board::parse("nucleo-f401re"), Ok(boards[1]));
        let unknown = Board::parse("nucleo-f411re").unwrap_err();
        assert!(unknown.contains("qemu, nucleo-f401re"), "{unknown}");
    }

    #[test]
    fn a_board_without_what_xtask_needs_is_refused_saying_what() {
        let manifest = |meta: &str| -> toml::Table {
            format!("[package]\nname = \"triad-board-x\"\n[package.metadata.triad-board]\n{meta}")
                .parse()
                .unwrap()
        };
        let no_chip = described("x", &manifest("target = \"thumbv7em-none-eabihf\"")).unwrap_err();
        assert!(no_chip.to_string().contains("probe-rs-chip"), "{no_chip}");
        let no_target = described("x", &manifest("emulated = true")).unwrap_err();
        assert!(no_target.to_string().contains("target"), "{no_target}");
        let bad = described("x", &manifest("emulated = \"yes\"")).unwrap_err();
        assert!(bad.to_string().contains("emulated"), "{bad}");
        let none: toml::Table = "[package]\nname = \"x\"".parse().unwrap();
        assert!(described("x", &none).is_err());
    }

    /// The README's "one crate and one line": no source of the core, the
    /// firmware or xtask names a board crate, except the list itself
    /// (firmware/Cargo.toml) and this test's expectations above.
    #[test]
    fn no_source_outside_the_list_names_a_board_crate() {
        let root = root();
        let mut files = Vec::new();
        for dir in ["src", "firmware", "xtask/src", "tests"] {
            sources(&root.join(dir), &mut files);
        }
        files.push(root.join("Cargo.toml"));
        let this = root.join("xtask/src/board.rs");
        let mut named = Vec::new();
        for file in files.iter().filter(|f| **f != this) {
            if file.ends_with("firmware/Cargo.toml") {
                continue;
            }
            let text = std::fs::read_to_string(file).unwrap_or_default();
            for board in Board::all() {
                let package = board.package();
                if text.contains(&package) || text.contains(&package.replace('-', "_")) {
                    named.push(format!("{} names {package}", file.display()));
                }
            }
        }
        assert!(named.is_empty(), "{named:#?}");
    }

    /// Every .rs and .toml file under `dir`.
    fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                sources(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs" || e == "toml") {
                out.push(path);
            }
        }
    }
}
