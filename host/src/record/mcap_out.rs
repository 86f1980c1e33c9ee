//! Writing a record as MCAP, the way a ROS 2 bag stores it: topic `/imu`
//! with sensor_msgs/msg/Imu in CDR (its `ros2msg` schema text included, so
//! ROS 2 tools and Foxglove decode it without the message package), and,
//! where the record has a temperature, topic `/imu/temperature` with
//! sensor_msgs/msg/Temperature. Each message's log time is its stamp.
//! The orientation is absent (orientation_covariance[0] = -1, as REP 145
//! says) and the covariances unknown (0). A stream decoded from the device
//! ([`McapWriter::with_frames`]) adds topic `/imu/frame`, message
//! `triad_msgs/msg/Frame` (header, `uint32 seq`, `uint16 flags`: the
//! frame's sequence number and flags as docs/PROTOCOL.md gives them, RAW
//! marking a raw frame whose values are the counts times the nominal scale).

use std::collections::BTreeMap;
use std::io::Write;

use anyhow::anyhow;
use mcap::records::MessageHeader;
use mcap::write::NoSeek;
use serde::Serialize;

use super::imu_msg::{self, Header, Imu};
use super::{Channels, Sample};

/// The IMU topic written.
pub const IMU_TOPIC: &str = "/imu";

/// The temperature topic written.
pub const TEMPERATURE_TOPIC: &str = "/imu/temperature";

/// The frame topic of a decoded stream.
pub const FRAME_TOPIC: &str = "/imu/frame";

/// Its message type (triad's own).
pub const FRAME_TYPE: &str = "triad_msgs/msg/Frame";

/// The frame_id of the messages.
pub const FRAME_ID: &str = "imu";

const SEPARATOR: &str =
    "\n================================================================================\n";

const HEADER_DEFINITION: &str =
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";

const TIME_DEFINITION: &str = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";

/// sensor_msgs/msg/Imu with its dependencies, as rosbag2 writes a schema.
fn imu_schema() -> String {
    [
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
        HEADER_DEFINITION,
        TIME_DEFINITION,
        "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
        "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
    ]
    .join(SEPARATOR)
}

/// sensor_msgs/msg/Temperature with its dependencies.
fn temperature_schema() -> String {
    [
        "std_msgs/Header header\nfloat64 temperature\nfloat64 variance\n",
        HEADER_DEFINITION,
        TIME_DEFINITION,
    ]
    .join(SEPARATOR)
}

/// triad_msgs/msg/Frame with its dependencies.
fn frame_schema() -> String {
    [
        "std_msgs/Header header\nuint32 seq\nuint16 flags\n",
        HEADER_DEFINITION,
        TIME_DEFINITION,
    ]
    .join(SEPARATOR)
}

/// triad_msgs/msg/Frame.
#[derive(Serialize)]
struct Frame {
    header: Header,
    seq: u32,
    flags: u16,
}

/// sensor_msgs/msg/Temperature.
#[derive(Serialize)]
struct Temperature {
    header: Header,
    temperature: f64,
    variance: f64,
}

/// An MCAP being written to `W`.
pub struct McapWriter<W: Write> {
    writer: mcap::Writer<NoSeek<W>>,
    channels: Channels,
    imu: u16,
    temperature: Option<u16>,
    frame: Option<u16>,
    sequence: u32,
}

impl<W: Write> McapWriter<W> {
    /// Starts an MCAP on `out` for samples with `channels`.
    pub fn new(out: W, channels: Channels) -> anyhow::Result<Self> {
        let mut writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("triad ", env!("CARGO_PKG_VERSION")))
            .disable_seeking(true)
            .create(NoSeek::new(out))
            .map_err(|e| anyhow!("{e}"))?;
        let none = BTreeMap::new();
        let schema = writer
            .add_schema(imu_msg::ROS2_TYPE, "ros2msg", imu_schema().as_bytes())
            .map_err(|e| anyhow!("{e}"))?;
        let imu = writer
            .add_channel(schema, IMU_TOPIC, "cdr", &none)
            .map_err(|e| anyhow!("{e}"))?;
        let temperature = if channels.temp {
            let schema = writer
                .add_schema(
                    "sensor_msgs/msg/Temperature",
                    "ros2msg",
                    temperature_schema().as_bytes(),
                )
                .map_err(|e| anyhow!("{e}"))?;
            Some(
                writer
                    .add_channel(schema, TEMPERATURE_TOPIC, "cdr", &none)
                    .map_err(|e| anyhow!("{e}"))?,
            )
        } else {
            None
        };
        Ok(McapWriter {
            writer,
            channels,
            imu,
            temperature,
            frame: None,
            sequence: 0,
        })
    }

    /// Starts an MCAP on `out` for a decoded stream: every channel, and
    /// each frame's sequence number and flags on [`FRAME_TOPIC`].
    pub fn with_frames(out: W) -> anyhow::Result<Self> {
        let all = Channels {
            accel: true,
            gyro: true,
            temp: true,
        };
        let mut w = McapWriter::new(out, all)?;
        let schema = w
            .writer
            .add_schema(FRAME_TYPE, "ros2msg", frame_schema().as_bytes())
            .map_err(|e| anyhow!("{e}"))?;
        let channel = w
            .writer
            .add_channel(schema, FRAME_TOPIC, "cdr", &BTreeMap::new())
            .map_err(|e| anyhow!("{e}"))?;
        w.frame = Some(channel);
        Ok(w)
    }

    /// Writes a decoded frame: its sample, then its sequence number and flags.
    pub fn write_frame(&mut self, s: &Sample, seq: u32, flags: u16) -> anyhow::Result<()> {
        self.write(s)?;
        let Some(channel) = self.frame else {
            return Ok(());
        };
        let stamp = imu_msg::stamp_of(s.t);
        let frame = Frame {
            header: Header {
                stamp,
                frame_id: FRAME_ID.to_string(),
            },
            seq,
            flags,
        };
        let time = (stamp.sec as i64 * 1_000_000_000 + stamp.nanosec as i64).max(0) as u64;
        let data = cdr::serialize::<_, _, cdr::CdrLe>(&frame, cdr::Infinite)
            .map_err(|e| anyhow!("{e}"))?;
        let header = MessageHeader {
            channel_id: channel,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        self.writer
            .write_to_known_channel(&header, &data)
            .map_err(|e| anyhow!("{e}"))
    }

    /// Writes one sample (the absent triad as zeros).
    pub fn write(&mut self, s: &Sample) -> anyhow::Result<()> {
        let stamp = imu_msg::stamp_of(s.t);
        let header = Header {
            stamp,
            frame_id: FRAME_ID.to_string(),
        };
        let mut orientation_covariance = [0.0; 9];
        orientation_covariance[0] = -1.0;
        let imu = Imu {
            header: header.clone(),
            orientation: [0.0, 0.0, 0.0, 1.0],
            orientation_covariance,
            angular_velocity: if self.channels.gyro { s.gyro } else { [0.0; 3] },
            linear_acceleration: if self.channels.accel {
                s.accel
            } else {
                [0.0; 3]
            },
            ..Imu::default()
        };
        let time = (stamp.sec as i64 * 1_000_000_000 + stamp.nanosec as i64).max(0) as u64;
        self.sequence = self.sequence.wrapping_add(1);
        let message = |channel_id| MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        self.writer
            .write_to_known_channel(&message(self.imu), &imu_msg::encode_cdr(&imu))
            .map_err(|e| anyhow!("{e}"))?;
        if let Some(channel) = self.temperature {
            let t = Temperature {
                header,
                temperature: s.temp,
                variance: 0.0,
            };
            let data = cdr::serialize::<_, _, cdr::CdrLe>(&t, cdr::Infinite)
                .map_err(|e| anyhow!("{e}"))?;
            self.writer
                .write_to_known_channel(&message(channel), &data)
                .map_err(|e| anyhow!("{e}"))?;
        }
        Ok(())
    }

    /// Ends the file (summary, footer) and gives the output back.
    pub fn finish(mut self) -> anyhow::Result<W> {
        self.writer.finish().map_err(|e| anyhow!("{e}"))?;
        Ok(self.writer.into_inner().into_inner())
    }
}
