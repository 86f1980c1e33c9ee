//! Recordings people have, behind one record type: a reader yields chunks of
//! [`Sample`]s (time, accelerometer, gyroscope, temperature where the format
//! has it, and where each came from), so a command can stream a record of
//! any length in bounded memory; [`read_all`] holds a whole one for the fits.
//!
//! The formats, found from the content ([`detect`]) and their units:
//!
//! | format | file | t | accel | gyro | temp |
//! |---|---|---|---|---|---|
//! | triad CSV ([`triad_csv`]) | `t,ax,ay,az,gx,gy,gz[,temp]` by name | s | m/s² | rad/s | °C |
//! | EuRoC / TUM-VI ([`euroc`]) | `#timestamp [ns],w_RS_S_x…,a_RS_S_x…` | ns | m/s² | rad/s | — |
//! | imu_tk ([`imu_tk`]) | `t x y z` per line, one file per triad | s | as written (taken as m/s²) | as written (taken as rad/s) | — |
//! | ROS 2 bag ([`mcap_bag`], [`sqlite_bag`], [`ros2_dir`]) | `sensor_msgs/msg/Imu` in CDR | header stamp (or log time) | m/s² | rad/s | — |
//! | ROS 1 bag ([`ros1_bag`]) | `sensor_msgs/Imu` | header stamp (or record time) | m/s² | rad/s | — |
//! | PX4 ULog ([`ulog`]) | `sensor_combined`, or `sensor_accel`+`sensor_gyro` | µs | m/s² | rad/s | °C (`sensor_gyro`) |
//!
//! ROS units are REP 103's (SI); PX4's are its uORB definitions' (SI). Times
//! are seconds in the record whatever the file's unit. Where a file has
//! several IMU topics (or ULog messages) one is chosen with `--topic`
//! ([`topics`]); every reader's time goes through [`time::check`], the one
//! place where a record's time base is judged.

pub mod detect;
pub mod euroc;
pub mod imu_msg;
pub mod imu_tk;
pub mod mcap_bag;
pub mod mcap_chunks;
pub mod mcap_out;
pub mod mcap_walk;
pub mod mcap_windows;
pub mod options;
pub mod producer;
pub mod ros1_bag;
pub mod ros2_dir;
pub mod sqlite_bag;
pub mod text_lines;
pub mod time;
pub mod to_csv;
pub mod topics;
pub mod triad_csv;
pub mod ulog;
pub mod ulog_bounds;
pub mod ulog_formats;

use std::fmt;
use std::path::Path;

pub use detect::Format;
pub use options::{Options, TimeSource};

/// One sample of a record (SI units; `temp` NaN where the record has none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time, seconds.
    pub t: f64,
    /// Specific force, m/s².
    pub accel: [f64; 3],
    /// Angular rate, rad/s.
    pub gyro: [f64; 3],
    /// Temperature, °C (NaN: none).
    pub temp: f64,
    /// Where it came from: its line (text) or message (containers), from 1.
    pub at: u64,
}

impl Sample {
    /// A sample at `at` with every channel zero and no temperature.
    pub fn at(at: u64, t: f64) -> Sample {
        Sample {
            t,
            accel: [0.0; 3],
            gyro: [0.0; 3],
            temp: f64::NAN,
            at,
        }
    }
}

/// Which channels a record carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Channels {
    /// ax, ay, az.
    pub accel: bool,
    /// gx, gy, gz.
    pub gyro: bool,
    /// temp.
    pub temp: bool,
}

impl Channels {
    /// Accelerometer and gyroscope, no temperature (what sensor_msgs/Imu carries).
    pub const IMU: Channels = Channels {
        accel: true,
        gyro: true,
        temp: false,
    };
}

/// What a sample's `at` counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// Line of a text file (from 1, the header included).
    Line,
    /// Message of the chosen topic (from 1).
    Message,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Place::Line => "line",
            Place::Message => "message",
        })
    }
}

/// What a reader reads.
#[derive(Clone, Debug)]
pub struct Source {
    /// The path, for messages.
    pub name: String,
    /// Its format.
    pub format: Format,
    /// The channels its samples carry.
    pub channels: Channels,
    /// What `Sample::at` counts.
    pub place: Place,
    /// The topic or message read, where the format has topics.
    pub topic: Option<String>,
}

impl Source {
    /// "FILE, message 12 (t = 0.05 s)": where a sample came from, for messages.
    pub fn where_is(&self, s: &Sample) -> String {
        format!("{}, {} {} (t = {} s)", self.name, self.place, s.at, s.t)
    }
}

/// Reads a record chunk by chunk.
pub trait Reader: Send {
    /// The next chunk of samples (never empty), or `None` at the end.
    fn next_chunk(&mut self) -> anyhow::Result<Option<Vec<Sample>>>;
}

/// A record opened for reading.
pub struct Opened {
    /// What it is.
    pub source: Source,
    /// Its samples, time-checked.
    pub reader: Box<dyn Reader>,
}

/// Samples per chunk the readers aim at.
pub const CHUNK: usize = 8192;

/// Opens the record at `path` (a file, or a ROS 2 bag directory).
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let format = detect::detect(path)?;
    let opened = match format {
        Format::TriadCsv => triad_csv::open(path)?,
        Format::Euroc => euroc::open(path)?,
        Format::ImuTk => imu_tk::open(path, options)?,
        Format::Mcap => mcap_bag::open(path, options)?,
        Format::Ros2Sqlite => sqlite_bag::open(path, options)?,
        Format::Ros2Dir => ros2_dir::open(path, options)?,
        Format::Ros1Bag => ros1_bag::open(path, options)?,
        Format::ULog => ulog::open(path, options)?,
    };
    Ok(time::checked(opened))
}

/// A whole record in memory.
pub struct Record {
    /// What it is.
    pub source: Source,
    /// Every sample, in time order.
    pub samples: Vec<Sample>,
}

/// Reads the whole record at `path`.
pub fn read_all(path: &Path, options: &Options) -> anyhow::Result<Record> {
    let Opened { source, mut reader } = open(path, options)?;
    let mut samples = Vec::new();
    while let Some(chunk) = reader.next_chunk()? {
        samples.extend_from_slice(&chunk);
    }
    if samples.is_empty() {
        anyhow::bail!("{}: no samples", source.name);
    }
    Ok(Record { source, samples })
}
