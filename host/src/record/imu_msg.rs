//! sensor_msgs/Imu as the bags carry it: ROS 2's CDR (decoded and written
//! with the `cdr` crate over the serde struct below) and ROS 1's
//! serialisation (a packed little-endian layout with no alignment: decoded
//! here in a few lines, as no kept crate decodes ROS 1 messages without
//! generated code).

use anyhow::{anyhow, bail};
use serde::{Deserialize, Serialize};

/// The ROS 2 type name.
pub const ROS2_TYPE: &str = "sensor_msgs/msg/Imu";

/// The ROS 1 type name.
pub const ROS1_TYPE: &str = "sensor_msgs/Imu";

/// True for a topic type that carries sensor_msgs/Imu (ROS 1 or 2).
pub fn is_imu(ty: &str) -> bool {
    ty == ROS2_TYPE || ty == ROS1_TYPE
}

/// builtin_interfaces/msg/Time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, below 10⁹.
    pub nanosec: u32,
}

/// std_msgs/msg/Header.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The time of the sample.
    pub stamp: Time,
    /// The sensor's frame.
    pub frame_id: String,
}

/// sensor_msgs/msg/Imu, field for field.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu {
    /// Stamp and frame.
    pub header: Header,
    /// x, y, z, w.
    pub orientation: [f64; 4],
    /// Row-major 3×3; element 0 = -1: no orientation.
    pub orientation_covariance: [f64; 9],
    /// rad/s.
    pub angular_velocity: [f64; 3],
    /// Row-major 3×3 (0: unknown).
    pub angular_velocity_covariance: [f64; 9],
    /// m/s².
    pub linear_acceleration: [f64; 3],
    /// Row-major 3×3 (0: unknown).
    pub linear_acceleration_covariance: [f64; 9],
}

/// The stamp in seconds: the nearest f64 to sec + nanosec/10⁹ while the
/// total of nanoseconds fits f64's 53 bits (104 days), so a time written
/// with at most nine decimals comes back as the same f64 ([`stamp_of`]).
pub fn stamp_seconds(sec: i64, nanosec: u32) -> f64 {
    nanoseconds_to_seconds(sec as i128 * 1_000_000_000 + nanosec as i128)
}

/// Nanoseconds as seconds (one division, correctly rounded).
pub fn nanoseconds_to_seconds(ns: i128) -> f64 {
    ns as f64 / 1e9
}

/// The stamp of time `t` (s), to the nearest nanosecond.
pub fn stamp_of(t: f64) -> Time {
    let ns = (t * 1e9).round() as i128;
    Time {
        sec: ns.div_euclid(1_000_000_000) as i32,
        nanosec: ns.rem_euclid(1_000_000_000) as u32,
    }
}

/// Decodes a ROS 2 CDR sensor_msgs/msg/Imu (with its encapsulation header).
pub fn decode_cdr(data: &[u8]) -> anyhow::Result<Imu> {
    // The cdr crate allocates a string's declared length before it checks
    // it against the message: check frame_id's length here first.
    if data.len() < 16 {
        bail!("{} bytes: too short for sensor_msgs/msg/Imu", data.len());
    }
    let len_bytes = [data[12], data[13], data[14], data[15]];
    let len = match data[1] {
        0 | 2 => u32::from_be_bytes(len_bytes),
        1 | 3 => u32::from_le_bytes(len_bytes),
        e => bail!("CDR encapsulation {e} is not plain CDR"),
    };
    if len as usize > data.len() - 16 {
        bail!(
            "frame_id's length {len} runs past the message's {} bytes",
            data.len()
        );
    }
    cdr::deserialize::<Imu>(data).map_err(|e| anyhow!("not a CDR sensor_msgs/msg/Imu: {e}"))
}

/// Encodes `imu` as ROS 2 CDR, little-endian, with its encapsulation header.
pub fn encode_cdr(imu: &Imu) -> Vec<u8> {
    // Cannot fail: no size limit, and every field is serialisable.
    cdr::serialize::<_, _, cdr::CdrLe>(imu, cdr::Infinite).unwrap_or_default()
}

/// Decodes a ROS 1 sensor_msgs/Imu: (stamp seconds, angular velocity, linear acceleration).
pub fn decode_ros1(data: &[u8]) -> anyhow::Result<(f64, [f64; 3], [f64; 3])> {
    let u32_at = |at: usize| -> anyhow::Result<u32> {
        data.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| anyhow!("{} bytes: too short for sensor_msgs/Imu", data.len()))
    };
    let (sec, nsec, id_len) = (u32_at(4)?, u32_at(8)?, u32_at(12)? as usize);
    // After the header: orientation (4), its covariance (9), then the rate (3).
    let floats = 16usize
        .checked_add(id_len)
        .filter(|&start| start + 37 * 8 == data.len())
        .ok_or_else(|| {
            anyhow!(
                "{} bytes with a frame_id of {id_len}: not the length of a sensor_msgs/Imu",
                data.len()
            )
        })?;
    let f = |k: usize| {
        let at = floats + 8 * k;
        f64::from_le_bytes(data[at..at + 8].try_into().unwrap_or([0; 8]))
    };
    let gyro = [f(13), f(14), f(15)];
    let accel = [f(25), f(26), f(27)];
    Ok((stamp_seconds(sec as i64, nsec), gyro, accel))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdr_round_trips_and_a_lying_length_is_refused() {
        let imu = Imu {
            header: Header {
                stamp: Time {
                    sec: 12,
                    nanosec: 500_000_000,
                },
                frame_id: "imu".into(),
            },
            angular_velocity: [0.1, -0.2, 0.3],
            linear_acceleration: [0.0, 0.5, 9.81],
            ..Imu::default()
        };
        let bytes = encode_cdr(&imu);
        assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
        assert_eq!(decode_cdr(&bytes).unwrap(), imu);
        let mut bad = bytes.clone();
        bad[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode_cdr(&bad)
            .unwrap_err()
            .to_string()
            .contains("runs past"));
        assert!(decode_cdr(&bytes[..40]).is_err());
    }

    #[test]
    fn ros1_layout_is_packed() {
        let mut data = Vec::new();
        data.extend_from_slice(&7u32.to_le_bytes());
        data.extend_from_slice(&3u32.to_le_bytes());
        data.extend_from_slice(&250_000_000u32.to_le_bytes());
        data.extend_from_slice(&2u32.to_le_bytes());
        data.extend_from_slice(b"ab");
        for k in 0..37 {
            data.extend_from_slice(&(k as f64).to_le_bytes());
        }
        let (t, g, a) = decode_ros1(&data).unwrap();
        assert_eq!((t, g, a), (3.25, [13.0, 14.0, 15.0], [25.0, 26.0, 27.0]));
        assert!(decode_ros1(&data[..data.len() - 1]).is_err());
    }
}
