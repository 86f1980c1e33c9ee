//! triad's CSV: a header naming the columns (`t,ax,ay,az,gx,gy,gz,temp` as
//! `triad sim` writes; `triad decode` adds `seq` and `flags`), in any order,
//! SI units. A triad is read where its three columns are all present.

use std::path::Path;

use anyhow::bail;

use super::text_lines::{number, open_with_header, TextLines};
use super::{Channels, Format, Opened, Place, Sample, Source};

/// The channel columns, in `Sample` order: t, accel, gyro, temp.
const NAMES: [&str; 8] = ["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"];

/// Opens triad's CSV at `path`.
pub fn open(path: &Path) -> anyhow::Result<Opened> {
    let (name, header, reader, number_) = open_with_header(path)?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let index: Vec<Option<usize>> = NAMES
        .iter()
        .map(|n| names.iter().position(|h| h == n))
        .collect();
    let all = |r: std::ops::Range<usize>| index[r].iter().all(Option::is_some);
    let channels = Channels {
        accel: all(1..4),
        gyro: all(4..7),
        temp: index[7].is_some(),
    };
    if index[0].is_none() || !(channels.accel || channels.gyro) {
        bail!("{name}: the header `{header}` lacks t or a whole triad (ax,ay,az or gx,gy,gz)");
    }
    let width = names.len();
    let parse = Box::new(move |line: &str, at: u64| {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != width {
            bail!(
                "expected {width} columns as in the header, found {}",
                cells.len()
            );
        }
        let mut v = [f64::NAN; 8];
        for (k, i) in index.iter().enumerate() {
            if let Some(i) = i {
                v[k] = number(cells[*i], NAMES[k])?;
            }
        }
        Ok(Some(Sample {
            t: v[0],
            accel: if channels.accel {
                [v[1], v[2], v[3]]
            } else {
                [0.0; 3]
            },
            gyro: if channels.gyro {
                [v[4], v[5], v[6]]
            } else {
                [0.0; 3]
            },
            temp: v[7],
            at,
        }))
    });
    Ok(Opened {
        source: Source {
            name: name.clone(),
            format: Format::TriadCsv,
            channels,
            place: Place::Line,
            topic: None,
        },
        reader: Box::new(TextLines::new(name, reader, number_, parse)),
    })
}
