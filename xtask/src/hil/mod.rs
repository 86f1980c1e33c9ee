//! `cargo xtask hil`: the hardware-in-the-loop procedure. A person with a
//! board runs it to check in minutes that the firmware does on their bench
//! what the tests show on the emulated board; `cargo xtask test` runs the
//! same procedure against the emulated board, so every step is tested here.
//!
//! For each sampling setting (rate and FIFO watermark; the firmware takes
//! them at build) it builds the firmware, loads it (probe-rs on hardware),
//! identifies the device and streams a few seconds, checking that nothing
//! was lost. With the first setting it also walks the calibration's life:
//! upload, save (its flash stalls counted where the flash stalls the CPU,
//! none on the emulated board), reset (the stored calibration in use), a bad upload
//! refused with nothing changed, erase and reset (the built-in one back),
//! and the self-test; a calibration the board had stored is put back at the
//! end. It writes a Markdown report, and fails when a step failed.

mod device_under_test;
mod report;
mod stream_check;
mod triad_device;

use crate::board::{Board, Bus, Firmware, Sampling};
use crate::{cmd, elf_facts, setup};
use anyhow::{bail, Context, Result};
use device_under_test::DeviceUnderTest;
use report::{Report, Step};
use std::path::{Path, PathBuf};
use std::time::Duration;
use triad_device::TriadDevice;

/// Arguments of `cargo xtask hil`.
#[derive(clap::Args)]
pub struct HilArgs {
    /// The board under test: `qemu` (the emulated board) or `nucleo-f401re`
    /// (flashed with probe-rs; needs --port).
    #[arg(long, default_value = "qemu", value_parser = Board::parse)]
    pub board: Board,
    /// The board's serial port (its ST-LINK's virtual COM port, e.g. /dev/ttyACM0).
    #[arg(long, value_name = "DEV")]
    pub port: Option<String>,
    /// The bus the chip is wired on.
    #[arg(long, default_value = "spi")]
    pub bus: Bus,
    /// The emulated board's chip model (the emulated board only).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(triad::sensor::CHIP_NAMES))]
    pub sensor: Option<String>,
    /// A sampling setting to stream at, RATE:W (RATE in Hz, or `default` for
    /// the driver's; W the FIFO watermark, 1..=32); repeat for several.
    /// Default: default:1, default:8 and default:32.
    #[arg(long = "sampling", value_name = "RATE:W", value_parser = parse_sampling)]
    pub sampling: Vec<Sampling>,
    /// Seconds of stream (by the frames' timestamps) per sampling setting.
    #[arg(long, value_name = "S", default_value_t = 3.0)]
    pub seconds: f64,
    /// Where to write the report (default target/hil/BOARD-BUS/report.md).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
}

impl HilArgs {
    /// The command that runs the procedure with these arguments.
    fn command_line(&self) -> String {
        let mut line = format!(
            "cargo xtask hil --board {} --bus {}",
            self.board.name(),
            self.bus.name()
        );
        if let Some(port) = &self.port {
            line += &format!(" --port {port}");
        }
        if let Some(sensor) = &self.sensor {
            line += &format!(" --sensor {sensor}");
        }
        for s in &self.sampling {
            let rate = s.rate_hz.map_or("default".to_string(), |hz| hz.to_string());
            line += &format!(" --sampling {rate}:{}", s.watermark.unwrap_or(1));
        }
        line + &format!(" --seconds {}", self.seconds)
    }
}

/// The calibration uploaded, saved and restored (a shipped file).
const UPLOADED: &str = "calibrations/lab-example.toml";
/// A calibration that reads as a file but that the device must refuse.
const REFUSED: &str = "calibrations/bad/singular.toml";

/// How long a command may take (identify, upload, save: the NUCLEO stalls
/// while it erases a flash sector).
const COMMAND_LIMIT: Duration = Duration::from_secs(60);

/// `RATE:W` as a sampling setting.
fn parse_sampling(text: &str) -> Result<Sampling, String> {
    let (rate, w) = text
        .split_once(':')
        .ok_or_else(|| format!("{text}: give RATE:W, e.g. 8000:32 or default:1"))?;
    let rate_hz = match rate {
        "default" => None,
        hz => Some(
            hz.parse::<u32>()
                .ok()
                .filter(|&hz| hz > 0)
                .ok_or_else(|| format!("{text}: the rate {hz} is not a whole number of Hz"))?,
        ),
    };
    let watermark = w
        .parse::<u16>()
        .ok()
        .filter(|w| (1..=32).contains(w))
        .ok_or_else(|| format!("{text}: the watermark {w} is not one of 1..=32"))?;
    Ok(Sampling {
        rate_hz,
        watermark: Some(watermark),
        ..Sampling::default()
    })
}

/// Runs the procedure; writes the report; an error when a step failed.
pub fn run(args: HilArgs) -> Result<()> {
    if !(args.seconds.is_finite() && args.seconds > 0.0) {
        bail!(
            "--seconds {}: must be a positive number of seconds",
            args.seconds
        );
    }
    let emulated = args.board.is_emulated();
    let emulated_chip = match (emulated, args.sensor.as_deref(), &args.port) {
        (true, _, Some(port)) => bail!(
            "--port {port}: the emulated board serves its own port; --port names a hardware board's"
        ),
        (true, chip, None) => {
            let chip = chip.unwrap_or(triad::sensor::CHIP_NAMES[0]);
            triad::sensor::CHIP_NAMES
                .iter()
                .copied()
                .find(|c| *c == chip)
        }
        (false, Some(chip), _) => bail!(
            "--sensor {chip}: the {} firmware finds whichever chip is fitted",
            args.board.name()
        ),
        (false, None, None) => bail!(
            "--port DEV is required for {}: its ST-LINK's virtual COM port, e.g. /dev/ttyACM0",
            args.board.name()
        ),
        (_, None, Some(_)) => None,
    };
    let samplings = match args.sampling.is_empty() {
        true => [1, 8, 32]
            .map(|w| Sampling {
                watermark: Some(w),
                ..Sampling::default()
            })
            .to_vec(),
        false => args.sampling.clone(),
    };
    setup::ensure_for(args.board)?;
    let triad = cmd::build_quick_host_tool()?;
    let calibration = cmd::pack_calibration(&triad, None)?;
    let dir = cmd::root().join("target/hil").join(format!(
        "{}-{}{}",
        args.board.name(),
        args.bus.name(),
        emulated_chip.map(|c| format!("-{c}")).unwrap_or_default()
    ));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let report_path = args.report.clone().unwrap_or_else(|| dir.join("report.md"));
    let mut dut = match &args.port {
        Some(port) => DeviceUnderTest::Hardware {
            port: port.clone(),
            chip: args.board.probe_rs_chip().unwrap_or_default(),
        },
        None => DeviceUnderTest::emulated(&dir)?,
    };

    let mut report = Report {
        facts: vec![
            ("board".into(), args.board.name().into()),
            ("bus".into(), args.bus.name().into()),
            ("device under test".into(), dut.describe()),
            ("host tool".into(), tool_version(&triad)),
            ("started".into(), utc_now()),
            ("command".into(), args.command_line()),
        ],
        steps: Vec::new(),
    };
    for (i, sampling) in samplings.iter().enumerate() {
        let firmware = Firmware {
            board: args.board,
            bus: args.bus,
            emulated_chip,
            sampling: *sampling,
        };
        let elf = cmd::build_firmware(firmware, &calibration)?;
        let baud = elf_facts::link_baud(&elf)?;
        note!("xtask hil: loading it on {}", dut.describe());
        let port = match dut.load(&elf) {
            Ok(port) => port,
            Err(e) => {
                report.steps.push(Step {
                    name: format!("load the firmware for {}", firmware.label()),
                    passed: false,
                    detail: vec![format!("{e:#}")],
                    commands: vec![],
                });
                continue;
            }
        };
        let device = TriadDevice {
            triad: triad.clone(),
            port,
            baud,
        };
        report.steps.push(identify(&device, firmware));
        report
            .steps
            .push(stream_check::run(&device, firmware, args.seconds, &dir));
        if i == 0 {
            calibration_life(&mut dut, &elf, &device, &dir, &mut report.steps);
            report.steps.push(self_test(&device));
        }
    }
    drop(dut);
    report.facts.push(("finished".into(), utc_now()));
    report.write(&report_path)?;
    note!(
        "xtask hil: {} ({} steps); the report: {}",
        if report.passed() { "PASS" } else { "FAIL" },
        report.steps.len(),
        report_path.display()
    );
    println!("{}", report_path.display());
    if !report.passed() {
        bail!("a step failed: see {}", report_path.display());
    }
    Ok(())
}

/// Identify: a triad device answers, on the bus built for, at the rate asked.
fn identify(device: &TriadDevice, firmware: Firmware) -> Step {
    let name = format!("identify ({})", firmware.label());
    let (ran, info) = match device.info() {
        Ok(found) => found,
        Err(e) => return failed(name, e),
    };
    let mut detail = vec![
        format!("firmware: {}", info.get("firmware")),
        format!(
            "board: {}, chip: {}, bus: {}",
            info.get("board"),
            info.get("chip"),
            info.get("bus")
        ),
        format!("sample rate: {}", info.get("sample rate")),
        format!(
            "calibration: {}, stored: {}",
            info.get("calibration"),
            info.get("stored")
        ),
    ];
    let mut passed = info.get("bus") == firmware.bus.name();
    if !passed {
        detail.push(format!(
            "the bus is not the {} the firmware was built for",
            firmware.bus.name()
        ));
    }
    if let Some(hz) = firmware.sampling.rate_hz {
        if info.number("sample rate") != Some(u64::from(hz)) {
            passed = false;
            detail.push(format!(
                "the sample rate is not the {hz} Hz the firmware asked for"
            ));
        }
    }
    Step {
        name,
        passed,
        detail,
        commands: vec![ran.line],
    }
}

/// Upload → save → reset → stored in use; a bad upload refused; erase →
/// reset → built in; the board's own stored calibration put back.
fn calibration_life(
    dut: &mut DeviceUnderTest,
    elf: &Path,
    device: &TriadDevice,
    dir: &Path,
    steps: &mut Vec<Step>,
) {
    let before = match device.info() {
        Ok((_, info)) => info,
        Err(e) => return steps.push(failed("read the calibration at start".into(), e)),
    };
    let stored_before = before.get("stored") == "valid";
    let backup = dir.join("calibration-before.toml");
    if stored_before {
        let path = backup.display().to_string();
        let ran = device.run(&["download", "-o", &path], None, COMMAND_LIMIT);
        steps.push(command_step(
            "keep the board's stored calibration (to put it back at the end)",
            ran,
        ));
    }
    let root = cmd::root();
    let uploaded = root.join(UPLOADED).display().to_string();
    steps.push(expect_after(
        "upload a calibration: applied, not yet stored",
        device,
        &["upload", &uploaded],
        true,
        |info| info.calibration().1 == "uploaded",
    ));
    let (uploaded_id, stalls_before) = device
        .info()
        .map(|(_, i)| (i.calibration().0, i.number("flash stalls")))
        .unwrap_or_default();
    // identify counts the flash operations that stalled the CPU: some for a
    // save where the flash stalls it, none where it does not.
    let stalls_cpu = dut.flash_stalls_the_cpu();
    let stalled = |before: Option<u64>, info: &triad_device::Info| match (
        before,
        info.number("flash stalls"),
    ) {
        (Some(before), Some(after)) if stalls_cpu => after > before,
        (Some(_), Some(after)) => after == 0,
        _ => false,
    };
    steps.push(expect_after(
        if stalls_cpu {
            "save it: stored, its flash stalls counted"
        } else {
            "save it: stored, no flash stall (the emulated flash is a file)"
        },
        device,
        &["save"],
        true,
        |info| info.get("stored") == "valid" && stalled(stalls_before, info),
    ));
    steps.push(reset_step(
        "reset: the stored calibration is in use",
        dut,
        elf,
        device,
        |info| info.calibration() == (uploaded_id.clone(), "stored".to_string()),
    ));
    let refused = root.join(REFUSED).display().to_string();
    let errors_before = device
        .info()
        .ok()
        .and_then(|(_, i)| i.number("command errors"));
    steps.push(expect_after(
        "a bad upload (a singular matrix) is refused by the device, nothing changes",
        device,
        &["upload", &refused],
        false,
        |info| {
            info.calibration() == (uploaded_id.clone(), "stored".to_string())
                && info.number("command errors") == errors_before.map(|n| n + 1)
        },
    ));
    let stalls_before = device
        .info()
        .ok()
        .and_then(|(_, i)| i.number("flash stalls"));
    steps.push(expect_after(
        "erase: nothing stored (the active calibration runs until reset)",
        device,
        &["erase"],
        true,
        |info| info.get("stored") == "empty" && stalled(stalls_before, info),
    ));
    steps.push(reset_step(
        "reset: the built-in calibration is back",
        dut,
        elf,
        device,
        |info| info.calibration().1 == "built in",
    ));
    if stored_before {
        let path = backup.display().to_string();
        let upload = device.run(&["upload", &path], None, COMMAND_LIMIT);
        let save = device.run(&["save"], None, COMMAND_LIMIT);
        let mut step = command_step("put the board's stored calibration back", upload);
        let save = command_step("save", save);
        step.passed &= save.passed;
        step.detail.extend(save.detail);
        step.commands.extend(save.commands);
        steps.push(step);
    }
}

/// Runs `args`, expects it to succeed (or fail, `succeeds` false), then
/// identifies and checks `after`.
fn expect_after(
    name: &str,
    device: &TriadDevice,
    args: &[&str],
    succeeds: bool,
    after: impl Fn(&triad_device::Info) -> bool,
) -> Step {
    let ran = match device.run(args, None, COMMAND_LIMIT) {
        Ok(ran) => ran,
        Err(e) => return failed(name.into(), e),
    };
    let mut step = Step {
        name: name.into(),
        passed: ran.status.success() == succeeds,
        detail: vec![format!(
            "`{}` {}: {}",
            args[0],
            exited(ran.status),
            one_line(&ran.output())
        )],
        commands: vec![ran.line],
    };
    if !step.passed {
        step.detail.push(format!(
            "expected it to {}",
            if succeeds { "succeed" } else { "be refused" }
        ));
    }
    check_info(device, &mut step, after);
    step
}

/// Resets the board, then identifies and checks `after`.
fn reset_step(
    name: &str,
    dut: &mut DeviceUnderTest,
    elf: &Path,
    device: &TriadDevice,
    after: impl Fn(&triad_device::Info) -> bool,
) -> Step {
    let mut step = Step {
        name: name.into(),
        passed: true,
        detail: vec![],
        commands: vec![],
    };
    step.detail.push(dut.reset_means());
    match dut.reset(elf) {
        Ok(port) if port == device.port => {}
        Ok(port) => {
            // The emulated board's pty is new after a restart.
            let moved = TriadDevice {
                triad: device.triad.clone(),
                port,
                baud: device.baud,
            };
            check_info(&moved, &mut step, after);
            return step;
        }
        Err(e) => return failed(name.into(), e),
    }
    check_info(device, &mut step, after);
    step
}

/// Identify, and fail `step` unless `after` holds; the fields it read in the detail.
fn check_info(device: &TriadDevice, step: &mut Step, after: impl Fn(&triad_device::Info) -> bool) {
    match device.info() {
        Ok((ran, info)) => {
            let holds = after(&info);
            step.detail.push(format!(
                "then: calibration {}, stored {}, command errors {}, flash stalls {}{}",
                info.get("calibration"),
                info.get("stored"),
                info.get("command errors"),
                info.get("flash stalls"),
                if holds {
                    ""
                } else {
                    " — not what this step expects"
                }
            ));
            step.passed &= holds;
            step.commands.push(ran.line);
        }
        Err(e) => {
            step.passed = false;
            step.detail
                .push(format!("identify afterwards failed: {e:#}"));
        }
    }
}

/// The chip's self-test, which must pass.
fn self_test(device: &TriadDevice) -> Step {
    command_step(
        "self-test: the chip's own test passes",
        device.run(&["selftest"], None, COMMAND_LIMIT),
    )
}

/// A step that passes when the command succeeded; its output in the detail.
fn command_step(name: &str, ran: Result<triad_device::Ran>) -> Step {
    match ran {
        Ok(ran) => Step {
            name: name.into(),
            passed: ran.status.success(),
            detail: ran.output().lines().map(str::to_string).collect(),
            commands: vec![ran.line],
        },
        Err(e) => failed(name.into(), e),
    }
}

fn failed(name: String, error: anyhow::Error) -> Step {
    Step {
        name,
        passed: false,
        detail: vec![format!("{error:#}")],
        commands: vec![],
    }
}

/// "succeeded" or "failed (exit code N)".
fn exited(status: std::process::ExitStatus) -> String {
    match status.code() {
        Some(0) => "succeeded".into(),
        Some(code) => format!("failed (exit code {code})"),
        None => format!("failed ({status})"),
    }
}

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `triad --version`'s first line.
fn tool_version(triad: &Path) -> String {
    std::process::Command::new(triad)
        .arg("--version")
        .output()
        .map(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .next()
                .unwrap_or("")
                .to_string()
        })
        .unwrap_or_else(|e| format!("(triad --version failed: {e})"))
}

/// The time now, UTC, as `date -u` prints it (xtask keeps no calendar code).
fn utc_now() -> String {
    std::process::Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M:%S UTC"])
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}
