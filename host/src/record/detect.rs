//! The format of a recording, from its first bytes (the containers' magic),
//! its first line (the text formats), or a directory's metadata.yaml (a
//! ROS 2 bag).

use std::fs::File;
use std::io::Read;
use std::path::Path;

use anyhow::{bail, Context};

/// The formats read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// CSV with a header naming t and the channels (triad's own).
    TriadCsv,
    /// EuRoC / TUM-VI `imu0/data.csv`.
    Euroc,
    /// imu_tk's whitespace-separated text, one triad.
    ImuTk,
    /// An MCAP file (a ROS 2 bag's storage, or triad's own).
    Mcap,
    /// A ROS 2 bag's SQLite storage (`.db3`).
    Ros2Sqlite,
    /// A ROS 2 bag directory (metadata.yaml and its storage files).
    Ros2Dir,
    /// A ROS 1 bag (format 2.0).
    Ros1Bag,
    /// A PX4 ULog.
    ULog,
}

impl Format {
    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::TriadCsv => "CSV",
            Format::Euroc => "EuRoC/TUM-VI CSV",
            Format::ImuTk => "imu_tk text",
            Format::Mcap => "MCAP",
            Format::Ros2Sqlite => "ROS 2 SQLite bag",
            Format::Ros2Dir => "ROS 2 bag directory",
            Format::Ros1Bag => "ROS 1 bag",
            Format::ULog => "PX4 ULog",
        }
    }

    /// True for the formats that are not text CSV with a header (the ones a
    /// command converts before its CSV parser sees them).
    pub fn is_container_or_foreign(self) -> bool {
        self != Format::TriadCsv
    }
}

/// The magic bytes that open each container.
const MAGICS: [(&[u8], Format); 4] = [
    (b"\x89MCAP", Format::Mcap),
    (b"#ROSBAG V2.0", Format::Ros1Bag),
    (b"ULog\x01\x12\x35", Format::ULog),
    (b"SQLite format 3\0", Format::Ros2Sqlite),
];

/// The format of `path`.
pub fn detect(path: &Path) -> anyhow::Result<Format> {
    let name = path.display();
    if path.is_dir() {
        if path.join("metadata.yaml").is_file() {
            return Ok(Format::Ros2Dir);
        }
        bail!("{name}: a directory without metadata.yaml (not a ROS 2 bag)");
    }
    let mut head = Vec::with_capacity(4096);
    File::open(path)
        .with_context(|| format!("{name}: cannot open"))?
        .take(4096)
        .read_to_end(&mut head)
        .with_context(|| format!("{name}: cannot read"))?;
    Ok(from_head(&head))
}

/// The format of a file that starts with `head` (up to its first 4 KiB).
pub fn from_head(head: &[u8]) -> Format {
    if let Some((_, f)) = MAGICS.iter().find(|(m, _)| head.starts_with(m)) {
        return *f;
    }
    let text = String::from_utf8_lossy(head);
    let first = crate::plumbing::input::strip_bom(&text)
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    if first.starts_with("#timestamp") || first.contains("w_RS_S_x") {
        Format::Euroc
    } else if imu_tk_line(first) {
        Format::ImuTk
    } else {
        Format::TriadCsv
    }
}

/// True for a line of four whitespace-separated numbers (imu_tk's layout).
fn imu_tk_line(line: &str) -> bool {
    let cells: Vec<&str> = line.split_whitespace().collect();
    cells.len() == 4 && cells.iter().all(|c| c.parse::<f64>().is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_content_names_the_format() {
        assert_eq!(from_head(b"\x89MCAP0\r\n"), Format::Mcap);
        assert_eq!(from_head(b"#ROSBAG V2.0\n"), Format::Ros1Bag);
        assert_eq!(from_head(b"ULog\x01\x12\x35\x01"), Format::ULog);
        assert_eq!(from_head(b"SQLite format 3\0..."), Format::Ros2Sqlite);
        assert_eq!(
            from_head(b"#timestamp [ns],w_RS_S_x [rad s^-1]\n"),
            Format::Euroc
        );
        assert_eq!(from_head(b"\n0.01 1 2 9.81\n"), Format::ImuTk);
        assert_eq!(from_head(b"t,ax,ay,az\n0,1,2,3\n"), Format::TriadCsv);
        assert_eq!(from_head(b""), Format::TriadCsv);
    }
}
