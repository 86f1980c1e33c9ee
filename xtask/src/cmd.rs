//! Builds: the host tool, the calibration blob, the firmware; and the
//! hardware run.

use crate::board::{Board, Firmware};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The workspace root (xtask lives one level below it).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask is in the workspace")
        .to_path_buf()
}

/// Cargo's target directory for host builds: `CARGO_TARGET_DIR` when set
/// (relative to the workspace root, where [`cargo`] runs), else `target/`.
pub fn host_target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => root().join(dir),
        None => root().join("target"),
    }
}

/// `target/NAME` in the workspace root, where xtask keeps what it makes
/// (blobs, firmware, captures) whatever `CARGO_TARGET_DIR` says; the
/// directory is made if missing.
fn artefact(name: &str) -> Result<PathBuf> {
    let dir = root().join("target");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir.join(name))
}

/// `cargo` (the one running xtask), in the workspace root.
pub fn cargo() -> Command {
    let mut command = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    command.current_dir(root());
    command
}

/// Runs `command` with its stdout relayed to stderr (xtask's stdout is for
/// data: `cargo xtask run`'s CSV); an error names `what` failed and how.
/// Relayed, not inherited: a child handed a full or abandoned stderr as its
/// stdout would fail on its report (`triad calib pack`), while for xtask
/// stderr is only notes, whose loss is no failure.
pub fn check(mut command: Command, what: &str) -> Result<()> {
    let mut child = command
        .stdout(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting {what}"))?;
    if let Some(mut out) = child.stdout.take() {
        let mut buffer = [0u8; 4096];
        loop {
            use std::io::{Read as _, Write as _};
            match out.read(&mut buffer) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    let _ = std::io::stderr().write_all(&buffer[..n]);
                }
            }
        }
    }
    let status = child
        .wait()
        .with_context(|| format!("waiting for {what}"))?;
    if !status.success() {
        bail!("{what} failed ({status}); its output above says why");
    }
    Ok(())
}

/// True when `program --version` starts and succeeds: the program is on
/// PATH and runs. Its output is dropped.
pub fn runs(program: &str) -> bool {
    Command::new(program)
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Builds the `triad` host tool as the benchmarks time it (release: fat
/// LTO, one codegen unit) and returns its path.
pub fn build_host_tool() -> Result<PathBuf> {
    build_triad(
        "release",
        "release, fat LTO: a second when up to date, minutes the first time",
    )
}

/// Builds the `triad` host tool that `run`, `serve`, `hil` and `test` drive
/// (Cargo.toml's quick-release profile: optimised, without LTO) and returns
/// its path.
pub fn build_quick_host_tool() -> Result<PathBuf> {
    build_triad(
        "quick-release",
        "optimised: a second when up to date, a minute or two the first time",
    )
}

fn build_triad(profile: &str, how_long: &str) -> Result<PathBuf> {
    note!("xtask: building the triad host tool ({how_long})");
    let mut command = cargo();
    command.args(["build", "--quiet", "--profile", profile]);
    command.args(["-p", "triad-host", "--bin", "triad"]);
    check(command, "building the triad host tool")?;
    Ok(host_target_dir().join(profile).join("triad"))
}

/// Packs the calibration TOML into the blob the firmware embeds and returns the
/// blob's path. `None` means calibrations/default.toml.
pub fn pack_calibration(triad: &Path, toml: Option<&Path>) -> Result<PathBuf> {
    let source = toml
        .map(Path::to_path_buf)
        .unwrap_or_else(|| root().join("calibrations/default.toml"));
    let blob = artefact("calibration.bin")?;
    let mut command = Command::new(triad);
    command
        .args(["calib", "pack"])
        .arg(&source)
        .arg("-o")
        .arg(&blob);
    check(command, &format!("triad calib pack {}", source.display()))?;
    Ok(blob)
}

/// Builds `firmware` (its board, chip and bus as cargo features) with the
/// calibration blob embedded and returns the ELF's path: a copy named after
/// the chip and bus, so the next build (same board, other features) does not
/// overwrite it.
pub fn build_firmware(firmware: Firmware, calibration: &Path) -> Result<PathBuf> {
    build(firmware, calibration, None)
}

/// The emulated board's firmware with its chip model fed by the simulator
/// running the scene in `scene_blob` (feature `sim-scene`, see build.rs).
pub fn build_firmware_with_scene(
    firmware: Firmware,
    calibration: &Path,
    scene_blob: &Path,
) -> Result<PathBuf> {
    build(firmware, calibration, Some(scene_blob))
}

/// Writes the blob of scene `name` (a scenes/ name or a file) with `seed`
/// for the emulated board, with `triad sim --pack`; returns its path.
pub fn pack_scene(triad: &Path, name: &str, seed: u64) -> Result<PathBuf> {
    let seed = seed.to_string();
    pack(triad, "scene.bin", &["--scene", name, "--seed", &seed])
}

/// Writes the blob of unit `unit` doing script `script` (shipped names or
/// files), its noise from `record_seed`, with `triad sim --pack`; returns
/// its path.
pub fn pack_unit(triad: &Path, unit: &str, script: &str, record_seed: u64) -> Result<PathBuf> {
    let seed = record_seed.to_string();
    let args = ["--unit", unit, "--script", script, "--record-seed", &seed];
    pack(triad, "unit-scene.bin", &args)
}

/// `triad sim ARGS --pack` into the artefact `file`.
fn pack(triad: &Path, file: &str, args: &[&str]) -> Result<PathBuf> {
    let blob = artefact(file)?;
    let mut command = Command::new(triad);
    command
        .current_dir(root())
        .arg("sim")
        .args(args)
        .arg("--pack")
        .arg(&blob);
    check(command, &format!("triad sim {} --pack", args.join(" ")))?;
    Ok(blob)
}

/// `cargo SUBCOMMAND --quiet -p triad-firmware` for `firmware`: its board's
/// target and target dir, its board, chip and bus as features, the
/// calibration blob it embeds and, with `scene`, the scene blob its chip
/// model measures (feature `sim-scene`). The build and clippy both run it.
pub fn firmware_cargo(
    subcommand: &str,
    firmware: Firmware,
    calibration: &Path,
    scene: Option<&Path>,
) -> Command {
    let mut command = cargo();
    command
        .args([subcommand, "--quiet", "-p", "triad-firmware"])
        .args(["--target", firmware.board.target(), "--features"])
        .arg(match scene {
            Some(_) => format!(
                "{},{}/sim-scene",
                firmware.features(),
                firmware.board.package()
            ),
            None => firmware.features(),
        })
        .envs(firmware.build_env())
        .env(EMBEDDED_PANIC.0, EMBEDDED_PANIC.1)
        .env("TRIAD_CALIBRATION", calibration)
        .env("CARGO_TARGET_DIR", firmware_target_dir(firmware.board));
    if let Some(blob) = scene {
        command.env("TRIAD_SCENE", blob);
    }
    command
}

/// What an embedded build (no std: nothing to unwind with) sets on the
/// workspace's release profile, which unwinds for the host (Cargo.toml).
pub const EMBEDDED_PANIC: (&str, &str) = ("CARGO_PROFILE_RELEASE_PANIC", "abort");

/// One target dir per board: each board's build keeps its artefacts, and
/// the chip model and bus rebuild only the firmware and board crates.
fn firmware_target_dir(board: Board) -> PathBuf {
    root().join("target/firmware").join(board.name())
}

fn build(firmware: Firmware, calibration: &Path, scene: Option<&Path>) -> Result<PathBuf> {
    let board = firmware.board;
    if scene.is_some() && !board.is_emulated() {
        bail!("--scene feeds the emulated board's chip model: use it with --board qemu");
    }
    note!(
        "xtask: building the firmware for {} (the first build for a board takes minutes)",
        firmware.label()
    );
    let mut command = firmware_cargo("build", firmware, calibration, scene);
    command.arg("--release");
    check(
        command,
        &format!("building the firmware for {}", firmware.label()),
    )?;
    let target_dir = firmware_target_dir(board);
    let built = target_dir
        .join(board.target())
        .join("release/triad-firmware");
    let elf = target_dir.join(format!(
        "triad-firmware-{}{}",
        firmware.stem(),
        if scene.is_some() { "-scene" } else { "" }
    ));
    std::fs::copy(&built, &elf)
        .with_context(|| format!("copying {} to {}", built.display(), elf.display()))?;
    Ok(elf)
}

/// Flashes and runs the firmware on a hardware board (its microcontroller
/// `chip` as probe-rs names it) with probe-rs (which also prints the defmt
/// log) and decodes the stream from the board's serial port.
pub fn run_on_hardware(
    elf: &Path,
    triad: &Path,
    chip: &str,
    port: &str,
    seconds: f64,
) -> Result<()> {
    if !runs("probe-rs") {
        bail!(
            "probe-rs not found: install it with `cargo install probe-rs-tools --locked` \
             and connect the board's ST-LINK"
        );
    }
    let baud = crate::elf_facts::link_baud(elf)?;
    let mut probe = Command::new("probe-rs")
        .args(["run", "--chip", chip])
        .arg(elf)
        .stdin(Stdio::null())
        .spawn()
        .context("starting probe-rs")?;
    let status = Command::new(triad)
        .args(["decode", "--port", port, "--baud", &baud.to_string()])
        .args(["--seconds", &seconds.to_string()])
        .status()
        .context("starting triad decode");
    let _ = probe.kill();
    let _ = probe.wait();
    let status = status?;
    if !status.success() {
        bail!("triad decode on {port} exited with {status}");
    }
    Ok(())
}

/// A copy of this executable for the tests and `xtask hil` to run `xtask serve` with (as
/// cargo may rebuild xtask's own while the tests run); its path.
pub fn serving_xtask() -> Result<std::path::PathBuf> {
    let dir = root().join("target/e2e");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let xtask = dir.join("xtask-serve");
    let copying = dir.join("xtask-serve.part");
    // By now `cargo clippy`/`cargo test` may have rebuilt xtask, replacing
    // the file this process was started from: on Linux /proc/self/exe still
    // opens the running image itself.
    let proc_exe = Path::new("/proc/self/exe");
    let current = if proc_exe.exists() {
        proc_exe.to_path_buf()
    } else {
        std::env::current_exe().context("xtask's own path")?
    };
    std::fs::copy(&current, &copying)
        .and_then(|_| std::fs::rename(&copying, &xtask))
        .with_context(|| format!("copying {} to {}", current.display(), xtask.display()))?;
    Ok(xtask)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;

    #[test]
    fn the_firmware_cargo_command_carries_the_features_and_both_blobs() {
        let firmware = Firmware::default_emulated();
        let command = firmware_cargo(
            "clippy",
            firmware,
            Path::new("cal.bin"),
            Some(Path::new("scene.bin")),
        );
        let args: Vec<&OsStr> = command.get_args().collect();
        assert_eq!(args[0], "clippy");
        let features = format!(
            "{},{}/sim-scene",
            firmware.features(),
            firmware.board.package()
        );
        assert!(args
            .windows(2)
            .any(|w| w[0] == "--features" && w[1] == features.as_str()));
        assert!(args
            .windows(2)
            .any(|w| w[0] == "--target" && w[1] == "thumbv7em-none-eabihf"));
        let env = |key: &str| {
            command
                .get_envs()
                .find(|(k, _)| *k == key)
                .and_then(|(_, v)| v)
        };
        assert_eq!(env("TRIAD_CALIBRATION"), Some(OsStr::new("cal.bin")));
        assert_eq!(env("TRIAD_SCENE"), Some(OsStr::new("scene.bin")));
        assert_eq!(
            env("CARGO_TARGET_DIR"),
            Some(root().join("target/firmware/qemu").as_os_str())
        );
        let (key, chip) = &firmware.build_env()[0];
        assert_eq!(env(key), Some(OsStr::new(chip)));
    }
}
