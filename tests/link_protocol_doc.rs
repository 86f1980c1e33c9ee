//! docs/PROTOCOL.md's version-2 examples stay true: the command and reply
//! bytes it shows are what the code produces, and decode back.

use triad::protocol::Decoder;
use triad::protocol::{Command, Packet, Payload, Reply, Status, MAX_WIRE_LEN};

mod protocol_doc;

use protocol_doc::{doc_hex, hex_lines};

/// Checks `name-unstuffed` and `name-wire` against the packet, and that the
/// wire bytes decode back to `expected`.
fn check(name: &str, packet: &triad::protocol::PacketBuf, expected: &Packet) {
    let mut wire = [0u8; MAX_WIRE_LEN];
    let n = packet.to_wire(&mut wire);
    println!(
        "{name} unstuffed:\n{}\n{name} wire:\n{}",
        hex_lines(packet.as_bytes()),
        hex_lines(&wire[..n])
    );
    assert_eq!(
        doc_hex(&format!("{name}-unstuffed")),
        packet.as_bytes(),
        "{name}: stale"
    );
    assert_eq!(
        doc_hex(&format!("{name}-wire")),
        &wire[..n],
        "{name}: stale"
    );
    let mut decoder = Decoder::new();
    let mut bytes = vec![0u8];
    bytes.extend_from_slice(&wire[..n]);
    let decoded: Vec<_> = decoder.feed_packets(&bytes).collect();
    assert_eq!(decoded, vec![Ok(expected.clone())], "{name}");
}

#[test]
fn command_and_reply_examples_match_the_code() {
    let command = Command::SetDecimation(8);
    let packet = command.to_packet(7).unwrap();
    let Ok(Packet::Command(parsed)) = Packet::parse(packet.as_bytes()) else {
        panic!("the command parses");
    };
    assert_eq!(parsed.command(), Ok(command));
    check("command", &packet, &Packet::Command(parsed));

    let ok = Reply {
        sequence: 7,
        command: command.code(),
        status: Status::Ok,
        payload: Payload::EMPTY,
    };
    check("reply-ok", &ok.to_packet().unwrap(), &Packet::Reply(ok));

    let refused = Reply {
        sequence: 8,
        command: command.code(),
        status: Status::BadArgument,
        payload: Payload::new(b"command 0x03: decimation must be at least 1").unwrap(),
    };
    check(
        "reply-error",
        &refused.to_packet().unwrap(),
        &Packet::Reply(refused),
    );
    // The firmware's form (written where the wire bytes go): the same bytes.
    for (name, reply) in [("reply-ok", ok), ("reply-error", refused)] {
        let mut wire = [0x55; MAX_WIRE_LEN];
        let n = reply.to_wire(&mut wire).unwrap();
        assert_eq!(doc_hex(&format!("{name}-wire")), &wire[..n], "{name}");
    }
}

const DOC: &str = include_str!("../docs/PROTOCOL.md");

/// True when the document says `text` (its line breaks read as spaces).
fn doc_says(text: &str) -> bool {
    DOC.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .contains(text)
}

#[test]
fn each_stated_limit_is_the_codes() {
    use triad::model::blob::BLOB_LEN;
    use triad::protocol::{CHUNK_LEN, MAX_PACKET_LEN, MAX_PAYLOAD, MAX_REPLY_PAYLOAD};
    let stated = [
        ("at most 240 bytes before stuffing", MAX_PACKET_LEN, 240),
        ("(242 on the wire)", MAX_WIRE_LEN, 242),
        ("a command's arguments are at most 231", MAX_PAYLOAD, 231),
        ("a reply's payload at most 230", MAX_REPLY_PAYLOAD, 230),
        ("`offset u16 \\| ≤ 128 bytes`", CHUNK_LEN, 128),
        ("`total length u16 \\| ≤ 128 bytes`", CHUNK_LEN, 128),
        ("584 bytes (version 3), little-endian", BLOB_LEN, 584),
    ];
    for (text, code, figure) in stated {
        assert!(doc_says(text), "PROTOCOL.md no longer says {text:?}");
        assert_eq!(code, figure, "{text:?}: the code says {code}");
    }
}

/// A version-2 packet of `kind` with `body` and a good CRC.
fn sealed(version: u8, kind: u8, body: &[u8]) -> Vec<u8> {
    let mut bytes = vec![version, kind];
    bytes.extend_from_slice(body);
    let crc = triad::protocol::crc32c(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    bytes
}

/// What the decoder makes of `packet` between two delimiters.
fn decode(packet: &[u8]) -> (Vec<Result<Packet, triad::protocol::DecodeError>>, Decoder) {
    let mut wire = vec![0u8; packet.len() + packet.len() / 254 + 2];
    let n = triad::protocol::cobs::stuff(packet, &mut wire).unwrap();
    let mut bytes = vec![0u8];
    bytes.extend_from_slice(&wire[..n]);
    bytes.push(0);
    let mut decoder = Decoder::new();
    let decoded = decoder.feed_packets(&bytes).collect();
    (decoded, decoder)
}

#[test]
fn every_packet_up_to_240_bytes_is_read_and_no_longer_one() {
    use triad::protocol::{MAX_PACKET_LEN, MAX_PAYLOAD, MAX_REPLY_PAYLOAD};
    // The longest reply, as the device builds it and the host decodes it.
    let longest = Reply {
        sequence: 9,
        command: 0x01,
        status: Status::Ok,
        payload: Payload::new(&[0x5A; MAX_REPLY_PAYLOAD]).unwrap(),
    };
    let packet = longest.to_packet().unwrap();
    assert_eq!(packet.as_bytes().len(), MAX_PACKET_LEN);
    let (decoded, decoder) = decode(packet.as_bytes());
    assert_eq!(decoded, vec![Ok(Packet::Reply(longest))]);
    assert_eq!(
        (decoder.stats().messages, decoder.stats().malformed),
        (1, 0)
    );
    // One payload byte more does not fit a reply.
    let too_long = Reply {
        payload: Payload::new(&[0x5A; MAX_PAYLOAD]).unwrap(),
        ..longest
    };
    assert!(too_long.to_packet().is_err());
    // The longest command: 231 argument bytes.
    let mut body = vec![0x07, 0x00, 0x04];
    body.extend_from_slice(&[0xA5; MAX_PAYLOAD]);
    let command = sealed(2, 0x10, &body);
    assert_eq!(command.len(), MAX_PACKET_LEN);
    let Ok(Packet::Command(parsed)) = Packet::parse(&command) else {
        panic!("a 240-byte command is read");
    };
    assert_eq!(parsed.args.as_slice().len(), MAX_PAYLOAD);
    // 241 bytes with a good CRC: malformed.
    body.push(0xA5);
    let (decoded, decoder) = decode(&sealed(2, 0x10, &body));
    assert!(matches!(decoded.as_slice(), [Err(_)]), "{decoded:?}");
    assert_eq!(decoder.stats().malformed, 1);
}

#[test]
fn a_later_versions_packet_with_a_good_crc_is_counted_malformed() {
    let (decoded, decoder) = decode(&sealed(3, 0x10, &[1, 0, 1]));
    assert!(matches!(decoded.as_slice(), [Err(_)]), "{decoded:?}");
    let stats = decoder.stats();
    assert_eq!((stats.malformed, stats.crc_errors), (1, 0));
    assert!(doc_says(
        "whose CRC is good is counted *malformed*, not as a CRC error"
    ));
}

#[test]
fn the_blob_example_is_the_shipped_default_calibration_byte_for_byte() {
    use triad::model::blob;
    use triad::model::{Calibration, TriadCalibration};
    let example = doc_hex("blob-example");
    let shipped: &[u8] = include_bytes!("../calibrations/default.bin");
    assert_eq!(
        example, shipped,
        "PROTOCOL.md §21 or calibrations/default.bin is stale"
    );
    // The values the section lists, packed with the id derived as it says.
    let mut cal = Calibration {
        id: 0,
        accel: TriadCalibration {
            scale_misalignment: [
                [1.002, 0.001, -0.0005],
                [0.0003, 0.998, 0.002],
                [0.0, -0.001, 1.001],
            ],
            bias: [0.05, -0.02, 0.10],
            temperature: None,
        },
        gyro: TriadCalibration {
            bias: [0.001, -0.002, 0.0005],
            ..TriadCalibration::IDENTITY
        },
        g_sensitivity: Some([
            [1.78e-4, 2.0e-5, -1.0e-5],
            [-1.5e-5, 2.1e-4, 3.0e-5],
            [0.0, 1.2e-5, -1.6e-4],
        ]),
    };
    // With a G the id covers bytes 12..=579 (§21).
    cal.id = triad::protocol::crc32c(&blob::encode(&cal)[12..580]);
    assert_eq!(cal.id, 0xA545_68AE);
    assert_eq!(cal.id, blob::parameter_id(&cal));
    assert_eq!(blob::encode(&cal).as_slice(), example.as_slice());
    assert_eq!(
        u32::from_le_bytes(example[580..].try_into().unwrap()),
        triad::protocol::crc32c(&example[..580])
    );
}

#[test]
fn a_tie_in_the_shortest_decimal_goes_to_the_larger_magnitude() {
    // `triad decode` prints with Rust's `{:?}` (host/src/decode/rows.rs).
    // 2097152.25 exactly (an f32 there is a multiple of 0.25): 2097152.2
    // and 2097152.3 both read back to it and are equally near.
    let tie = 2_097_152f32 + 0.25;
    assert_eq!(tie as f64, 2_097_152.25);
    assert_eq!(format!("{tie:?}"), "2097152.3");
    assert_eq!(format!("{:?}", -tie), "-2097152.3");
    assert_eq!("2097152.2".parse::<f32>(), Ok(tie));
    assert!(doc_says("the `f32` 2097152.25 prints `2097152.3`"));
    for (value, text) in [
        (1.0f32, "1.0"),
        (1e-4, "0.0001"),
        (1e-5, "1e-5"),
        (1.5e16, "1.5e16"),
        (1e16, "1e16"),
    ] {
        assert_eq!(format!("{value:?}"), text);
        assert!(doc_says(&format!("`{text}`")), "{text}");
    }
}
