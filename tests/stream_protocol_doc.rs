//! docs/PROTOCOL.md stays true: its worked example, stuffing example and
//! check value are what the code produces.

use triad::protocol::{cobs, crc32c, encode, Decoder, Flags, Frame, MAX_ENCODED_LEN};

mod protocol_doc;

use protocol_doc::{doc_hex, hex_lines};

const DOC: &str = include_str!("../docs/PROTOCOL.md");

/// The frame the document's worked example decodes to.
fn example_frame() -> Frame {
    Frame {
        sequence: 42,
        timestamp_us: 1_000_000,
        flags: Flags::ACCEL_CLIPPED | Flags::OVERRUN,
        overruns: 1,
        dropped: 0,
        calibration_id: 0x1234_5678,
        accel: [0.5, -0.25, 9.80665],
        gyro: [0.0, 0.001, -0.0175],
        temperature: 25.0,
    }
}

#[test]
fn worked_example_matches_the_encoder() {
    let frame = example_frame();
    let raw = frame.to_bytes();
    let mut wire = [0u8; MAX_ENCODED_LEN];
    let n = encode(&frame, &mut wire);
    let wire = &wire[..n];
    println!(
        "unstuffed:\n{}\nwire:\n{}",
        hex_lines(&raw),
        hex_lines(wire)
    );
    assert_eq!(
        doc_hex("example-unstuffed"),
        raw,
        "PROTOCOL.md unstuffed example is stale"
    );
    assert_eq!(
        doc_hex("example-wire"),
        wire,
        "PROTOCOL.md wire example is stale"
    );
    let crc = crc32c(&raw[..47]);
    assert!(
        DOC.contains(&format!("0x{crc:08X}")),
        "PROTOCOL.md must quote the example CRC 0x{crc:08X}"
    );
    let mut decoder = Decoder::new();
    let decoded: Vec<_> = decoder.feed(wire).collect();
    assert_eq!(decoded, vec![Ok(frame)]);
}

#[test]
fn stuffing_example_matches_the_code() {
    let data = doc_hex("stuffing-data");
    let want = doc_hex("stuffing-wire");
    let mut out = vec![0u8; cobs::max_stuffed_len(data.len())];
    let n = cobs::stuff(&data, &mut out).unwrap();
    out.truncate(n);
    out.push(0);
    assert_eq!(out, want);
}

#[test]
fn check_value_is_quoted() {
    assert!(DOC.contains("0xE3069283"));
    assert_eq!(crc32c(b"123456789"), 0xE306_9283);
}
