//! `triad device selftest`: the reply, as a person reads it. The result
//! payload's layout is not defined yet (docs/PROTOCOL.md will say it), so
//! an ok reply's payload is shown as bytes; this is the one function to
//! change when it is.

use triad::link::{Reply, Status};

use crate::stdio::outln;

/// The lines to print, and whether the self-test ran and passed.
pub fn render(reply: &Reply) -> (String, bool) {
    let mut out = String::new();
    outln!(out, "self-test: {}", reply.status);
    if reply.status == Status::Ok {
        let bytes = reply.payload.as_slice();
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02x}")).collect();
        outln!(out, "result: {} bytes: {}", bytes.len(), hex.join(" "));
    } else {
        outln!(out, "reason: {}", reply.reason());
    }
    (out, reply.status == Status::Ok)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::link::Payload;

    #[test]
    fn a_refusal_shows_its_status_and_reason() {
        let reply = Reply {
            sequence: 3,
            command: triad::link::command::code::SELF_TEST,
            status: Status::NotSupported,
            payload: Payload::new(b"no self-test on this chip").unwrap(),
        };
        let (text, passed) = render(&reply);
        assert_eq!(
            text,
            "self-test: not supported\nreason: no self-test on this chip\n"
        );
        assert!(!passed);
        let ok = Reply {
            status: Status::Ok,
            payload: Payload::new(&[1, 0xab]).unwrap(),
            ..reply
        };
        assert_eq!(
            render(&ok),
            ("self-test: ok\nresult: 2 bytes: 01 ab\n".into(), true)
        );
    }
}
