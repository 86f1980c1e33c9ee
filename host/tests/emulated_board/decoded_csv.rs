//! The CSV `triad decode` and `triad device stream` print, read back.

use triad::model::Sample;
use triad::protocol::{Flags, Frame};

/// One row: the frame's number, its seven values (accel, gyro,
/// temperature) and its flags.
#[derive(Debug)]
pub struct Row {
    pub sequence: u32,
    pub values: [f32; 7],
    pub flags: Flags,
}

/// The rows of `csv`, whose header is checked.
pub fn rows(csv: &str) -> Vec<Row> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("seq,t,ax,ay,az,gx,gy,gz,temp,flags"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 10, "{line}");
            let mut values = [0f32; 7];
            for (v, x) in values.iter_mut().zip(&f[2..9]) {
                *v = x.parse().unwrap_or_else(|_| panic!("{line}"));
            }
            Row {
                sequence: f[0].parse().unwrap(),
                values,
                flags: Flags::from_bits_retain(f[9].parse().unwrap()),
            }
        })
        .collect()
}

/// A frame's seven values as a row holds them.
pub fn frame_values(frame: &Frame) -> [f32; 7] {
    let (a, g) = (frame.accel, frame.gyro);
    [a[0], a[1], a[2], g[0], g[1], g[2], frame.temperature]
}

/// A sample's seven values as a row holds them.
pub fn sample_values(sample: &Sample) -> [f32; 7] {
    let (a, g) = (sample.accel, sample.gyro);
    [a[0], a[1], a[2], g[0], g[1], g[2], sample.temperature]
}
