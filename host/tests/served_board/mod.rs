//! The emulated board served like hardware, for the tests: `xtask serve
//! --elf ELF --storage FILE` started as a child process (the xtask and the
//! firmware ELF that `cargo xtask test` names in TRIAD_SERVE_XTASK and
//! TRIAD_SERVE_ELF), its pseudo-terminal driven with the real `triad device`
//! binary, or with the host's transport ([`Link`]) where a test reads the
//! frames themselves. Dropping it kills xtask, and QEMU with it (QEMU gets
//! SIGKILL when its parent dies).

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use triad::protocol::Packet;
use triad_host::device::link::{Link, Settings};

/// How long xtask may take to print the port (its set-up check and QEMU's
/// start, on a loaded machine).
const START_TIMEOUT: Duration = Duration::from_secs(60);

/// The link's baud: the emulated board's (a pty ignores it, as QEMU's USART does).
pub const BAUD: u32 = 921_600;

/// How QEMU's clock runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// Paced to the host's clock, as a user serves it.
    RealTime,
    /// `--deterministic`: one instruction per virtual nanosecond, so the
    /// host's load makes no overrun.
    Deterministic,
}

/// A path from an environment variable `cargo xtask test` sets.
pub fn env_path(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var_os(name).unwrap_or_else(|| panic!("{name} is set by cargo xtask test")),
    )
}

/// A fresh directory for one test.
pub fn test_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("device_qemu-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Output bytes as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A running `xtask serve`.
pub struct ServedBoard {
    child: Child,
    port: String,
    /// Its stderr: xtask's messages and the firmware's defmt log.
    log: PathBuf,
}

impl ServedBoard {
    /// Serves the firmware with `storage` as its flash (created erased when
    /// missing), `clock`, and a power cut before the flash operation
    /// `cut_after` (0: the first) when given; returns once the port is known.
    /// The log goes to `storage` with `.log` appended (`-N.log` for the N-th run).
    pub fn start(storage: &Path, clock: Clock, cut_after: Option<u32>) -> ServedBoard {
        Self::serve(storage, clock, cut_after, &[])
    }

    /// As [`ServedBoard::start`], the board showing `faults` (each a
    /// `--fault` schedule entry of `xtask serve`).
    #[allow(dead_code)] // the fault tests'
    pub fn start_with_faults(storage: &Path, clock: Clock, faults: &[String]) -> ServedBoard {
        Self::serve(storage, clock, None, faults)
    }

    /// As [`ServedBoard::start_with_faults`], serving the firmware `elf`
    /// (another build than TRIAD_SERVE_ELF's).
    #[allow(dead_code)] // the fault tests'
    pub fn start_elf_with_faults(
        elf: &Path,
        storage: &Path,
        clock: Clock,
        faults: &[String],
    ) -> ServedBoard {
        Self::serve_elf(elf, storage, clock, None, faults)
    }

    fn serve(
        storage: &Path,
        clock: Clock,
        cut_after: Option<u32>,
        faults: &[String],
    ) -> ServedBoard {
        Self::serve_elf(
            &env_path("TRIAD_SERVE_ELF"),
            storage,
            clock,
            cut_after,
            faults,
        )
    }

    fn serve_elf(
        elf: &Path,
        storage: &Path,
        clock: Clock,
        cut_after: Option<u32>,
        faults: &[String],
    ) -> ServedBoard {
        let log = (0..)
            .map(|n| PathBuf::from(format!("{}-{n}.log", storage.display())))
            .find(|p| !p.exists())
            .unwrap();
        let mut command = Command::new(env_path("TRIAD_SERVE_XTASK"));
        command
            .arg("serve")
            .arg("--elf")
            .arg(elf)
            .arg("--storage")
            .arg(storage);
        if clock == Clock::Deterministic {
            command.arg("--deterministic");
        }
        if let Some(n) = cut_after {
            command.args(["--storage-cut-after", &n.to_string()]);
        }
        for fault in faults {
            command.args(["--fault", fault]);
        }
        let mut child = command
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(File::create(&log).unwrap())
            .spawn()
            .expect("starting xtask serve");
        // The first stdout line is the port; the reader keeps the pipe open.
        let stdout = child.stdout.take().unwrap();
        let (send, receive) = mpsc::channel();
        std::thread::spawn(move || {
            let mut lines = BufReader::new(stdout).lines();
            let _ = send.send(lines.next());
            for _ in lines {}
        });
        let mut board = ServedBoard {
            child,
            port: String::new(),
            log,
        };
        match receive.recv_timeout(START_TIMEOUT) {
            Ok(Some(Ok(port))) => board.port = port,
            other => panic!(
                "xtask serve printed no port within {START_TIMEOUT:?} ({other:?}); its log:\n{}",
                board.log()
            ),
        }
        board
    }

    /// The pseudo-terminal's path.
    pub fn port(&self) -> &str {
        &self.port
    }

    /// What xtask and the firmware logged so far.
    pub fn log(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// `triad device --port PORT ARGS`, run to its end.
    pub fn device(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_triad"))
            .args(["device", "--port", &self.port])
            .args(args)
            .output()
            .expect("run triad device")
    }

    /// `triad device ARGS`, which must succeed; its stdout.
    pub fn device_ok(&self, args: &[&str]) -> String {
        let out = self.device(args);
        assert!(
            out.status.success(),
            "triad device {args:?}: {}\nstdout: {}\nstderr: {}\nserve's log:\n{}",
            out.status,
            text(&out.stdout),
            text(&out.stderr),
            self.log()
        );
        text(&out.stdout)
    }

    /// The host's transport on the port, as `triad device` opens it; one
    /// reader at a time: drop it before running `triad device`.
    pub fn link(&self) -> Link<Box<dyn serialport::SerialPort>> {
        let port = triad_host::plumbing::serial::open(&self.port, BAUD, Duration::from_millis(20))
            .expect("opening the served port");
        let settings = Settings {
            timeout: Duration::from_secs(2),
            tries: 3,
        };
        Link::new(port, settings, format!("on {}", self.port), 0x4000)
    }

    /// Waits up to `within` for xtask to exit by itself (the firmware
    /// stopped QEMU); its status, or `None` if it still runs.
    pub fn wait_exit(&mut self, within: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + within;
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return Some(status);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for ServedBoard {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The next `count` frames (data or raw) the link brings, within `within`;
/// replies and damage before the first frame (a packet cut when the port
/// was opened) are skipped, damage after it fails.
pub fn frames<P: std::io::Read + std::io::Write>(
    link: &mut Link<P>,
    count: usize,
    within: Duration,
) -> Vec<Packet> {
    let deadline = Instant::now() + within;
    let mut frames = Vec::with_capacity(count);
    while frames.len() < count {
        match link.next_packet(deadline).expect("reading the port") {
            Some(Ok(p @ (Packet::Data(_) | Packet::Raw(_)))) => frames.push(p),
            Some(Ok(_)) => {}
            Some(Err(e)) => assert!(frames.is_empty(), "a damaged packet mid-stream: {e:?}"),
            None => panic!("{} of {count} frames within {within:?}", frames.len()),
        }
    }
    frames
}
