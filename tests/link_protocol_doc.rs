//! docs/PROTOCOL.md's version-2 examples stay true: the command and reply
//! bytes it shows are what the code produces, and decode back.

use triad::link::{Command, Packet, Payload, Reply, Status, MAX_WIRE_LEN};
use triad::stream::Decoder;

mod protocol_doc;

use protocol_doc::{doc_hex, hex_lines};

/// Checks `name-unstuffed` and `name-wire` against the packet, and that the
/// wire bytes decode back to `expected`.
fn check(name: &str, packet: &triad::link::PacketBuf, expected: &Packet) {
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
}
