//! The host's end of the command link (docs/PROTOCOL.md, version 2): send a
//! command, wait for the reply that names its sequence number, skipping the
//! frames the device streams meanwhile; send it again, same number and
//! bytes, when no reply comes in time (the device answers a retry from its
//! last reply without applying the command twice).
//!
//! Generic over `Read + Write`, so a test drives it over an in-memory pipe
//! as `triad device` does over a serial port. The port's reads are expected
//! to give up after a short poll (a timeout or `WouldBlock` error, as a
//! serial port opened by [`crate::plumbing::serial::open`] does), so that a deadline
//! is kept.

use std::io::{self, ErrorKind, Read, Write};
use std::thread;
use std::time::{Duration, Instant};

use triad::protocol::command::name_of;
use triad::protocol::{Command, Packet, Reply, Status, MAX_WIRE_LEN};
use triad::protocol::{DecodeError, Decoder, DecoderStats, DELIMITER};

/// How long to wait and how often to try.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// How long one try waits for its reply.
    pub timeout: Duration,
    /// Tries per command (the first included), each with the same sequence
    /// number and bytes.
    pub tries: u32,
}

impl Default for Settings {
    /// 500 ms, 3 tries: a reply takes a few ms at 115200 baud and above.
    fn default() -> Self {
        Settings {
            timeout: Duration::from_millis(500),
            tries: 3,
        }
    }
}

/// A device that answers "busy" is asked again, with a new sequence number,
/// after this pause (the sampling task takes a change within a sample).
const BUSY_PAUSE: Duration = Duration::from_millis(20);

/// The least a try of `command` waits, whatever `--timeout-ms` says: a
/// save or an erase stalls a NUCLEO while its flash erases a 128 KiB sector
/// (up to 2 s each, one sector per save, two per erase:
/// boards/nucleo-f401re/README.md), and a retry sent into that stall only
/// queues behind it.
fn least_wait(command: &Command) -> Duration {
    match command {
        Command::Save => Duration::from_secs(3),
        Command::Erase => Duration::from_secs(5),
        _ => Duration::ZERO,
    }
}

/// Why a command did not get its answer.
#[derive(Debug)]
pub enum LinkError {
    /// No reply with the command's sequence number in any try.
    NoReply {
        /// The command's name.
        command: &'static str,
        /// Its sequence number.
        sequence: u16,
        /// Tries made.
        tries: u32,
        /// How long each waited.
        timeout: Duration,
        /// Where (`at 921600 baud on /dev/ttyACM0`).
        place: String,
    },
    /// The device answered with an error status.
    Refused {
        /// The command's name.
        command: &'static str,
        /// The status.
        status: Status,
        /// The device's reason.
        reason: String,
    },
    /// The reply with the command's sequence number answers another command.
    WrongCommand {
        /// The sequence number.
        sequence: u16,
        /// The command sent.
        sent: &'static str,
        /// The code the reply names.
        answered: u8,
    },
    /// A reply whose result cannot be read.
    BadResult {
        /// The command's name.
        command: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The port closed (the device unplugged, the pty's other end gone).
    Closed {
        /// Where.
        place: String,
        /// The system's reason.
        reason: String,
    },
    /// Reading or writing the port failed.
    Io {
        /// Where.
        place: String,
        /// The error.
        error: io::Error,
    },
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinkError::NoReply {
                command,
                sequence,
                tries,
                timeout,
                place,
            } => write!(
                f,
                "no reply to {command} (seq {sequence}) after {tries} {} of {} ms {place}: \
                 is the device running triad firmware at this baud?",
                if *tries == 1 { "try" } else { "tries" },
                timeout.as_millis()
            ),
            LinkError::Refused {
                command,
                status,
                reason,
            } => write!(f, "{command}: the device answered {status}: {reason}"),
            LinkError::WrongCommand {
                sequence,
                sent,
                answered,
            } => write!(
                f,
                "the reply to {sent} (seq {sequence}) answers {} (code {answered:#04x}): \
                 another program may be talking to the device",
                name_of(*answered)
            ),
            LinkError::BadResult { command, reason } => {
                write!(f, "the reply to {command} cannot be read: {reason}")
            }
            LinkError::Closed { place, reason } => {
                write!(f, "the port closed {place} ({reason})")
            }
            LinkError::Io { place, error } => write!(f, "the port failed {place}: {error}"),
        }
    }
}

impl std::error::Error for LinkError {}

/// Bytes read from the port at a time.
const READ_LEN: usize = 4096;

/// One end of a link to a device.
pub struct Link<P> {
    port: P,
    decoder: Decoder,
    buffer: Box<[u8; READ_LEN]>,
    /// `buffer[next..end]` is read but not decoded yet.
    next: usize,
    end: usize,
    next_sequence: u16,
    settings: Settings,
    place: String,
    /// True once a delimiter went out before a command.
    in_step: bool,
}

impl<P: Read + Write> Link<P> {
    /// A link over `port`; `place` says where in messages (`at 921600 baud
    /// on /dev/ttyACM0`); commands are numbered from `first_sequence`.
    pub fn new(port: P, settings: Settings, place: String, first_sequence: u16) -> Self {
        Self {
            port,
            decoder: Decoder::new(),
            buffer: Box::new([0; READ_LEN]),
            next: 0,
            end: 0,
            next_sequence: first_sequence,
            settings,
            place,
            in_step: false,
        }
    }

    /// Where the link goes, as messages say it.
    pub fn place(&self) -> &str {
        &self.place
    }

    /// What the link's decoder has counted (frames, replies, errors).
    pub fn stats(&self) -> &DecoderStats {
        self.decoder.stats()
    }

    /// Bytes of a packet received in part.
    pub fn pending_bytes(&self) -> u64 {
        self.decoder.pending_bytes()
    }

    /// True when bytes already read wait to be decoded.
    pub fn buffered(&self) -> bool {
        self.next < self.end
    }

    /// Sends `command` and returns its reply, which has status ok; a
    /// device that is busy is asked again (a new sequence number) up to the
    /// tries of the settings; any other status is [`LinkError::Refused`].
    pub fn command(&mut self, command: &Command) -> Result<Reply, LinkError> {
        let mut busy = 0;
        let timeout = self.settings.timeout.max(least_wait(command));
        loop {
            let reply = self.exchange(command, timeout)?;
            match reply.status {
                Status::Ok => return Ok(reply),
                Status::Busy if busy + 1 < self.settings.tries => {
                    busy += 1;
                    thread::sleep(BUSY_PAUSE);
                }
                status => {
                    return Err(LinkError::Refused {
                        command: command.name(),
                        status,
                        reason: reply.reason().to_string(),
                    })
                }
            }
        }
    }

    /// Sends `command` under the next sequence number and returns its
    /// reply, whatever its status; each try waits `timeout`.
    pub fn exchange(&mut self, command: &Command, timeout: Duration) -> Result<Reply, LinkError> {
        let sequence = self.next_sequence;
        self.next_sequence = sequence.wrapping_add(1);
        let packet = command
            .to_packet(sequence)
            .map_err(|_| LinkError::BadResult {
                command: command.name(),
                reason: "the command does not fit in a packet".into(),
            })?;
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = packet.to_wire(&mut wire);
        let mut bytes = Vec::with_capacity(n + 1);
        // A delimiter before the first command (and its retries): whatever
        // the device's decoder holds (noise, a command cut by an earlier
        // program) ends there, so the command is read from its first byte.
        if !self.in_step {
            bytes.push(DELIMITER);
        }
        bytes.extend_from_slice(&wire[..n]);
        for _ in 0..self.settings.tries {
            self.send(&bytes)?;
            self.in_step = true;
            let deadline = Instant::now() + timeout;
            while let Some(decoded) = self.next_packet(deadline)? {
                match decoded {
                    Ok(Packet::Reply(reply)) if reply.sequence == sequence => {
                        if reply.command != command.code() {
                            return Err(LinkError::WrongCommand {
                                sequence,
                                sent: command.name(),
                                answered: reply.command,
                            });
                        }
                        return Ok(reply);
                    }
                    // Frames streamed meanwhile, a late copy of an earlier
                    // reply, damage: not this command's answer.
                    _ => {}
                }
            }
        }
        Err(LinkError::NoReply {
            command: command.name(),
            sequence,
            tries: self.settings.tries,
            timeout,
            place: self.place.clone(),
        })
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.port
            .write_all(bytes)
            .and_then(|()| self.port.flush())
            .map_err(|e| self.port_error(e))
    }

    /// The next packet or rejected frame the port brings before `deadline`;
    /// `None` when the deadline passes first.
    pub fn next_packet(
        &mut self,
        deadline: Instant,
    ) -> Result<Option<Result<Packet, DecodeError>>, LinkError> {
        loop {
            while self.next < self.end {
                let byte = self.buffer[self.next];
                self.next += 1;
                if let Some(decoded) = self.decoder.push(byte) {
                    return Ok(Some(decoded));
                }
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            match self.port.read(&mut self.buffer[..]) {
                Ok(0) => {
                    return Err(LinkError::Closed {
                        place: self.place.clone(),
                        reason: "end of file".into(),
                    })
                }
                Ok(n) => (self.next, self.end) = (0, n),
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Err(self.port_error(e)),
            }
        }
    }

    fn port_error(&self, error: io::Error) -> LinkError {
        if crate::plumbing::serial::is_port_gone(&error) {
            LinkError::Closed {
                place: self.place.clone(),
                reason: error.to_string(),
            }
        } else {
            LinkError::Io {
                place: self.place.clone(),
                error,
            }
        }
    }
}
