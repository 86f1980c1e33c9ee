//! `triad device` run as a person runs it, against a port: each command with
//! a time limit, its output kept, and the few lines the procedure checks
//! (identify's fields, the stream's summary) read back from what it printed.

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The `triad` binary and the port it talks to.
pub struct TriadDevice {
    /// The host tool.
    pub triad: PathBuf,
    /// The device's serial port.
    pub port: String,
    /// The link's baud (read from the firmware ELF).
    pub baud: u32,
}

/// What one command did.
pub struct Ran {
    /// The command line, as a person would type it.
    pub line: String,
    /// Its exit status.
    pub status: ExitStatus,
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
}

impl Ran {
    /// Standard output and error, for a report.
    pub fn output(&self) -> String {
        format!("{}{}", self.stdout, self.stderr)
    }
}

impl TriadDevice {
    /// `triad device --port P --baud B ARGS`, its stdout to `stdout_file`
    /// when given (a stream), killed after `limit`.
    pub fn run(&self, args: &[&str], stdout_file: Option<&Path>, limit: Duration) -> Result<Ran> {
        let baud = self.baud.to_string();
        let mut command = Command::new(&self.triad);
        command
            .args(["device", "--port", &self.port, "--baud", &baud])
            .args(args)
            .stdin(Stdio::null())
            .stderr(Stdio::piped());
        match stdout_file {
            Some(path) => {
                let file = std::fs::File::create(path)
                    .with_context(|| format!("creating {}", path.display()))?;
                command.stdout(file);
            }
            None => {
                command.stdout(Stdio::piped());
            }
        }
        let line = format!(
            "triad device --port {} --baud {baud} {}{}",
            self.port,
            args.join(" "),
            stdout_file
                .map(|p| format!(" > {}", p.display()))
                .unwrap_or_default()
        );
        let mut child = command
            .spawn()
            .with_context(|| format!("starting {}", self.triad.display()))?;
        let mut out = child.stdout.take();
        let mut err = child.stderr.take().context("triad's stderr")?;
        let out_reader = std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(out) = out.as_mut() {
                let _ = out.read_to_string(&mut text);
            }
            text
        });
        let err_reader = std::thread::spawn(move || {
            let mut text = String::new();
            let _ = err.read_to_string(&mut text);
            text
        });
        let deadline = Instant::now() + limit;
        let status = loop {
            if let Some(status) = child.try_wait()? {
                break status;
            }
            if Instant::now() > deadline {
                let _ = child.kill();
                let _ = child.wait();
                bail!("`{line}` did not finish within {} s", limit.as_secs());
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        Ok(Ran {
            line,
            status,
            stdout: out_reader.join().unwrap_or_default(),
            stderr: err_reader.join().unwrap_or_default(),
        })
    }

    /// `info`, read into its fields; an error when it fails.
    pub fn info(&self) -> Result<(Ran, Info)> {
        let ran = self.run(&["info"], None, Duration::from_secs(20))?;
        if !ran.status.success() {
            bail!(
                "`{}` failed ({}): {}",
                ran.line,
                ran.status,
                ran.stderr.trim()
            );
        }
        let info = Info::parse(&ran.stdout);
        Ok((ran, info))
    }
}

/// `triad device info`'s lines as `name: value`.
pub struct Info(BTreeMap<String, String>);

impl Info {
    /// Reads the `name: value` lines of `text`.
    pub fn parse(text: &str) -> Info {
        Info(
            text.lines()
                .filter_map(|l| l.split_once(": "))
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .collect(),
        )
    }

    /// The value of line `name`, or "" when absent.
    pub fn get(&self, name: &str) -> &str {
        self.0.get(name).map(String::as_str).unwrap_or("")
    }

    /// The leading whole number of line `name`.
    pub fn number(&self, name: &str) -> Option<u64> {
        leading_number(self.get(name))
    }

    /// The calibration's id (`0x…`) and its source (`stored`, `built in`, …).
    pub fn calibration(&self) -> (String, String) {
        let value = self.get("calibration");
        match value.split_once(' ') {
            Some((id, source)) => (
                id.to_string(),
                source.trim_matches(|c| c == '(' || c == ')').to_string(),
            ),
            None => (value.to_string(), String::new()),
        }
    }
}

/// The stream summary's counters (`crc errors: 0`, …) from `triad device
/// stream`'s stderr.
pub struct StreamSummary(BTreeMap<String, u64>);

impl StreamSummary {
    /// Reads the `name: N …` lines of `text`, and the device's report line
    /// (`device reported: N overruns, M frames dropped`).
    pub fn parse(text: &str) -> StreamSummary {
        let mut counts: BTreeMap<String, u64> = text
            .lines()
            .filter_map(|l| l.split_once(": "))
            .filter_map(|(k, v)| Some((k.trim().to_string(), leading_number(v)?)))
            .collect();
        if let Some(line) = text
            .lines()
            .find_map(|l| l.strip_prefix("device reported: "))
        {
            let mut parts = line.split(", ");
            if let Some(n) = parts.next().and_then(leading_number) {
                counts.insert("device overruns".into(), n);
            }
            if let Some(n) = parts.next().and_then(leading_number) {
                counts.insert("device frames dropped".into(), n);
            }
        }
        StreamSummary(counts)
    }

    /// The counter `name`, if the summary had it.
    pub fn get(&self, name: &str) -> Option<u64> {
        self.0.get(name).copied()
    }
}

fn leading_number(text: &str) -> Option<u64> {
    let digits: String = text.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn info_lines_give_the_calibration_and_counters() {
        let info = Info::parse(
            "link: at 921600 baud on /dev/pts/3, protocol 2\n\
             calibration: 0xbbf952b2 (built in)\n\
             stored: empty\n\
             overruns: 3\n",
        );
        assert_eq!(
            info.calibration(),
            ("0xbbf952b2".to_string(), "built in".to_string())
        );
        assert_eq!(info.get("stored"), "empty");
        assert_eq!(info.number("overruns"), Some(3));
        assert_eq!(info.number("missing"), None);
    }

    #[test]
    fn the_stream_summary_gives_every_loss_counter() {
        let summary = StreamSummary::parse(
            "triad device stream: stopped at --seconds reached\n\
             frames: 3001 (3001 stored as CSV rows)\n\
             crc errors: 0\n\
             malformed: 2\n\
             sequence gaps: 1 (5 frames lost)\n\
             device reported: 7 overruns, 9 frames dropped\n",
        );
        assert_eq!(summary.get("frames"), Some(3001));
        assert_eq!(summary.get("crc errors"), Some(0));
        assert_eq!(summary.get("malformed"), Some(2));
        assert_eq!(summary.get("sequence gaps"), Some(1));
        assert_eq!(summary.get("device overruns"), Some(7));
        assert_eq!(summary.get("device frames dropped"), Some(9));
    }
}
