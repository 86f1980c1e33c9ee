//! Choosing the IMU topic of a bag (or the IMU message of a ULog): `--topic`
//! where given (a missing one lists what is there), else the only IMU topic
//! (several: the error lists them).

use anyhow::bail;

/// The topic to read among `all` ((name, type) pairs) of which `is_imu`
/// says which carry IMU samples; `name` is the file, in messages.
pub fn choose(
    name: &str,
    all: &[(String, String)],
    wanted: Option<&str>,
    is_imu: impl Fn(&str) -> bool,
) -> anyhow::Result<String> {
    let imu: Vec<&str> = all
        .iter()
        .filter(|(_, ty)| is_imu(ty))
        .map(|(n, _)| n.as_str())
        .collect();
    let listed = |names: Vec<String>| {
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    };
    match wanted {
        Some(w) => match all.iter().find(|(n, _)| n == w) {
            Some((_, ty)) if is_imu(ty) => Ok(w.to_string()),
            Some((_, ty)) => bail!(
                "{name}: --topic {w} carries {ty}, not IMU samples; IMU topics: {}",
                listed(imu.iter().map(|s| s.to_string()).collect())
            ),
            None => bail!(
                "{name}: no topic {w}; the recording has: {}",
                listed(all.iter().map(|(n, t)| format!("{n} ({t})")).collect())
            ),
        },
        None => match imu.as_slice() {
            [one] => Ok(one.to_string()),
            [] => bail!(
                "{name}: no IMU topic; the recording has: {}",
                listed(all.iter().map(|(n, t)| format!("{n} ({t})")).collect())
            ),
            several => bail!(
                "{name}: {} IMU topics ({}): choose one with --topic",
                several.len(),
                several.join(", ")
            ),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all() -> Vec<(String, String)> {
        [
            ("/imu0", "sensor_msgs/msg/Imu"),
            ("/cam", "sensor_msgs/msg/Image"),
            ("/imu1", "sensor_msgs/msg/Imu"),
        ]
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .to_vec()
    }

    fn imu(ty: &str) -> bool {
        ty.ends_with("/Imu")
    }

    #[test]
    fn several_imu_topics_need_a_choice_and_the_error_lists_them() {
        let e = choose("b", &all(), None, imu).unwrap_err().to_string();
        assert_eq!(e, "b: 2 IMU topics (/imu0, /imu1): choose one with --topic");
        assert_eq!(choose("b", &all(), Some("/imu1"), imu).unwrap(), "/imu1");
        let e = choose("b", &all(), Some("/x"), imu)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no topic /x; the recording has: /imu0 (sensor_msgs/msg/Imu), /cam"));
        let e = choose("b", &all(), Some("/cam"), imu)
            .unwrap_err()
            .to_string();
        assert!(e.contains("carries sensor_msgs/msg/Image"), "{e}");
        assert_eq!(choose("b", &all()[..2], None, imu).unwrap(), "/imu0");
    }
}
