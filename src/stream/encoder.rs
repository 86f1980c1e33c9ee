//! Frame → bytes on the wire: serialise, stuff, delimit.

use super::cobs::{max_stuffed_len, stuff};
use super::frame::{Frame, FRAME_LEN};

/// Bytes on the wire of one encoded frame, delimiter included. A frame is
/// shorter than 254 bytes, so stuffing always adds exactly one byte: every
/// frame is exactly this long.
pub const MAX_ENCODED_LEN: usize = max_stuffed_len(FRAME_LEN) + 1;

/// The frame delimiter.
pub const DELIMITER: u8 = 0x00;

/// Encodes `frame` into `out` (stuffed bytes, then the 0x00 delimiter) and
/// returns the number of bytes written, which is always
/// [`MAX_ENCODED_LEN`].
pub fn encode(frame: &Frame, out: &mut [u8; MAX_ENCODED_LEN]) -> usize {
    let raw = frame.to_bytes();
    // `out` holds max_stuffed_len(FRAME_LEN) + 1 bytes by the definition of
    // MAX_ENCODED_LEN, so neither branch returning 0 is ever taken; they keep
    // the function panic-free without an unwrap.
    match stuff(&raw, out) {
        Ok(stuffed) => match out.get_mut(stuffed) {
            Some(end) => {
                *end = DELIMITER;
                stuffed + 1
            }
            None => 0,
        },
        Err(_) => 0,
    }
}

/// Highest frame rate a UART link of `baud` bits per second sustains with
/// 8N1 framing (10 bit times per byte: start, 8 data, stop), rounded down.
pub const fn max_frame_rate(baud: u32) -> u32 {
    baud / (10 * MAX_ENCODED_LEN as u32)
}
