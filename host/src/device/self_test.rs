//! `triad device selftest`: the reply as a person reads it, one line per
//! axis (docs/PROTOCOL.md gives the payload; [`SelfTestResult`] reads it).

use triad::protocol::{Reply, SelfTestResult, Status};
use triad::units::{rad_to_deg, STANDARD_GRAVITY};

use crate::plumbing::stdio::outln;

/// The lines to print, and whether the self-test ran and every axis passed.
pub fn render(reply: &Reply) -> (String, bool) {
    let mut out = String::new();
    if reply.status != Status::Ok {
        outln!(out, "self-test: {}", reply.status);
        outln!(out, "reason: {}", reply.reason());
        return (out, false);
    }
    let bytes = reply.payload.as_slice();
    let Some(result) = SelfTestResult::parse(bytes) else {
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02x}")).collect();
        outln!(
            out,
            "self-test: a result of {} bytes, not the layout this build reads: {}",
            bytes.len(),
            hex.join(" ")
        );
        return (out, false);
    };
    outln!(
        out,
        "self-test: {}",
        if result.passed { "passed" } else { "FAILED" }
    );
    let axes = ["x", "y", "z"];
    // Responses in SI, limits in the data sheets' units: both shown in the latter.
    let mg = |si: f32| f64::from(si) / STANDARD_GRAVITY * 1e3;
    let dps = |si: f32| rad_to_deg(f64::from(si));
    for (triad, results, si_unit, unit, to_unit) in [
        (
            "accel",
            &result.accel,
            "m/s²",
            "mg",
            &mg as &dyn Fn(f32) -> f64,
        ),
        ("gyro", &result.gyro, "rad/s", "°/s", &dps),
    ] {
        for (axis, a) in axes.iter().zip(results) {
            let factory = if a.factory.is_nan() {
                String::new()
            } else {
                format!(", factory {:.1} {unit}", a.factory)
            };
            let verdict = match (a.response_ok, a.offset_ok) {
                (true, true) => "ok",
                (false, true) => "FAILED: response out of limits",
                (true, false) => "FAILED: output with self-test off out of bound",
                (false, false) => "FAILED: response and self-test-off output out of bounds",
            };
            outln!(
                out,
                // A person's precision: 0.1 mg or °/s is below the chips' noise.
                "{triad} {axis}: response {:.1} {unit} ({:.4} {si_unit}), limits {:.1}..{:.1} {unit}{factory}; off {:.4} {si_unit}: {verdict}",
                to_unit(a.response),
                a.response,
                a.min,
                a.max,
                a.off,
            );
        }
    }
    (out, result.passed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use triad::protocol::self_test::AxisResult;
    use triad::protocol::Payload;

    fn reply(status: Status, payload: Payload) -> Reply {
        Reply {
            sequence: 3,
            command: triad::protocol::command::code::SELF_TEST,
            status,
            payload,
        }
    }

    #[test]
    fn a_refusal_shows_its_status_and_reason() {
        let r = reply(
            Status::SensorError,
            Payload::new(b"the self-test did not finish").unwrap(),
        );
        assert_eq!(
            render(&r),
            (
                "self-test: sensor error\nreason: the self-test did not finish\n".into(),
                false
            )
        );
    }

    #[test]
    fn each_axis_is_a_line_with_its_verdict() {
        let good = AxisResult {
            response: 4.903325,
            off: 0.01,
            min: 50.0,
            max: 1700.0,
            factory: f32::NAN,
            response_ok: true,
            offset_ok: true,
        };
        let weak = AxisResult {
            response_ok: false,
            factory: 480.0,
            ..good
        };
        let result = SelfTestResult {
            passed: false,
            accel: [good, weak, good],
            gyro: [good; 3],
        };
        let (text, passed) = render(&reply(Status::Ok, result.to_payload()));
        assert!(!passed);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 7, "{text}");
        assert_eq!(lines[0], "self-test: FAILED");
        // 4.903325 m/s² is 500 mg.
        assert_eq!(
            lines[1],
            "accel x: response 500.0 mg (4.9033 m/s²), limits 50.0..1700.0 mg; off 0.0100 m/s²: ok"
        );
        assert!(
            lines[2].contains("mg, factory 480.0 mg; off"),
            "{}",
            lines[2]
        );
        assert!(lines[2].ends_with(": FAILED: response out of limits"));
        assert!(
            lines[4].starts_with("gyro x: response 280.9"),
            "{}",
            lines[4]
        );
        let short = reply(Status::Ok, Payload::new(&[1, 2]).unwrap());
        assert_eq!(
            render(&short),
            (
                "self-test: a result of 2 bytes, not the layout this build reads: 01 02\n".into(),
                false
            )
        );
    }
}
