//! The stream `cargo xtask test` captured from QEMU (TRIAD_E2E_STREAM),
//! decoded, with the decoder's and the device's loss counters checked: what
//! every end-to-end test on it starts from.

use std::path::PathBuf;

use triad::protocol::{Decoder, Frame, Packet};

/// The path in the environment variable `name` (set by cargo xtask test).
pub fn env_path(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var_os(name).unwrap_or_else(|| panic!("{name} is set by cargo xtask test")),
    )
}

/// Every packet of the capture, after checking that none failed to decode
/// and that nothing was lost: no CRC error, malformed packet, sequence gap,
/// skipped byte, or overrun or drop the device reported.
pub fn packets() -> Vec<Packet> {
    let bytes = std::fs::read(env_path("TRIAD_E2E_STREAM")).expect("stream capture");
    let mut decoder = Decoder::new();
    let packets: Vec<Packet> = decoder
        .feed_packets(&bytes)
        .map(|p| p.expect("no packet of the capture fails to decode"))
        .collect();
    let stats = decoder.stats();
    assert_eq!(stats.crc_errors, 0, "{stats:?}");
    assert_eq!(stats.malformed, 0, "{stats:?}");
    assert_eq!(stats.sequence_gaps, 0, "{stats:?}");
    assert_eq!(stats.bytes_skipped, 0, "{stats:?}");
    assert_eq!(stats.device_overruns, 0, "no sample lost: {stats:?}");
    assert_eq!(stats.device_dropped, 0, "the link kept up: {stats:?}");
    packets
}

/// A data frame's six corrected values: accel x y z, gyro x y z.
pub fn six_axes(frame: &Frame) -> [f32; 6] {
    let (a, g) = (frame.accel, frame.gyro);
    [a[0], a[1], a[2], g[0], g[1], g[2]]
}
