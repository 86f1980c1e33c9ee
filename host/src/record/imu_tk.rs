//! imu_tk's text (`importAsciiData`): one triad per file, each line
//! `t x y z` separated by spaces or tabs, t in seconds (imu_tk's
//! `TIMESTAMP_UNIT_SEC`, as its test program reads them), the values taken
//! as SI (m/s² for an accelerometer, rad/s for a gyroscope). Which triad:
//! `--imu-tk-triad`, else the file's name (`acc…` or `gyr…`).

use std::path::Path;

use anyhow::bail;
use triad::model::Triad;

use super::text_lines::{number, TextLines};
use super::{Channels, Format, Opened, Options, Place, Sample, Source};
use crate::plumbing::input;

/// Opens the imu_tk file at `path`.
pub fn open(path: &Path, options: &Options) -> anyhow::Result<Opened> {
    let name = input::name(path);
    let triad = match options.imu_tk_triad.or_else(|| triad_from_name(path)) {
        Some(t) => t,
        None => bail!(
            "{name}: an imu_tk file holds one triad and its name does not say which (acc… or gyr…): give --imu-tk-triad accel or --imu-tk-triad gyro"
        ),
    };
    let opened = input::open_bytes(path, 1 << 20)?;
    let parse = Box::new(move |line: &str, at: u64| {
        let cells: Vec<&str> = line.split_whitespace().collect();
        if cells.len() != 4 {
            bail!("expected 4 numbers (t x y z), found {}", cells.len());
        }
        let mut s = Sample::at(at, number(cells[0], "t")?);
        let v = [
            number(cells[1], "x")?,
            number(cells[2], "y")?,
            number(cells[3], "z")?,
        ];
        match triad {
            Triad::Accel => s.accel = v,
            Triad::Gyro => s.gyro = v,
        }
        Ok(Some(s))
    });
    Ok(Opened {
        source: Source {
            name: name.clone(),
            format: Format::ImuTk,
            channels: Channels {
                accel: triad == Triad::Accel,
                gyro: triad == Triad::Gyro,
                temp: false,
            },
            place: Place::Line,
            topic: None,
        },
        reader: Box::new(TextLines::new(name, opened.reader, 0, parse)),
    })
}

/// The triad a file's name says: `acc…` or `gyr…` (case ignored).
fn triad_from_name(path: &Path) -> Option<Triad> {
    let stem = path.file_name()?.to_str()?.to_ascii_lowercase();
    match (stem.contains("acc"), stem.contains("gyr")) {
        (true, false) => Some(Triad::Accel),
        (false, true) => Some(Triad::Gyro),
        _ => None,
    }
}
