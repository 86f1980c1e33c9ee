//! An in-memory duplex byte pipe: two ends, each reading what the other
//! writes. The host's end reads as a serial port does (waits up to a poll
//! period, then a `TimedOut` error); the device's end never waits
//! (`WouldBlock`), as the fake device polls it between samples.

use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// Bytes in flight one way.
#[derive(Default)]
struct Lane {
    bytes: Mutex<VecDeque<u8>>,
    arrived: Condvar,
}

/// One end of the pipe.
pub struct End {
    incoming: Arc<Lane>,
    outgoing: Arc<Lane>,
    /// How long a read waits for bytes (zero: not at all).
    wait: Duration,
}

/// The two ends: (host, device).
pub fn pair(host_poll: Duration) -> (End, End) {
    let (a, b) = (Arc::new(Lane::default()), Arc::new(Lane::default()));
    let host = End {
        incoming: Arc::clone(&a),
        outgoing: Arc::clone(&b),
        wait: host_poll,
    };
    let device = End {
        incoming: b,
        outgoing: a,
        wait: Duration::ZERO,
    };
    (host, device)
}

impl Read for End {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let mut bytes = self.incoming.bytes.lock().unwrap();
        if bytes.is_empty() && !self.wait.is_zero() {
            bytes = self
                .incoming
                .arrived
                .wait_timeout(bytes, self.wait)
                .unwrap()
                .0;
        }
        if bytes.is_empty() {
            let kind = if self.wait.is_zero() {
                ErrorKind::WouldBlock
            } else {
                ErrorKind::TimedOut
            };
            return Err(kind.into());
        }
        let n = buf.len().min(bytes.len());
        for (slot, byte) in buf.iter_mut().zip(bytes.drain(..n)) {
            *slot = byte;
        }
        Ok(n)
    }
}

impl Write for End {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.outgoing.bytes.lock().unwrap().extend(buf);
        self.outgoing.arrived.notify_all();
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
