//! `triad calib session --port DEV`: a guided rig-free calibration on a
//! device. The device streams raw frames; the session tells the user which
//! way to turn the board, finds each static pose live ([`live_poses`],
//! with a stillness meter), shows which gravity directions are still
//! missing ([`coverage`]), and once enough poses are in fits both triads
//! from the recorded stream exactly as `triad calib fit imu` fits a record
//! ([`fit_imu::fit_record`]). It shows the report and, when the user
//! confirms (or `--yes`), uploads the calibration, saves it, switches to
//! calibrated frames and verifies on a few fresh static poses: each
//! corrected pose's |f| − g against the fit's own residuals, by `triad
//! calib verify`'s F test.
//!
//! All timing follows the frames' time stamps ([`stream_time`]), never the
//! wall clock, except for noticing a stream that stopped. Guidance goes to
//! stderr ([`prompt`]); stdout carries the report and the verification.

pub mod coverage;
pub mod live_poses;
pub mod prompt;
pub mod stream_time;

use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail};
use triad::model::{blob, Calibration, Corrector, Orientation, Triad};
use triad::protocol::{Command, Mode, Packet, RawFrame};
use triad::units::STANDARD_GRAVITY;

use super::fit_csv::Record;
use super::fit_imu::{self, ImuFit};
use super::segments::check_pose_options;
use super::verify;
use crate::calib::file::{self as calib_file, CalibFile};
use crate::device::link::{Link, LinkError, Settings};
use crate::device::{first_sequence, identify, transfer};
use crate::plumbing::interrupt;
use crate::plumbing::outfile;
use crate::plumbing::stdio::{self, outln};
use coverage::Coverage;
use live_poses::{Event, LivePoses, Pose};
use prompt::Guide;
use stream_time::StreamTime;

/// Arguments of `triad calib session`.
#[derive(clap::Args)]
#[command(after_help = "\
Turn the board by hand between static poses as told (hold each still for \
--min-static seconds); the fit starts once --poses poses are in and gravity \
has been seen near all six half-axes (+x, −x, … −z). Exit status: 0 when the \
calibration was uploaded, saved and verified; 1 when the user declined \
(nothing uploaded) or the verification failed (the calibration stays saved).")]
pub struct SessionArgs {
    /// The device's serial port (e.g. /dev/ttyACM0, or the pseudo-terminal
    /// `cargo xtask serve` prints).
    #[arg(long, value_name = "DEV")]
    port: String,
    /// Baud rate of --port (8N1).
    #[arg(long, value_name = "N", default_value_t = 921_600)]
    baud: u32,
    /// Write the fitted calibration file here (TOML, whole or not at all),
    /// once the fit succeeds, whether or not it is uploaded.
    #[arg(long, value_name = "CAL.toml")]
    out: Option<PathBuf>,
    /// Write the raw record the fit used here (CSV, as `triad calib fit imu
    /// --positions` reads it: the same fit again).
    #[arg(long, value_name = "FILE")]
    record: Option<PathBuf>,
    /// Upload, save and verify without asking.
    #[arg(long)]
    yes: bool,
    /// Static poses to collect (the accelerometer fit has 9 unknowns: at
    /// least 10 poses for σ's; the first, joined mid-pose, may be too short).
    #[arg(long, value_name = "N", default_value_t = 14, value_parser = clap::value_parser!(u32).range(10..=64))]
    poses: u32,
    /// Fresh static poses to verify the uploaded calibration on.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=24))]
    verify_poses: u32,
    /// Seconds a pose is held still (of the data's time).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    min_static: f64,
    /// Local gravity, m/s².
    #[arg(long, default_value_t = STANDARD_GRAVITY, allow_negative_numbers = true)]
    gravity: f64,
    /// Seconds (wall clock) without a frame after which the stream counts as stopped.
    #[arg(
        long,
        value_name = "S",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    stall_s: f64,
}

/// A new pose must have turned by this much from the previous one
/// (`rig_free::MIN_TURN_DEG`: smaller moves carry little about (I+Σ)).
const MIN_TURN_DEG: f64 = triad_lab::calib_fit::fits::rig_free::MIN_TURN_DEG;

/// What the user is asked for during the verification.
const FRESH_POSE: &str = "turn the board to a new orientation and hold it still";

/// How long one read of the port waits (Ctrl-C is checked between reads).
const PORT_POLL: Duration = Duration::from_millis(50);

/// A 16-bit chip's full scale in counts.
const FULL_SCALE_COUNTS: f64 = 32768.0;

/// The raw stream recorded for the fit.
#[derive(Default)]
struct RawRecord {
    t: Vec<f64>,
    accel: Vec<[f64; 3]>,
    gyro: Vec<[f64; 3]>,
    temperature: Vec<f64>,
}

/// A raw frame's specific force and rate (SI, f64).
fn si(frame: &RawFrame) -> ([f64; 3], [f64; 3]) {
    let (a, g, _) = frame.to_si();
    (a.map(f64::from), g.map(f64::from))
}

impl RawRecord {
    fn push(&mut self, t: f64, frame: &RawFrame) -> ([f64; 3], [f64; 3]) {
        let (a, g) = si(frame);
        let temp = frame.to_si().2;
        self.t.push(t);
        self.accel.push(a);
        self.gyro.push(g);
        self.temperature.push(f64::from(temp));
        (a, g)
    }

    /// The CSV `triad calib fit imu --positions` reads.
    fn csv(&self) -> String {
        let mut text = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
        for i in 0..self.t.len() {
            let (a, g) = (self.accel[i], self.gyro[i]);
            text += &format!(
                "{},{},{},{},{},{},{},{}\n",
                self.t[i], a[0], a[1], a[2], g[0], g[1], g[2], self.temperature[i]
            );
        }
        text
    }
}

/// The open device and what the session needs to say about it.
struct Device<P> {
    link: Link<P>,
    port: String,
    stall: Duration,
}

impl<P: Read + Write> Device<P> {
    /// The next packet, or an error when none comes for the stall time or
    /// Ctrl-C is pressed; `stage` says what was under way.
    fn next(
        &mut self,
        interrupted: &std::sync::atomic::AtomicBool,
        stage: &str,
    ) -> anyhow::Result<Packet> {
        let deadline = Instant::now() + self.stall;
        loop {
            if interrupt::requested(interrupted) {
                bail!("interrupted {stage}");
            }
            match self.link.next_packet(Instant::now() + PORT_POLL) {
                Ok(Some(Ok(packet))) => return Ok(packet),
                Ok(Some(Err(_))) | Ok(None) => {}
                Err(LinkError::Closed { reason, .. }) => {
                    bail!("the port {} closed {stage} ({reason})", self.port)
                }
                Err(e) => return Err(e.into()),
            }
            if Instant::now() >= deadline {
                bail!(
                    "the stream stopped {stage}: no frame from {} for {:.1} s; is the board still running and connected?",
                    self.port,
                    self.stall.as_secs_f64()
                );
            }
        }
    }
}

/// Runs `triad calib session`.
pub fn run(args: SessionArgs) -> anyhow::Result<ExitCode> {
    check_pose_options(args.gravity, args.min_static)?;
    crate::plumbing::number::positive(
        "--stall-s",
        args.stall_s,
        "must be a positive number of seconds",
    )?;
    for path in [&args.out, &args.record].into_iter().flatten() {
        outfile::probe(path)?;
    }
    if let (Some(out), Some(record)) = (&args.out, &args.record) {
        crate::plumbing::distinct::check(
            &[crate::plumbing::distinct::named("--record", record)],
            &[crate::plumbing::distinct::named("--out", out)],
        )?;
    }
    let opened = crate::plumbing::serial::open(&args.port, args.baud, PORT_POLL)?;
    let settings = Settings {
        timeout: Duration::from_millis(500),
        tries: 3,
    };
    let place = format!("at {} baud on {}", args.baud, args.port);
    let mut device = Device {
        link: Link::new(opened, settings, place, first_sequence()),
        port: args.port.clone(),
        stall: Duration::from_secs_f64(args.stall_s),
    };
    let info = identify(&mut device.link)?;
    let mut guide = Guide::stderr();
    guide.say(&format!(
        "session with {} ({} on {}, {} Hz), calibration {:#010x} ({}) until this one is uploaded",
        args.port,
        info.chip,
        info.board,
        info.sample_rate_hz,
        info.calibration_id,
        info.calibration_source
    ));
    device.link.command(&Command::SetMode(Mode::Raw))?;
    let interrupted = interrupt::flag();

    let (record, scale) = collect(&mut device, &args, &mut guide, &interrupted)?;
    let name = args
        .record
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("the session on {}", args.port)));
    if let Some(path) = &args.record {
        outfile::write_whole(path, record.csv().as_bytes())?;
        guide.say(&format!("wrote the raw record to {}", path.display()));
    }
    // Timed as `calib fit imu` times the record's file.
    let (t, _) = crate::calib::fit_csv::repaired_times(&name.display().to_string(), &record.t)?;
    let accel = Record {
        path: name.clone(),
        t: t.clone(),
        samples: record.accel.clone(),
    };
    let gyro = Record {
        path: name,
        t,
        samples: record.gyro,
    };
    let full_scale = (
        FULL_SCALE_COUNTS * f64::from(scale.accel_si_per_lsb),
        FULL_SCALE_COUNTS * f64::from(scale.gyro_si_per_lsb),
    );
    let fit = fit_imu::fit_record(&accel, &gyro, args.gravity, args.min_static, full_scale.1)
        .map_err(refused)?;
    let file = calibration_file(&fit, full_scale, &args)?;
    stdio::print(&fit.report)?;
    if let Some(out) = &args.out {
        stdio::print(format!("wrote {}\n", out.display()))?;
    }

    let id = file.calibration.id;
    if !args.yes {
        guide.say(&format!(
            "upload calibration {id:#010x} to the device on {}, save it to its flash and verify it? [y/N]",
            args.port
        ));
        if !prompt::answer_is_yes(&mut std::io::stdin().lock()) {
            device.link.command(&Command::SetMode(Mode::Calibrated))?;
            stdio::print(format!(
                "declined: nothing uploaded; the device keeps calibration {:#010x}\n",
                info.calibration_id
            ))?;
            return Ok(ExitCode::FAILURE);
        }
    }
    let uploaded = transfer::upload(&mut device.link, &blob::encode(&file.calibration))?;
    device.link.command(&Command::Save)?;
    device.link.command(&Command::SetMode(Mode::Calibrated))?;
    // Fresh poses as long as the fit's on average: their means then scatter
    // as the fit's did, which the verdict's scale assumes.
    let poses = &fit.fit.poses;
    let hold_s = poses
        .iter()
        .map(|p| accel.t[p.samples.end - 1] - accel.t[p.samples.start])
        .sum::<f64>()
        / poses.len().max(1) as f64;
    let hold_s = hold_s.max(args.min_static);
    stdio::print(format!(
        "uploaded calibration {uploaded:#010x}, saved it to the device's flash; verifying on {} fresh poses \
         held still for {hold_s:.1} s each (the fit's poses' mean length)\n",
        args.verify_poses
    ))?;
    let pass = verify_fresh(
        &mut device,
        &args,
        &file,
        (uploaded, hold_s),
        &mut guide,
        &interrupted,
    )?;
    Ok(if pass {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// A refused fit: its reason and what to do.
fn refused(reason: anyhow::Error) -> anyhow::Error {
    anyhow!(
        "the fit is refused, nothing uploaded: {reason:#}\n(run the session again: more poses (--poses), \
         each held still for --min-static seconds, turned about different axes, not faster than \
         the gyro's range; --record FILE keeps the record to look at)"
    )
}

/// Collects the raw stream until enough poses are in: --poses poses and
/// all six sides seen, or twice --poses whatever the coverage.
fn collect<P: Read + Write>(
    device: &mut Device<P>,
    args: &SessionArgs,
    guide: &mut Guide,
    interrupted: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<(RawRecord, triad::protocol::RawScale)> {
    let wanted = args.poses as usize;
    let mut time = StreamTime::default();
    let mut record = RawRecord::default();
    let mut poses = LivePoses::new(args.min_static, MIN_TURN_DEG);
    let mut coverage = Coverage::default();
    let mut held = 0usize;
    let mut scale = None;
    let mut overruns = 0usize;
    let mut lost_while_still = 0usize;
    guide.say(&format!(
        "hold the board still, then {}",
        prompt::next_turn(&coverage)
    ));
    loop {
        let stage = "while recording the poses (nothing uploaded)";
        let Packet::Raw(frame) = device.next(interrupted, stage)? else {
            continue;
        };
        let (t, gap) = time.frame(
            frame.sequence,
            frame.timestamp_us,
            frame.dropped,
            frame.overruns,
        );
        match gap {
            // Missed sample steps leave a longer step between two samples:
            // the fit integrates across it by the time stamps, and refuses
            // a step that turned too far ("too fast for the sample rate").
            Some(gap @ stream_time::Break::Overrun(_)) => {
                if overruns == 0 {
                    guide.say(&format!(
                        "at {t:.1} s {gap}: the fit integrates across such gaps by the time stamps"
                    ));
                }
                overruns += 1;
            }
            // Frames lost while the board stays still: nothing turned, the
            // record goes on (the poses' means lose a few samples).
            Some(gap) if !record.t.is_empty() && poses.continues(&si(&frame).0, &si(&frame).1) => {
                if lost_while_still == 0 {
                    guide.say(&format!(
                        "at {t:.1} s {gap}, while the board was still: the record goes on across it"
                    ));
                }
                lost_while_still += 1;
            }
            // Frames lost during a turn: their samples are gone, and with
            // them how far the board turned meanwhile.
            Some(gap) if !record.t.is_empty() => {
                guide.say(&format!(
                    "at {t:.1} s {gap}: the turns cannot be integrated across it, so the session starts again from here"
                ));
                record = RawRecord::default();
                poses = LivePoses::new(args.min_static, MIN_TURN_DEG);
                coverage = Coverage::default();
                held = 0;
            }
            _ => {}
        }
        if scale.is_some_and(|s| s != frame.scale) {
            bail!("the raw frames' scale changed during the session: the chip was reconfigured; run the session again");
        }
        scale = Some(frame.scale);
        let (a, g) = record.push(t, &frame);
        match poses.push(t, a, g) {
            Some(Event::Held(pose)) => {
                held += 1;
                let new = coverage.add(&pose.up());
                guide.say(&format!(
                    "pose {held} held at {:.1} s{}; gravity seen: {}",
                    pose.to,
                    if new.is_empty() {
                        String::new()
                    } else {
                        format!(" (new: {})", new.join(", "))
                    },
                    coverage.summary()
                ));
                let enough = held >= wanted && coverage.complete() || held >= 2 * wanted;
                if enough {
                    if !coverage.complete() {
                        guide.say(&format!(
                            "{held} poses, still no gravity from {}: fitting with what there is",
                            coverage.missing().join(", ")
                        ));
                    }
                    if overruns + lost_while_still > 0 {
                        guide.say(&format!(
                            "over {t:.1} s: {overruns} frames after missed sample steps, \
                             {lost_while_still} gaps of lost frames while still"
                        ));
                    }
                    return Ok((record, scale.unwrap_or(frame.scale)));
                }
                guide.say(&format!("{} more; {}", wanted.saturating_sub(held).max(1), prompt::next_turn(&coverage)));
            }
            Some(Event::SamePose { turned_deg }) => guide.say(&format!(
                "that is the last pose again (turned {turned_deg:.0}°, less than {MIN_TURN_DEG}°): {}",
                prompt::next_turn(&coverage)
            )),
            None => guide.meter(poses.meter(), poses.still_for(), poses.min_static()),
        }
    }
}

/// The fitted calibration as a file: validated as `triad calib check`
/// does at the chip's ranges, written to --out when given, and read back
/// (the id is the parameters' CRC, as for any file `calib fit` writes).
fn calibration_file(
    fit: &ImuFit,
    full_scale: (f64, f64),
    args: &SessionArgs,
) -> anyhow::Result<CalibFile> {
    let calibration = Calibration {
        id: 0,
        accel: fit.accel,
        gyro: fit.gyro,
        g_sensitivity: fit.g_sensitivity,
    };
    Corrector::new_si(
        &calibration,
        full_scale.0,
        full_scale.1,
        Orientation::RotationNone,
    )
    .map_err(|e| anyhow!("the fitted calibration is rejected, nothing uploaded: {e}"))?;
    let mut tables = toml::Table::new();
    tables.insert("accel".into(), toml::Value::Table(fit.accel_table.clone()));
    tables.insert("gyro".into(), toml::Value::Table(fit.gyro_table.clone()));
    let mut extra = toml::Table::new();
    extra.insert("fit".into(), toml::Value::Table(tables));
    let header = format!(
        "{}\nFitted live by `triad calib session` on {}.",
        fit.header, args.port
    );
    let text = calib_file::render(&calibration, Orientation::RotationNone, &header, extra)?;
    let path = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("the session's calibration"));
    let file = calib_file::parse(&text, &path)?;
    if let Some(out) = &args.out {
        outfile::write_whole(out, text.as_bytes())?;
    }
    Ok(file)
}

/// Verifies the uploaded calibration `id` on --verify-poses fresh static
/// poses of the corrected stream, each held still for `hold_s` seconds; prints each pose's |f| − g and the F
/// test's verdict; true when it passes.
fn verify_fresh<P: Read + Write>(
    device: &mut Device<P>,
    args: &SessionArgs,
    file: &CalibFile,
    (id, hold_s): (u32, f64),
    guide: &mut Guide,
    interrupted: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<bool> {
    let scale = verify::fit_scale(file, Triad::Accel)?;
    let mut time = StreamTime::default();
    let mut poses = LivePoses::new(hold_s, MIN_TURN_DEG);
    let mut fresh: Vec<Pose> = Vec::new();
    guide.say(&format!("verifying: {FRESH_POSE}"));
    let stage = "while verifying (the calibration is uploaded and saved)";
    while fresh.len() < args.verify_poses as usize {
        let packet = device.next(interrupted, stage)?;
        for c in corrected_samples(&packet, id) {
            let t = match c.sequence {
                Some(sequence) => time.frame(sequence, c.stamp, c.dropped, c.overruns).0,
                None => time.within(c.stamp),
            };
            let (a, g) = (c.accel, c.gyro);
            match poses.push(t, a, g) {
                Some(Event::Held(pose)) => {
                    fresh.push(pose);
                    guide.say(&format!("fresh pose {} held", fresh.len()));
                    if fresh.len() < args.verify_poses as usize {
                        guide.say(FRESH_POSE);
                    }
                }
                Some(Event::SamePose { .. }) => {
                    guide.say("the last pose again: turn the board to a new orientation")
                }
                None => guide.meter(poses.meter(), poses.still_for(), poses.min_static()),
            }
        }
    }
    device
        .link
        .command(&Command::SetMode(Mode::Calibrated))
        .ok();
    let mut out = String::new();
    outln!(
        out,
        "verification of calibration {id:#010x} on {} fresh poses (corrected by the device; |f| − g, and the rate at rest):",
        fresh.len()
    );
    let mut sum_sq = 0.0;
    for pose in &fresh {
        let (r, se) =
            verify::gravity_residual(&pose.accel, &pose.accel_standard_error, args.gravity);
        sum_sq += r * r;
        let rate = pose.gyro.map(f64::to_degrees);
        outln!(
            out,
            "  {:.1}–{:.1} s: {r:+.3e} m/s² (mean's SE {se:.1e}); rate [{:+.4}, {:+.4}, {:+.4}] °/s",
            pose.from,
            pose.to,
            rate[0],
            rate[1],
            rate[2]
        );
    }
    let v = scale.verdict(sum_sq, fresh.len());
    outln!(
        out,
        "residual RMS {:.3e}, the fit's prediction {:.3e}; verdict: {} (F = {:.2} against F({}, {}) at {:.0} %: {:.2})",
        (sum_sq / fresh.len() as f64).sqrt(),
        v.expected.sqrt(),
        if v.pass { "PASS" } else { "FAIL" },
        v.f,
        fresh.len(),
        scale.dof,
        100.0 * verify::LEVEL,
        v.limit
    );
    if !v.pass {
        outln!(
            out,
            "the calibration stays uploaded and saved; run the session again, holding each pose stiller"
        );
    }
    stdio::print(&out)?;
    Ok(v.pass)
}

/// One corrected sample of the calibration being verified.
struct Corrected {
    /// Its frame's number (a batch's first sample), or none (a batch's later ones).
    sequence: Option<u32>,
    stamp: u32,
    dropped: u16,
    overruns: u16,
    accel: [f64; 3],
    gyro: [f64; 3],
}

/// The samples of `packet` corrected by calibration `id` (none from
/// frames of the calibration before it, still queued at the upload).
fn corrected_samples(packet: &Packet, id: u32) -> Vec<Corrected> {
    match packet {
        Packet::Data(f) if f.calibration_id == id => vec![Corrected {
            sequence: Some(f.sequence),
            stamp: f.timestamp_us,
            dropped: f.dropped,
            overruns: f.overruns,
            accel: f.accel.map(f64::from),
            gyro: f.gyro.map(f64::from),
        }],
        Packet::Batch(b) if b.calibration_id == id => (0..usize::from(b.count))
            .filter_map(|i| {
                let (a, g) = b.sample_si(i)?;
                // Each sample's own time: the stamp is the last one's.
                let back = (usize::from(b.count) - 1 - i) as u64 * u64::from(b.period_ns) / 1000;
                Some(Corrected {
                    sequence: (i == 0).then_some(b.sequence),
                    stamp: b.timestamp_us.wrapping_sub(back as u32),
                    dropped: b.dropped,
                    overruns: b.overruns,
                    accel: a.map(f64::from),
                    gyro: g.map(f64::from),
                })
            })
            .collect(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad_lab::calib_fit::hand_record::{self, Axes, Script, TriadTruth, Unit};

    /// A record of `poses` hand-turned poses of an ideal unit with a little noise.
    fn hand(poses: usize) -> (Record, Record) {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let triad = |noise| TriadTruth {
            scale_misalignment: identity,
            bias: [0.0; 3],
            noise,
        };
        let unit = Unit {
            accel: triad(0.01),
            gyro: triad(0.001),
            gravity: STANDARD_GRAVITY,
            g_sensitivity: None,
        };
        let script = Script {
            rate_hz: 100.0,
            poses,
            static_s: 3.0,
            turn_s: 1.5,
            angle_deg: (60.0, 120.0),
            axes: Axes::Any,
            drift: None,
        };
        let mut state = 12345u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let mut samples = Vec::new();
        hand_record::generate(&script, &unit, &mut uniform, |s| {
            samples.push((s.t, s.accel, s.gyro))
        });
        crate::calib::fit_csv::imu_records(
            std::path::Path::new("the session on /dev/pts/9"),
            samples,
        )
    }

    #[test]
    fn a_refused_fit_says_why_that_nothing_was_uploaded_and_what_to_do() {
        let (accel, gyro) = hand(6);
        let full_scale = 2000f64.to_radians();
        let e = refused(
            fit_imu::fit_record(&accel, &gyro, STANDARD_GRAVITY, 1.0, full_scale).unwrap_err(),
        )
        .to_string();
        assert!(
            e.starts_with(
                "the fit is refused, nothing uploaded: the session on /dev/pts/9: accelerometer: "
            ),
            "{e}"
        );
        assert!(e.contains("turn the board to more orientations"), "{e}");
        assert!(
            e.ends_with("--record FILE keeps the record to look at)"),
            "{e}"
        );
        // Enough poses: the same record's fit is accepted.
        let (accel, gyro) = hand(14);
        assert!(fit_imu::fit_record(&accel, &gyro, STANDARD_GRAVITY, 1.0, full_scale).is_ok());
    }
}
