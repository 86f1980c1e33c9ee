//! A ROS 2 bag's SQLite storage (`.db3`, rosbag2's `sqlite3` plugin):
//! `topics(id, name, type, serialization_format, …)` and `messages(id,
//! topic_id, timestamp, data)`, read with `rusqlite` (SQLite bundled),
//! messages in the order they were written (`id`), CDR
//! sensor_msgs/msg/Imu.

use std::path::Path;

use anyhow::{anyhow, bail, Context};
use rusqlite::{Connection, OpenFlags};

use super::imu_msg::{self, ROS2_TYPE};
use super::producer::{spawn, Sink};
use super::{topics, Channels, Format, Opened, Options, Place, Sample, Source, TimeSource};
use crate::plumbing::input;

/// Opens the SQLite bag at `path`, its IMU topic chosen by `options`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let db = connect(path, &name)?;
    let all = topics_of(&db)
        .map_err(|e| anyhow!("{name}: cannot read a ROS 2 bag's topics table: {e}"))?;
    let (id, topic, format) = {
        let topic = topics::choose(
            &name,
            &strip_ids(&all),
            options.record_topic.as_deref(),
            imu_msg::is_imu,
        )?;
        let (id, _, _, format) = all
            .iter()
            .find(|t| t.1 == topic)
            .cloned()
            .unwrap_or_default();
        (id, topic, format)
    };
    if format != "cdr" {
        bail!("{name}: topic {topic} is serialised as `{format}`, not ROS 2's cdr");
    }
    let time = options.record_time;
    let (path_, name_, topic_) = (path.to_path_buf(), name.clone(), topic.clone());
    let reader = spawn(&name, move |sink| {
        let db = connect(&path_, &name_)?;
        read(&db, &name_, id, &topic_, time, sink)
    });
    Ok(Opened {
        source: Source {
            name,
            format: Format::Ros2Sqlite,
            channels: Channels::IMU,
            place: Place::Message,
            topic: Some(topic),
        },
        reader: Box::new(reader),
    })
}

/// The database, read-only.
fn connect(path: &Path, name: &str) -> anyhow::Result<Connection> {
    Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .with_context(|| format!("{name}: cannot open as SQLite"))
}

/// (id, name, type, serialization format) of every topic.
fn topics_of(db: &Connection) -> rusqlite::Result<Vec<(i64, String, String, String)>> {
    let mut st =
        db.prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")?;
    let rows = st.query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))?;
    rows.collect()
}

fn strip_ids(all: &[(i64, String, String, String)]) -> Vec<(String, String)> {
    all.iter().map(|t| (t.1.clone(), t.2.clone())).collect()
}

/// Reads the messages of topic `id` into `sink`.
fn read(
    db: &Connection,
    name: &str,
    id: i64,
    topic: &str,
    time: TimeSource,
    sink: &mut Sink,
) -> anyhow::Result<()> {
    let broken = |index: u64, e: rusqlite::Error| {
        anyhow!("{name}: the database broke after message {index} of {topic}: {e}")
    };
    let mut st = db
        .prepare("SELECT timestamp, data FROM messages WHERE topic_id = ?1 ORDER BY id")
        .map_err(|e| broken(0, e))?;
    let mut rows = st.query([id]).map_err(|e| broken(0, e))?;
    let mut index = 0u64;
    while let Some(row) = rows.next().map_err(|e| broken(index, e))? {
        index += 1;
        let received: i64 = row.get(0).map_err(|e| broken(index, e))?;
        let data = row
            .get_ref(1)
            .and_then(|v| Ok(v.as_blob()?))
            .map_err(|e| broken(index, e))?;
        let imu = imu_msg::decode_cdr(data)
            .map_err(|e| anyhow!("{name}, message {index} of {topic} ({ROS2_TYPE}): {e}"))?;
        let t = match time {
            TimeSource::Header => imu_msg::stamp_seconds(imu.stamp.sec as i64, imu.stamp.nanosec),
            TimeSource::Receive => imu_msg::nanoseconds_to_seconds(received as i128),
        };
        let mut s = Sample::at(index, t);
        s.gyro = imu.angular_velocity;
        s.accel = imu.linear_acceleration;
        sink.push(s)?;
    }
    Ok(())
}
