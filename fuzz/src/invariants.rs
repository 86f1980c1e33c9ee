//! The invariants the targets check after each input, one function each,
//! so that AFL's binaries, the mutation run and the tests check the same
//! things. Each returns `Err(Broken)` with what it saw when it does not hold.

use std::fmt;

use triad::model::blob::BLOB_LEN;
use triad::protocol::{CalibrationSource, DecoderStats, Reply, Status, StoredState};

/// An invariant that did not hold: what it says, and what was seen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Broken(pub String);

impl fmt::Display for Broken {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

fn holds(ok: bool, what: impl FnOnce() -> String) -> Result<(), Broken> {
    if ok {
        Ok(())
    } else {
        Err(Broken(what()))
    }
}

/// The stream decoder's byte accounting: every byte fed is counted, and is
/// a good packet's, skipped, or pending (a packet not yet delimited).
pub fn byte_accounting_balances(
    stats: &DecoderStats,
    fed: u64,
    pending: u64,
) -> Result<(), Broken> {
    holds(
        stats.bytes == fed && stats.bytes == stats.packet_bytes + stats.bytes_skipped + pending,
        || format!("{fed} bytes fed, {pending} pending, but the decoder counts {stats:?}"),
    )
}

/// Every good packet the decoder gave is counted once, under its kind.
pub fn good_packets_counted_once(stats: &DecoderStats, given: u64) -> Result<(), Broken> {
    let counted = stats.frames + stats.raw_frames + stats.batch_frames + stats.messages;
    holds(counted == given, || {
        format!("{given} good packets given, {counted} counted: {stats:?}")
    })
}

/// Every damaged packet the decoder reported is counted once, as a CRC
/// error or as malformed.
pub fn errors_counted_once(stats: &DecoderStats, reported: u64) -> Result<(), Broken> {
    let counted = stats.crc_errors + stats.malformed;
    holds(counted == reported, || {
        format!("{reported} damaged packets reported, {counted} counted: {stats:?}")
    })
}

/// The device answers at most once per packet (each ends at a delimiter).
pub fn one_reply_per_packet(replies: u32, delimiters: u32) -> Result<(), Broken> {
    holds(replies <= delimiters, || {
        format!("{replies} replies to {delimiters} delimited packets")
    })
}

/// What a command may change on the device: the calibration in force, what
/// the store holds, and the flash (its writes and erases so far).
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceState {
    /// The calibration in force: its blob (`None`: the identity), id and source.
    pub active: (Option<[u8; BLOB_LEN]>, u32, CalibrationSource),
    /// What the store holds, as `identify` says.
    pub stored: StoredState,
    /// Writes and erases of the flash so far.
    pub flash_ops: (u32, u32),
}

/// A refused command (an upload's chunk, its commit, a save, ...) changes
/// nothing: the calibration in force, the store and the flash are as before.
pub fn refused_changes_nothing(
    reply: &Reply,
    before: &DeviceState,
    after: &DeviceState,
) -> Result<(), Broken> {
    holds(reply.status == Status::Ok || before == after, || {
        format!("the refused {reply:?} changed the device from {before:?} to {after:?}")
    })
}

/// The counters `identify` reports add up: commands = the replies since
/// the last reset of the counters (the reset's own reply, and the identify
/// asking, included), command errors = the refusals among them.
pub fn counters_add_up(
    commands: u32,
    command_errors: u32,
    replies_since_reset: u32,
    errors_since_reset: u32,
) -> Result<(), Broken> {
    holds(
        commands == replies_since_reset + 1 && command_errors == errors_since_reset,
        || {
            format!(
                "{replies_since_reset} replies and {errors_since_reset} refusals since the \
                 counters' reset, but identify says {commands} commands and {command_errors} \
                 errors"
            )
        },
    )
}

/// What decoded encodes to bytes that decode to the same: `first` are the
/// bytes encoded from what was decoded, `second` those encoded from their
/// decoding in turn (bytes, not values: a NaN is not equal to itself).
pub fn reencodes_to_itself(what: &str, first: &[u8], second: &[u8]) -> Result<(), Broken> {
    holds(first == second, || {
        format!("a {what} re-encodes to {first:02x?}, then to {second:02x?}")
    })
}

/// The three COBS stuffers give the same bytes for a block they all take.
pub fn stuffers_agree(data: &[u8], stuffed: &[&[u8]]) -> Result<(), Broken> {
    holds(stuffed.windows(2).all(|w| w[0] == w[1]), || {
        format!("{data:02x?} stuffs differently: {stuffed:02x?}")
    })
}

/// Stuffed bytes hold no 0x00 (the delimiter), are at most
/// `max_stuffed_len` long, and unstuff to the data.
pub fn stuffing_undoes(
    data: &[u8],
    stuffed: &[u8],
    max_len: usize,
    unstuffed: Option<&[u8]>,
) -> Result<(), Broken> {
    holds(
        !stuffed.contains(&0) && stuffed.len() <= max_len && unstuffed == Some(data),
        || format!("{data:02x?} stuffs to {stuffed:02x?}, which unstuffs to {unstuffed:02x?}"),
    )
}

/// An error names its cause: a refusal with an empty message is a broken
/// promise to the user.
pub fn error_has_message(message: &str) -> Result<(), Broken> {
    holds(!message.trim().is_empty(), || {
        "an error without a message".to_string()
    })
}

/// A recording reader's chunk holds samples (an empty one would end a
/// reading loop before the file's end).
pub fn chunk_has_samples(len: usize) -> Result<(), Broken> {
    holds(len > 0, || "a reader gave an empty chunk".to_string())
}

/// A sample's time is a number: the readers refuse what is not.
pub fn sample_time_finite(t: f64) -> Result<(), Broken> {
    holds(t.is_finite(), || format!("a sample at t = {t} passed"))
}

/// The samples' places in the file (line or message) increase.
pub fn places_increase(at: u64, last: u64) -> Result<(), Broken> {
    holds(at > last, || format!("places go back: {at} after {last}"))
}

/// A reading library that panicked on the file: refused, but through a
/// panic (`message` is the refusal's, with its causes).
pub fn no_library_panic(message: &str) -> Result<(), Broken> {
    holds(
        !message.contains(triad_host::record::producer::LIBRARY_FAILED),
        || format!("a reader's library panicked: {message}"),
    )
}

/// A refusal names the file it refused.
pub fn error_names_file(message: &str, file: &str) -> Result<(), Broken> {
    holds(message.contains(file), || {
        format!("an error without the file's name ({file}): {message}")
    })
}
