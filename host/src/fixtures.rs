//! Test fixtures that need no `triad` binary, shared by the library's unit
//! tests and the integration tests (`tests/common` re-exports them). Not
//! part of the command: a library module only so that both kinds of test
//! reach one copy without a `#[path]` include.

use std::path::Path;

use triad::protocol::{encode, Frame, MAX_ENCODED_LEN};

/// Frames 0..n, 10 ms apart from t = 1 s, as the firmware sends them.
pub fn stream(n: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut out = [0u8; MAX_ENCODED_LEN];
    for i in 0..n {
        let frame = Frame {
            sequence: i,
            timestamp_us: 1_000_000 + 10_000 * i,
            accel: [0.5, -1.0, 9.75],
            gyro: [0.0, 0.125, -2.0],
            temperature: 25.5,
            ..Frame::default()
        };
        let len = encode(&frame, &mut out);
        bytes.extend_from_slice(&out[..len]);
    }
    bytes
}

/// The names of the files in `d`, sorted (to see that no temporary file is left).
pub fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
