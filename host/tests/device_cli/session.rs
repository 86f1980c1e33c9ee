//! `triad calib session` against the fake device over a pseudo-terminal:
//! the errors a user meets before any fit, each saying what happened and
//! that nothing was uploaded. (The whole session, fit to verification, runs
//! on the emulated board: host/tests/calib_session_qemu.rs.)

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::fake_device::{Applied, FakeDevice};
use super::pty::Pty;
use super::{options, text};
use triad::protocol::Mode;

/// `triad calib session --port PTY ARGS`, started (not awaited).
fn session(pty: &Pty, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_triad"))
        .args(["calib", "session", "--port", &pty.path])
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run triad calib session")
}

#[test]
fn a_port_nobody_answers_on_is_named_with_the_identify_that_went_unanswered() {
    let pty = Pty::open();
    let out = session(&pty, &[]).wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.starts_with("triad: no reply to identify (seq "),
        "{err}"
    );
    assert!(
        err.ends_with(&format!(
            " after 3 tries of 500 ms at 921600 baud on {}: is the device running triad firmware at this baud?\n",
            pty.path
        )),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn a_stream_that_stops_while_recording_is_an_error_and_nothing_is_uploaded() {
    let pty = Pty::open();
    let fake = FakeDevice::spawn(pty.master.try_clone().unwrap(), options());
    let child = session(&pty, &["--stall-s", "0.5"]);
    // The session switched the device to raw frames: then the device stops.
    let deadline = Instant::now() + Duration::from_secs(30);
    while !fake.applied().contains(&Applied::Mode(Mode::Raw)) {
        assert!(
            Instant::now() < deadline,
            "the session never asked for raw frames"
        );
    }
    let applied = fake.applied();
    drop(fake);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    let expected = format!(
        "triad: the stream stopped while recording the poses (nothing uploaded): no frame from {} for 0.5 s; \
         is the board still running and connected?\n",
        pty.path
    );
    assert!(err.ends_with(&expected), "{err}");
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    // Nothing but the mode reached the device.
    assert_eq!(applied, vec![Applied::Mode(Mode::Raw)]);
}
