//! The EuRoC MAV / TUM-VI IMU CSV (`mav0/imu0/data.csv`): a header line
//! starting `#timestamp [ns]`, then `t_ns,wx,wy,wz,ax,ay,az` (rad/s, m/s²),
//! the time in integer nanoseconds.

use std::path::Path;

use anyhow::{anyhow, bail};

use super::imu_msg;
use super::text_lines::{number, open_with_header, TextLines};
use super::{Channels, Format, Opened, Place, Sample, Source};

/// The columns after the time, in the file's order.
const COLUMNS: [&str; 6] = [
    "w_RS_S_x", "w_RS_S_y", "w_RS_S_z", "a_RS_S_x", "a_RS_S_y", "a_RS_S_z",
];

/// Opens the EuRoC / TUM-VI CSV at `path`.
pub fn open(path: &Path) -> anyhow::Result<Opened> {
    let (name, header, reader, number_) = open_with_header(path)?;
    let names: Vec<&str> = header
        .split(',')
        .map(|c| c.split_whitespace().next().unwrap_or(""))
        .collect();
    if names.len() != 7 || names[1..] != COLUMNS {
        bail!(
            "{name}: the header `{header}` is not EuRoC's `#timestamp [ns],{}` (with their units)",
            COLUMNS.join(",")
        );
    }
    let parse = Box::new(|line: &str, at: u64| {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != 7 {
            bail!("expected 7 columns, found {}", cells.len());
        }
        let ns: u64 = cells[0].trim().parse().map_err(|_| {
            anyhow!(
                "column #timestamp: `{}` is not a whole number of nanoseconds",
                cells[0].trim()
            )
        })?;
        let mut v = [0.0; 6];
        for (k, x) in v.iter_mut().enumerate() {
            *x = number(cells[k + 1], COLUMNS[k])?;
        }
        let mut s = Sample::at(at, imu_msg::nanoseconds_to_seconds(ns as i128));
        s.gyro = [v[0], v[1], v[2]];
        s.accel = [v[3], v[4], v[5]];
        Ok(Some(s))
    });
    Ok(Opened {
        source: Source {
            name: name.clone(),
            format: Format::Euroc,
            channels: Channels::IMU,
            place: Place::Line,
            topic: None,
        },
        reader: Box::new(TextLines::new(name, reader, number_, parse)),
    })
}
