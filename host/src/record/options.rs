//! How a record is read: `--topic`, `--time`, `--imu-tk-triad`. They are global
//! options of the `triad` command (every command that reads a record takes
//! them), set once by `main` before the command runs, as `--quiet` is.

use std::sync::OnceLock;

use triad::model::Triad;

/// Which time a container's sample gets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TimeSource {
    /// The message's own stamp (ROS header.stamp; ULog timestamp_sample).
    #[default]
    Header,
    /// When the message was logged or received (MCAP log time, SQLite
    /// timestamp, ROS 1 record time; ULog timestamp).
    Receive,
}

/// How to read a record.
#[derive(Clone, Debug, Default, PartialEq, Eq, clap::Args)]
pub struct Options {
    /// The IMU topic (ROS bags) or message (ULog: sensor_combined or
    /// sensor_accel+sensor_gyro) to read where a recording has several.
    #[arg(
        long = "topic",
        global = true,
        value_name = "NAME",
        help_heading = "Reading recordings"
    )]
    pub record_topic: Option<String>,
    /// The time of each sample in a bag or ULog: the message's stamp or when it was logged.
    #[arg(long = "time", global = true, value_enum, default_value_t = TimeSource::Header, help_heading = "Reading recordings")]
    pub record_time: TimeSource,
    /// The triad an imu_tk text file holds (default: from its name: acc… or gyr…).
    #[arg(long = "imu-tk-triad", global = true, value_name = "accel|gyro", value_parser = parse_triad, help_heading = "Reading recordings")]
    pub imu_tk_triad: Option<Triad>,
}

/// `accel` or `gyro`.
fn parse_triad(s: &str) -> Result<Triad, String> {
    match s {
        "accel" => Ok(Triad::Accel),
        "gyro" => Ok(Triad::Gyro),
        _ => Err(format!("`{s}`: expected accel or gyro")),
    }
}

static GLOBAL: OnceLock<Options> = OnceLock::new();

/// Sets the options every record is read with (once, from `main`).
pub fn set(options: Options) {
    let _ = GLOBAL.set(options);
}

/// The options set by [`set`], else the defaults.
pub fn global() -> Options {
    GLOBAL.get().cloned().unwrap_or_default()
}
