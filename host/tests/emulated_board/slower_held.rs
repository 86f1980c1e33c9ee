//! The slower triad of a build with the accelerometer and gyroscope at two
//! rates (docs/PROTOCOL.md §22), checked on the raw samples the firmware
//! read, whatever path read them (data ready or the chip's FIFO): shared by
//! the end-to-end tests of each path.

use triad::model::Triad;
use triad::sensor::{Imu, RawSample};

use super::HostSensor;

/// Checks, in `raws` (the samples the firmware read from `sensor`'s chip),
/// that the `slower` triad (which, at what rate) reads the chip's "no data"
/// marker only before its first sample, reads no output-register reset
/// value, moves, and takes a new value only once in every stream rate /
/// slower rate samples, always at one phase: held between its own samples.
pub fn assert_held_between_its_samples(
    raws: &[RawSample],
    sensor: &HostSensor,
    (triad, slower_hz): (Triad, u32),
) {
    let ratio = (sensor.sample_rate_hz() / f64::from(slower_hz)).round() as usize;
    let scale = sensor.scale();
    assert!(ratio >= 2, "{slower_hz} Hz is slower than the stream");
    let slow = |r: &RawSample| match triad {
        Triad::Accel => r.accel,
        Triad::Gyro => r.gyro,
    };
    let no_data = match triad {
        Triad::Accel => scale.accel.codes.no_data(),
        Triad::Gyro => scale.gyro.codes.no_data(),
    };
    // Until its first sample the slower triad reads the marker on every axis.
    let first = raws.iter().take_while(|r| slow(r) == [no_data; 3]).count();
    assert!(
        first < ratio,
        "{first} samples before the slower sensor's first"
    );
    assert!(
        raws.iter().all(|r| r.accel != [0; 3] && r.gyro != [0; 3]),
        "no triad reads the output registers' reset value as a measurement"
    );
    let changed: Vec<usize> = (first + 1..raws.len())
        .filter(|&i| slow(&raws[i]) != slow(&raws[i - 1]))
        .collect();
    // The slower sensor's samples keep one phase against the faster's.
    let phase = changed.first().map_or(0, |&i| i % ratio);
    assert!(
        changed.len() > raws.len() / ratio / 2,
        "the slower sensor's value moves: {} changes in {} samples",
        changed.len(),
        raws.len()
    );
    let off_beat: Vec<usize> = changed.into_iter().filter(|i| i % ratio != phase).collect();
    assert!(
        off_beat.is_empty(),
        "held between its samples (every {ratio}): changed at {off_beat:?}"
    );
    println!(
        "the slower {triad:?} at {slower_hz} Hz: held between its samples, new once in \
         {ratio} of {} samples",
        raws.len()
    );
}
