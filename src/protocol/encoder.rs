//! Frame → bytes on the wire: serialise, stuff, delimit.

use super::cobs::{max_stuffed_len, stuff_short};
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
    const STUFFED_LEN: usize = FRAME_LEN + 1;
    const _: () = assert!(STUFFED_LEN + 1 == MAX_ENCODED_LEN);
    let (stuffed, delimiter) = out.split_at_mut(STUFFED_LEN);
    // Both halves have the lengths the constants say, so these always match;
    // the fallback keeps the function panic-free without an unwrap.
    match (
        <&mut [u8; STUFFED_LEN]>::try_from(stuffed),
        delimiter.first_mut(),
    ) {
        (Ok(stuffed), Some(end)) => {
            stuff_short(&frame.to_bytes(), stuffed);
            *end = DELIMITER;
            MAX_ENCODED_LEN
        }
        _ => 0,
    }
}

/// Highest frame rate a UART link of `baud` bits per second sustains with
/// 8N1 framing (10 bit times per byte: start, 8 data, stop), rounded down.
pub const fn max_frame_rate(baud: u32) -> u32 {
    baud / (10 * MAX_ENCODED_LEN as u32)
}
