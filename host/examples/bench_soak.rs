//! The soak (issue 26): the emulated board at 1 kHz for hours of device
//! time, a command storm every few seconds (identify, mode, decimation, an
//! upload read back, a save, every tenth an erase), and a sensor fault every
//! hour (vanish, brown-out, output stopped, data-ready held high, silent, a
//! NACK storm, in turn). `cargo xtask bench --soak` builds the firmware and
//! runs it; its figures go to stderr.
//!
//! Checked as it runs, on every frame: the stream loses nothing on the wire
//! (no sequence gap, no damaged packet), and every data-ready period between
//! two frames is a sample carried or a step the device counted lost (the
//! gap in periods = the samples the frames between carried, one per data
//! frame and a batch's count, + the `overruns` they reported: no
//! unexplained gap). At the end, every device counter accounted for: steps
//! lost = the frames' `overruns`; stalls = the silencing faults; each NACK
//! storm's failed transactions = the read failures + failed restarts that
//! the `identify`s around it saw (a storm that outlasts 50 ms of failed
//! reads, as 30 reads do with the chip's FIFO at W = 16, also fails the
//! restarts the firmware tries meanwhile, each at its first transaction;
//! a silencing fault's restarts fail too, while the chip is away, so the
//! failed restarts are counted by when they happened), and no read failure
//! outside the storms; nothing dropped, no received byte lost; and the
//! queues' high-water marks from the firmware's log.
//!
//! What bounds its speed: QEMU, not the host tools (serve and this reader
//! take a tenth of its CPU). The firmware sleeps ~98 % of device time,
//! which `-icount shift=0,sleep=off` skips; what is left per device second
//! is the chip model's ~12 M instructions (11.9 k per sample: the demo
//! motion's one software sine and the quantisation, in `f64`, which the
//! Cortex-M4F does in software) and the link's bytes, which QEMU 7.2's
//! STM32 USART hands its link one system call each: 53 kB per device
//! second in data frames, 14.7 kB in batch frames (`--soak-watermark 16`,
//! the default, TRIAD_SOAK_* below unchanged). The link is a pair of FIFOs
//! (xtask/src/qemu_link.rs): on a Unix socket each 1-byte write took a
//! whole buffer of its send budget and QEMU slept whenever the host had
//! not read for a moment (7.5× real time where the FIFOs give 21.7×).
//! The 24 hours at W = 16 (2026-11-27, `cargo xtask bench --soak`, the
//! 2-core machine shared with other builds for most of it): 86 405 s of device time in 4 030 s of
//! wall time (21.4× real time), QEMU 23.7 device seconds per CPU second.
//! W = 1 was measured at 4.4–5.2 device seconds per QEMU CPU second on the
//! socket (not since). Each CPU-second figure is printed at the end (device seconds
//! per CPU second of QEMU, serve and the reader), so a run on a loaded
//! machine still says what a free core would give. Past 52 429 s of device
//! time the demo motion's sine argument (2π·5 Hz·t) passes 2²⁰·π/2, where
//! libm reduces it by its long path: expect the last 9.4 hours of a day to
//! run slower than the first.
//!
//! Environment (set by xtask): TRIAD_SOAK_XTASK (an xtask to serve with),
//! TRIAD_SOAK_ELF, TRIAD_SOAK_BLOB (the calibration blob to upload),
//! TRIAD_SOAK_SECONDS (device time), TRIAD_SOAK_FAULT_EVERY (s, default 3600),
//! TRIAD_SOAK_STORM_EVERY (s, default 5), TRIAD_SOAK_DIR (its files),
//! TRIAD_SOAK_WALL_SECONDS (stop sooner, at this much wall time: the
//! soak then reports the device time it reached, checked the same).

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command as Process, Stdio};
use std::time::{Duration, Instant};

use triad::protocol::{BatchFrame, DecoderStats, Frame};
use triad::protocol::{Command, Mode, Packet};
use triad_host::device::link::{Link, Settings};
use triad_host::device::{identify, transfer};

/// The transactions a NACK storm fails: one sample read each.
const STORM_TRANSACTIONS: u32 = 30;
/// Each silencing fault lasts this long, s.
const FAULT_S: f64 = 0.5;
/// The fault kinds, one an hour in turn.
const KINDS: [&str; 6] = [
    "vanish",
    "brownout",
    "stop",
    "drdy-high",
    "drdy-silent",
    "nack",
];

fn env(name: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| panic!("{name} is set by cargo xtask bench --soak"))
}

fn env_f64(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name}={v}: not a number"))
        })
        .unwrap_or(default)
}

/// The schedule: kind k from (k + ½)·every, then every 6·every.
fn schedule(every: f64) -> Vec<String> {
    KINDS
        .iter()
        .enumerate()
        .map(|(k, kind)| {
            let at = (k as f64 + 0.5) * every;
            let period = 6.0 * every;
            match *kind {
                "nack" => format!("nack@{at}*{STORM_TRANSACTIONS}/{period}"),
                _ => format!("{kind}@{at}+{FAULT_S}/{period}"),
            }
        })
        .collect()
}

/// The device time after a NACK storm's start within which its failed
/// transactions are done, s (30 transactions at W = 16 take about 0.5 s).
const NACK_WINDOW_S: f64 = 2.0;

/// Whether a NACK storm (kind 5) falls in part within `from..=to` s.
fn nack_between(every: f64, from: f64, to: f64) -> bool {
    let (first, period) = (5.5 * every, 6.0 * every);
    let n = ((from - NACK_WINDOW_S - first) / period).ceil().max(0.0);
    first + n * period <= to
}

/// The bus failures between consecutive `identify`s, put to the NACK storms
/// by device time: the read failures and failed restarts of an interval
/// that overlaps a storm are its failed transactions; elsewhere no read
/// should fail (a silencing fault's failed restarts are not counted here).
#[derive(Default)]
struct FailureLedger {
    last: Option<(f64, u32, u32)>,
    in_storms: u64,
    reads_elsewhere: u64,
}

impl FailureLedger {
    fn identified(&mut self, info: &triad::protocol::DeviceInfo, every: f64) {
        let c = &info.counters;
        let now = (
            f64::from(info.uptime_ms) * 1e-3,
            c.read_failures,
            c.sensor_restart_failures,
        );
        if let Some((then, reads, restarts)) = self.last.replace(now) {
            let reads = u64::from(now.1.wrapping_sub(reads));
            let restarts = u64::from(now.2.wrapping_sub(restarts));
            if nack_between(every, then, now.0) {
                self.in_storms += reads + restarts;
            } else {
                self.reads_elsewhere += reads;
            }
        }
    }
}

/// Occurrences of kind `k` that have ended by `t` s.
fn occurrences(k: usize, every: f64, t: f64) -> u64 {
    let first_end = (k as f64 + 0.5) * every + FAULT_S;
    if t < first_end {
        return 0;
    }
    ((t - first_end) / (6.0 * every)).floor() as u64 + 1
}

/// `xtask serve` on the firmware, deterministic; its port.
fn serve(dir: &std::path::Path, faults: &[String]) -> (Child, String, PathBuf) {
    let log = dir.join("serve.log");
    let mut command = Process::new(env("TRIAD_SOAK_XTASK"));
    command
        .args(["serve", "--deterministic", "--elf", &env("TRIAD_SOAK_ELF")])
        .arg("--storage")
        .arg(dir.join("storage.bin"));
    for fault in faults {
        command.args(["--fault", fault]);
    }
    let _ = std::fs::remove_file(dir.join("storage.bin"));
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&log).expect("the serve log"))
        .spawn()
        .expect("starting xtask serve");
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let port = lines
        .next()
        .and_then(Result::ok)
        .expect("xtask serve printed its port");
    std::thread::spawn(move || for _ in lines {});
    (child, port, log)
}

/// A data or batch frame as the accounting sees it: its first sample's
/// time, its number, the samples it carries, and the steps lost it reports.
#[derive(Clone, Copy)]
struct Seen {
    timestamp_us: u32,
    sequence: u32,
    samples: u64,
    overruns: u16,
}

impl Seen {
    fn data(frame: &Frame) -> Self {
        Self {
            timestamp_us: frame.timestamp_us,
            sequence: frame.sequence,
            samples: 1,
            overruns: frame.overruns,
        }
    }

    fn batch(batch: &BatchFrame) -> Self {
        Self {
            timestamp_us: batch.timestamp_us,
            sequence: batch.sequence,
            samples: u64::from(batch.count),
            overruns: batch.overruns,
        }
    }
}

/// Samples the link's decoder has seen carried, in data and batch frames
/// (those a command's wait read past too).
fn carried(stats: &DecoderStats) -> u64 {
    stats.frames + stats.batch_samples
}

/// The frames' accounting: every period between two frames seen.
#[derive(Default)]
struct Accounting {
    last: Option<(Seen, DecoderStats)>,
    device_us: u64,
    frames_seen: u64,
    first_sequence: u32,
    unexplained: u64,
}

impl Accounting {
    fn frame(&mut self, frame: Seen, stats: DecoderStats, period_us: f64) {
        self.frames_seen += 1;
        if self.last.is_none() {
            // Device time from the board's start, as the fault schedule's.
            self.device_us = u64::from(frame.timestamp_us);
            self.first_sequence = frame.sequence;
        }
        if frame.overruns > 0 && std::env::var_os("TRIAD_SOAK_TRACE").is_some() {
            eprintln!(
                "soak: frame {} at {:.3} s: {} steps lost",
                frame.sequence,
                self.device_us as f64 * 1e-6,
                frame.overruns
            );
        }
        if let Some((a, sa)) = self.last.replace((frame, stats)) {
            let gap_us = frame.timestamp_us.wrapping_sub(a.timestamp_us);
            self.device_us += u64::from(gap_us);
            let periods = (f64::from(gap_us) / period_us).round() as u64;
            // The samples from `a`'s first to this frame's first: those `a`
            // and the frames in between (read past by a command's wait)
            // carried, with the steps lost they reported. One per data
            // frame; a batch's count each.
            let between = (carried(&stats) - frame.samples) - (carried(&sa) - a.samples);
            let lost = stats.device_overruns - sa.device_overruns;
            if periods != between + lost {
                self.unexplained += 1;
                if self.unexplained <= 5 {
                    eprintln!(
                        "soak: unexplained gap at {:.3} s: {periods} periods between frames {} \
                         and {}, {between} samples carried, {lost} steps counted lost",
                        self.device_us as f64 * 1e-6,
                        a.sequence,
                        frame.sequence
                    );
                }
            }
        }
    }

    fn seconds(&self) -> f64 {
        self.device_us as f64 * 1e-6
    }
}

/// One command storm; the commands that failed, and what its `identify` said.
fn storm<P: std::io::Read + std::io::Write>(
    link: &mut Link<P>,
    blob: &[u8],
    n: u64,
) -> (u64, Option<triad::protocol::DeviceInfo>) {
    let mut failed = 0;
    let info = identify(link);
    let mut check = |what: &str, ok: Result<(), String>| {
        if let Err(e) = ok {
            failed += 1;
            eprintln!("soak: {what} failed: {e}");
        }
    };
    let info = match info {
        Ok(info) => Some(info),
        Err(e) => {
            check("identify", Err(e.to_string()));
            None
        }
    };
    check(
        "mode",
        link.command(&Command::SetMode(Mode::Calibrated))
            .map(drop)
            .map_err(|e| e.to_string()),
    );
    check(
        "decimation",
        link.command(&Command::SetDecimation(1))
            .map(drop)
            .map_err(|e| e.to_string()),
    );
    check(
        "upload",
        transfer::upload(link, blob)
            .map(drop)
            .map_err(|e| e.to_string()),
    );
    check(
        "read back",
        match transfer::download(link) {
            Ok(Some(back)) if back == blob => Ok(()),
            Ok(other) => Err(format!(
                "{:?} bytes, not the upload",
                other.map(|b| b.len())
            )),
            Err(e) => Err(e.to_string()),
        },
    );
    check(
        "save",
        link.command(&Command::Save)
            .map(drop)
            .map_err(|e| e.to_string()),
    );
    if n % 10 == 9 {
        check(
            "erase",
            link.command(&Command::Erase)
                .map(drop)
                .map_err(|e| e.to_string()),
        );
    }
    (failed, info)
}

/// CPU seconds (user + system) so far of each process in the tree from
/// `root` (serve, and the QEMU it runs), by command name, and of this one
/// (the reader), from /proc: the machine is shared, so wall time alone
/// does not say what the soak costs.
fn cpu_seconds(root: u32) -> Vec<(String, f64)> {
    // Clock ticks per second: Linux reports USER_HZ, 100 on every platform.
    const TICKS: f64 = 100.0;
    let stat = |pid: &str| -> Option<(u32, u32, String, f64)> {
        let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        // The command name is in parentheses and may hold spaces.
        let (head, tail) = text.rsplit_once(") ")?;
        let (pid, name) = head.split_once(" (")?;
        let fields: Vec<&str> = tail.split_whitespace().collect();
        let ticks = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
        Some((
            pid.parse().ok()?,
            fields.get(1)?.parse().ok()?,
            name.to_string(),
            ticks / TICKS,
        ))
    };
    let all: Vec<_> = std::fs::read_dir("/proc")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| stat(e.file_name().to_str()?))
        .collect();
    let mut tree = vec![root];
    let mut out = Vec::new();
    while let Some(pid) = tree.pop() {
        for (child, parent, name, seconds) in &all {
            if *child == pid {
                out.push((name.clone(), *seconds));
            }
            if *parent == pid {
                tree.push(*child);
            }
        }
    }
    if let Some((_, _, _, seconds)) = stat("self") {
        out.push(("reader (bench_soak)".into(), seconds));
    }
    out
}

/// The last queue high-water line in the firmware's log.
fn high_water(log: &std::path::Path) -> String {
    std::fs::read_to_string(log)
        .unwrap_or_default()
        .lines()
        .rev()
        .find_map(|l| {
            l.split_once("queue high-water: ")
                .map(|(_, m)| m.to_string())
        })
        .unwrap_or_else(|| "not logged".into())
}

fn main() {
    let seconds = env_f64("TRIAD_SOAK_SECONDS", 86_400.0);
    let every = env_f64("TRIAD_SOAK_FAULT_EVERY", 3600.0);
    let storm_every = env_f64("TRIAD_SOAK_STORM_EVERY", 5.0);
    let wall_limit = env_f64("TRIAD_SOAK_WALL_SECONDS", f64::INFINITY);
    let dir = PathBuf::from(env("TRIAD_SOAK_DIR"));
    std::fs::create_dir_all(&dir).expect("the soak's directory");
    let blob = std::fs::read(env("TRIAD_SOAK_BLOB")).expect("the calibration blob");
    let faults = schedule(every);
    eprintln!(
        "soak: {seconds} s of device time, a fault every {every} s ({}), a command storm every \
         {storm_every} s",
        faults.join(" ")
    );
    let (mut child, port, log) = serve(&dir, &faults);
    let serial = triad_host::plumbing::serial::open(&port, 921_600, Duration::from_millis(20))
        .expect("opening the served port");
    let settings = Settings {
        timeout: Duration::from_secs(5),
        tries: 3,
    };
    let mut link = Link::new(serial, settings, format!("on {port}"), 0x5000);
    // The stream's first frame before the first identify: the frames its
    // wait reads past are then between two frames the accounting has seen,
    // so every period from the first frame on is checked.
    let mut acc = Accounting::default();
    let first = loop {
        match link.next_packet(Instant::now() + Duration::from_secs(60)) {
            Ok(Some(Ok(Packet::Data(frame)))) => break Seen::data(&frame),
            Ok(Some(Ok(Packet::Batch(batch)))) => break Seen::batch(&batch),
            Ok(Some(_)) => {}
            Ok(None) => panic!("soak: no frame in 60 s; serve's log: {}", log.display()),
            Err(e) => panic!("soak: the link failed before the first frame: {e}"),
        }
    };
    // The first frame only sets the start: no period to convert yet.
    acc.frame(first, *link.stats(), f64::NAN);
    let info = identify(&mut link).expect("identify at start");
    let period_us = 1e6 / f64::from(info.sample_rate_hz);
    let mut failures = FailureLedger::default();
    failures.identified(&info, every);

    let started = Instant::now();
    let (mut storms, mut failed, mut damaged) = (0u64, 0u64, 0u64);
    let mut next_storm = storm_every;
    let note_every = 600.0_f64.min(seconds / 10.0);
    let mut next_note = note_every;
    // The speed over the last note's interval too: the machine's load varies.
    let mut last_note = (0.0, 0.0);
    while acc.seconds() < seconds && started.elapsed().as_secs_f64() < wall_limit {
        match link.next_packet(Instant::now() + Duration::from_secs(60)) {
            Ok(Some(Ok(Packet::Data(frame)))) => {
                acc.frame(Seen::data(&frame), *link.stats(), period_us);
            }
            Ok(Some(Ok(Packet::Batch(batch)))) => {
                acc.frame(Seen::batch(&batch), *link.stats(), period_us);
            }
            Ok(Some(Ok(_))) => {}
            Ok(Some(Err(_))) => damaged += u64::from(acc.frames_seen > 0),
            Ok(None) => panic!(
                "soak: no packet for 60 s at {:.1} s of device time; serve's log: {}",
                acc.seconds(),
                log.display()
            ),
            Err(e) => panic!("soak: the link failed at {:.1} s: {e}", acc.seconds()),
        }
        if acc.seconds() >= next_storm {
            let (storm_failed, info) = storm(&mut link, &blob, storms);
            failed += storm_failed;
            if let Some(info) = info {
                failures.identified(&info, every);
            }
            storms += 1;
            next_storm += storm_every;
        }
        if acc.seconds() >= next_note {
            let wall = started.elapsed().as_secs_f64();
            let (device_then, wall_then) = last_note;
            eprintln!(
                "soak: {:.0} s of device time in {wall:.0} s ({:.2}× real time; {:.2}× since the \
                 last note)",
                acc.seconds(),
                acc.seconds() / wall,
                (acc.seconds() - device_then) / (wall - wall_then)
            );
            last_note = (acc.seconds(), wall);
            next_note = acc.seconds() + note_every;
        }
    }
    let wall = started.elapsed().as_secs_f64();
    let end = identify(&mut link).expect("identify at the end");
    failures.identified(&end, every);
    let stats = *link.stats();
    let cpu = cpu_seconds(child.id());
    let _ = child.kill();
    let _ = child.wait();

    let t = acc.seconds();
    let c = end.counters;
    let silencing: u64 = (0..5).map(|k| occurrences(k, every, t)).sum();
    let storms_of_nack = occurrences(5, every, t);
    let rate = t / wall;
    eprintln!(
        "soak: {t:.0} s of device time at {:.0} Hz in {wall:.0} s of wall time: {rate:.2}× real \
         time; 24 h of device time would take {:.1} h",
        info.sample_rate_hz,
        86_400.0 / rate / 3600.0
    );
    for (name, seconds) in &cpu {
        eprintln!(
            "soak: CPU of {name}: {seconds:.0} s, {:.1} device s per CPU s",
            t / seconds.max(1e-3)
        );
    }
    eprintln!(
        "soak: {} frames seen from sequence {} ({} sent), {storms} command storms ({} commands, {} answered busy \
         and asked again), {failed} commands failed",
        acc.frames_seen, acc.first_sequence, c.frames_sent, c.commands, c.command_errors
    );
    eprintln!(
        "soak: faults: {silencing} silencing data-ready, {storms_of_nack} NACK storms of \
         {STORM_TRANSACTIONS}; device: {} stalls, {} restarts, {} failed restarts, {} read \
         failures, {} steps lost",
        c.sensor_stalls, c.sensor_restarts, c.sensor_restart_failures, c.read_failures, c.overruns
    );
    eprintln!("soak: queue high-water: {}", high_water(&log));
    let checks = [
        ("unexplained gaps", acc.unexplained, 0),
        ("sequence gaps on the wire", stats.sequence_gaps, 0),
        ("damaged packets", damaged + stats.crc_errors, 0),
        ("commands failed", failed, 0),
        (
            "steps lost: device − frames",
            u64::from(c.overruns),
            stats.device_overruns,
        ),
        ("stalls", u64::from(c.sensor_stalls), silencing),
        (
            "the NACK storms' failed transactions: read failures + failed restarts around them",
            failures.in_storms,
            storms_of_nack * u64::from(STORM_TRANSACTIONS),
        ),
        (
            "read failures outside the NACK storms",
            failures.reads_elsewhere,
            0,
        ),
        ("frames dropped", u64::from(c.frames_dropped), 0),
        ("received bytes lost", u64::from(c.rx_overflows), 0),
    ];
    let mut bad = 0;
    for (what, got, want) in checks {
        let ok = got == want;
        bad += u32::from(!ok);
        eprintln!(
            "soak: {what}: {got}{}",
            if ok {
                String::new()
            } else {
                format!(" (expected {want})")
            }
        );
    }
    if bad > 0 {
        eprintln!("soak: {bad} checks failed");
        std::process::exit(1);
    }
    eprintln!("soak: every counter accounted for");
}
