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
    // The same f64 as from i128 (both conversions round to nearest), in
    // one instruction where it fits (every i32 stamp does) rather than a
    // library call: a twentieth of reading a bag's samples.
    match i64::try_from(ns) {
        Ok(ns) => ns as f64 / 1e9,
        Err(_) => ns as f64 / 1e9,
    }
}

/// A log time (ns, as MCAP and rosbag2 keep it) as seconds.
pub fn log_time_seconds(ns: u64) -> f64 {
    nanoseconds_to_seconds(ns as i128)
}

/// The stamp of time `t` (s), to the nearest nanosecond.
pub fn stamp_of(t: f64) -> Time {
    let ns = (t * 1e9).round() as i128;
    Time {
        sec: ns.div_euclid(1_000_000_000) as i32,
        nanosec: ns.rem_euclid(1_000_000_000) as u32,
    }
}

/// What a record takes of a sensor_msgs/msg/Imu.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuFields {
    /// The header's stamp.
    pub stamp: Time,
    /// rad/s.
    pub angular_velocity: [f64; 3],
    /// m/s².
    pub linear_acceleration: [f64; 3],
}

/// The f64s of sensor_msgs/msg/Imu after its header.
const IMU_FLOATS: usize = 37;

/// Decodes a ROS 2 CDR sensor_msgs/msg/Imu (with its encapsulation header).
///
/// Read at fixed offsets after the one variable field (the frame_id): the
/// message is a header and 37 f64s, so this is the whole of CDR it needs;
/// it reads only the six f64s it returns (after checking that all 37 are
/// there) and allocates nothing (serde's decoding through the `cdr` crate
/// made a String per message and was an eighth of `triad allan`'s time on
/// a bag). [`encode_cdr`] writes with the `cdr` crate, so the tests hold
/// the two against each other. Inlined where it is called: the fields then
/// stay in registers (returned through memory, they were a fifth of the
/// time `triad allan` took to decode a message).
#[inline(always)]
pub fn decode_cdr(data: &[u8]) -> anyhow::Result<ImuFields> {
    let body = CdrBody::of(data, IMU_FLOATS, ROS2_TYPE)?;
    let f = |k: usize| body.float(data, k);
    Ok(ImuFields {
        stamp: body.stamp,
        angular_velocity: [f(13), f(14), f(15)],
        linear_acceleration: [f(25), f(26), f(27)],
    })
}

/// Decodes a ROS 2 CDR message that is a std_msgs/Header followed by `N`
/// f64s (sensor_msgs/msg/Imu, sensor_msgs/msg/Temperature): its stamp and
/// the f64s. A message longer than that is accepted (its tail is not read),
/// as CDR readers do.
pub fn decode_header_and_floats<const N: usize>(
    data: &[u8],
    ty: &str,
) -> anyhow::Result<(Time, [f64; N])> {
    let body = CdrBody::of(data, N, ty)?;
    Ok((body.stamp, std::array::from_fn(|k| body.float(data, k))))
}

/// Where the f64s after a CDR message's std_msgs/Header start, checked to
/// hold as many as the type has.
struct CdrBody {
    stamp: Time,
    little: bool,
    /// The byte of the first f64.
    start: usize,
}

impl CdrBody {
    /// The header of `data`, a message of type `ty` whose header is
    /// followed by `floats` f64s (an error when they are not all there).
    #[inline(always)]
    fn of(data: &[u8], floats: usize, ty: &str) -> anyhow::Result<CdrBody> {
        // Encapsulation (4 bytes), then sec, nanosec and frame_id's length.
        if data.len() < 16 {
            bail!("{} bytes: too short for {ty}", data.len());
        }
        let little = match data[1] {
            0 | 2 => false,
            1 | 3 => true,
            e => bail!("CDR encapsulation {e} is not plain CDR"),
        };
        let word = |at: usize| {
            let b = [data[at], data[at + 1], data[at + 2], data[at + 3]];
            if little {
                u32::from_le_bytes(b)
            } else {
                u32::from_be_bytes(b)
            }
        };
        let (sec, nanosec, len) = (word(4) as i32, word(8), word(12) as usize);
        if len > data.len() - 16 {
            bail!(
                "frame_id's length {len} runs past the message's {} bytes",
                data.len()
            );
        }
        // CDR aligns an f64 to 8 bytes from the start of the body (after the
        // 4-byte encapsulation).
        let body_at = (12 + len).next_multiple_of(8);
        let start = 4 + body_at;
        if data.len() < start + 8 * floats {
            bail!(
                "{} bytes with a frame_id of {len}: too short for {ty}",
                data.len()
            );
        }
        Ok(CdrBody {
            stamp: Time { sec, nanosec },
            little,
            start,
        })
    }

    /// The `k`th f64 of `data` (k below the count [`CdrBody::of`] checked).
    #[inline]
    fn float(&self, data: &[u8], k: usize) -> f64 {
        let at = self.start + 8 * k;
        let mut b = [0u8; 8];
        b.copy_from_slice(&data[at..at + 8]);
        if self.little {
            f64::from_le_bytes(b)
        } else {
            f64::from_be_bytes(b)
        }
    }
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
        let fields = decode_cdr(&bytes).unwrap();
        assert_eq!(fields.stamp, imu.header.stamp);
        assert_eq!(fields.angular_velocity, imu.angular_velocity);
        assert_eq!(fields.linear_acceleration, imu.linear_acceleration);
        // Big-endian CDR and every length of frame_id (its padding): as the crate writes them.
        for id in ["", "a", "abc", "abcdefgh", "abcdefghi"] {
            let imu = Imu {
                header: Header {
                    frame_id: id.into(),
                    ..imu.header.clone()
                },
                ..imu.clone()
            };
            for bytes in [
                encode_cdr(&imu),
                cdr::serialize::<_, _, cdr::CdrBe>(&imu, cdr::Infinite).unwrap(),
            ] {
                let fields = decode_cdr(&bytes).unwrap();
                assert_eq!(fields.stamp, imu.header.stamp, "{id:?}");
                assert_eq!(fields.angular_velocity, imu.angular_velocity, "{id:?}");
                assert_eq!(fields.linear_acceleration, imu.linear_acceleration);
                assert!(decode_cdr(&bytes[..bytes.len() - 1]).is_err());
            }
        }
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
