//! Consistent Overhead Byte Stuffing (COBS; Cheshire and Baker, "Consistent
//! Overhead Byte Stuffing", IEEE/ACM Trans. Networking 7(2), 1999).
//!
//! Stuffing removes every 0x00 from a frame so that 0x00 can mark frame
//! ends: a reader that starts anywhere, or loses bytes, is back in step at
//! the next 0x00. The data is cut at each zero into blocks; each block is
//! sent as a code byte (1 + the number of non-zero bytes that follow, at most
//! 0xFF) and those bytes. A block with code < 0xFF stands for its bytes
//! followed by a zero, except the last, whose zero is dropped; a block with
//! code 0xFF holds 254 bytes and no zero. The overhead is one byte per 254
//! bytes of data, at least one.

/// Why stuffing or unstuffing failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CobsError {
    /// The output buffer holds fewer than [`max_stuffed_len`] bytes.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes available.
        available: usize,
    },
    /// The bytes ended in the middle of a block (a code byte promised more
    /// bytes than arrived before the delimiter), or there were none.
    Truncated,
}

/// Worst-case stuffed length of `len` data bytes (without the delimiter).
pub const fn max_stuffed_len(len: usize) -> usize {
    len + len / 254 + 1
}

/// Stuffs `data` into `out` and returns the number of bytes written (no
/// delimiter is written). Fails only if `out` is shorter than
/// [`max_stuffed_len`]`(data.len())`.
pub fn stuff(data: &[u8], out: &mut [u8]) -> Result<usize, CobsError> {
    let needed = max_stuffed_len(data.len());
    if out.len() < needed {
        return Err(CobsError::BufferTooSmall {
            needed,
            available: out.len(),
        });
    }
    let too_small = CobsError::BufferTooSmall {
        needed,
        available: out.len(),
    };
    // `code_at` is where the current block's code byte goes once its length
    // is known; `next` is where the next data byte goes.
    let mut code_at = 0;
    let mut next = 1;
    let mut code: u8 = 1;
    for &byte in data {
        if byte == 0 {
            *out.get_mut(code_at).ok_or(too_small)? = code;
            code_at = next;
            next += 1;
            code = 1;
        } else {
            *out.get_mut(next).ok_or(too_small)? = byte;
            next += 1;
            code += 1;
            if code == 0xFF {
                *out.get_mut(code_at).ok_or(too_small)? = code;
                code_at = next;
                next += 1;
                code = 1;
            }
        }
    }
    *out.get_mut(code_at).ok_or(too_small)? = code;
    Ok(next)
}

/// [`stuff`] for a block of N < 254 bytes into exactly N + 1: no block can
/// reach the 254-byte run that needs a 0xFF code, so each byte is one copy
/// and one test for zero, with every index inside the arrays by their sizes
/// (no bounds checks, no error path). The frame encoder's form: the same
/// bytes as [`stuff`], a quarter of its instructions.
#[inline]
pub fn stuff_short<const N: usize, const M: usize>(data: &[u8; N], out: &mut [u8; M]) {
    const { assert!(N < 254 && M == N + 1) };
    // Indexed, not as [`stuff_exact`]: with both lengths known at build,
    // this form is 80 instructions shorter per 53-byte frame on the
    // emulated Cortex-M4F (the bench's `pipeline` row), the other shorter on
    // runtime lengths.
    let mut code_at = 0;
    for (i, &byte) in data.iter().enumerate() {
        out[i + 1] = byte;
        if byte == 0 {
            // The block since code_at holds i − code_at non-zero bytes.
            out[code_at] = (i + 1 - code_at) as u8;
            code_at = i + 1;
        }
    }
    out[code_at] = (N + 1 - code_at) as u8;
}

/// Stuffs `data` (under 254 bytes, so no run reaches a 0xFF code) into
/// `out`, exactly one byte longer: each byte one test for zero and one
/// store, the current block's code slot carried as a reference (no index
/// arithmetic, no bounds check per byte).
#[inline(always)]
fn stuff_exact(data: &[u8], out: &mut [u8]) {
    let Some((first, rest)) = out.split_first_mut() else {
        return;
    };
    // The current block's code byte, written once its length is known; a
    // zero's own slot becomes the next block's code byte.
    let mut code = first;
    let mut run: u8 = 1;
    for (slot, &byte) in rest.iter_mut().zip(data) {
        if byte == 0 {
            *code = run;
            code = slot;
            run = 1;
        } else {
            *slot = byte;
            run += 1;
        }
    }
    *code = run;
}

/// Longest block [`stuff_block`] takes: a 254-byte run would need a 0xFF code.
pub const MAX_BLOCK: usize = 253;

/// [`stuff`] for at most [`MAX_BLOCK`] bytes into `out` (N + 1 bytes): no
/// block reaches the 254-byte run that needs a 0xFF code, so each byte is
/// one copy and one test for zero, as in [`stuff_short`] (a word-at-a-time
/// form and a run-by-run copy were both measured no faster on the emulated
/// Cortex-M4F: the stream's counts hold many zero bytes). The length is
/// runtime: the packets of protocol v2 (at most 240 bytes) use it.
/// Fails only when `data` is longer than [`MAX_BLOCK`] or `out` shorter
/// than `data.len() + 1`.
#[inline]
pub fn stuff_block(data: &[u8], out: &mut [u8]) -> Result<usize, CobsError> {
    let needed = data.len() + 1;
    if data.len() > MAX_BLOCK || out.len() < needed {
        return Err(CobsError::BufferTooSmall {
            needed: max_stuffed_len(data.len()),
            available: out.len(),
        });
    }
    stuff_exact(data, &mut out[..needed]);
    Ok(needed)
}

/// Stuffs a block in place: `frame[1..frame.len() - 1]` holds the data (at
/// most [`MAX_BLOCK`] bytes), already where the stuffed bytes go, since
/// stuffing a block that short leaves every non-zero byte one place on
/// and only writes codes: `frame[0]` and each zero. Writes those codes and
/// the 0x00 delimiter at the end, and returns `frame.len()`. An encoder
/// that writes its packet at `frame[1..]` so stuffs it without a copy.
/// Fails when the data is longer than [`MAX_BLOCK`] or `frame` shorter than
/// two bytes.
pub fn stuff_in_place(frame: &mut [u8]) -> Result<usize, CobsError> {
    let n = frame.len();
    let data = n.wrapping_sub(2);
    if n < 2 || data > MAX_BLOCK {
        return Err(CobsError::BufferTooSmall {
            needed: max_stuffed_len(data.min(MAX_BLOCK + 1)) + 1,
            available: n,
        });
    }
    let end = n - 1;
    let mut stuffer = InPlaceStuffer::new();
    let mut at = 1;
    // `at + 4 <= end < n`: the word is inside `frame` (no bounds check left).
    while at + 4 <= end {
        let Some(&[b0, b1, b2, b3]) = frame.get(at..at + 4) else {
            break;
        };
        stuffer.word(frame, at, u32::from_le_bytes([b0, b1, b2, b3]));
        at += 4;
    }
    while at < end {
        stuffer.byte(frame, at);
        at += 1;
    }
    stuffer.finish(frame, end);
    Ok(n)
}

/// [`stuff_in_place`] fed piece by piece, so that another pass over the
/// same bytes (the packet's CRC) can share its loads: the caller reads the
/// block's bytes in order, from `frame[1]`, a word ([`Self::word`]) or a
/// byte ([`Self::byte`]) at a time, and ends at the delimiter's place
/// ([`Self::finish`]). Zeros are found four bytes at a time (an exact mask
/// of the zero bytes in a word, then each by its bit), and no byte is
/// copied: a word without a zero costs its test alone.
#[derive(Clone, Copy, Debug, Default)]
pub struct InPlaceStuffer {
    /// The current block's code slot; each zero found becomes the next one.
    code_at: usize,
}

impl InPlaceStuffer {
    /// At the block's start: the first code goes to `frame[0]`.
    pub const fn new() -> Self {
        Self { code_at: 0 }
    }

    /// `word` is `frame[at..at + 4]`, little-endian: closes a block at each
    /// of its zero bytes.
    #[inline(always)]
    pub fn word(&mut self, frame: &mut [u8], at: usize, word: u32) {
        // 0x80 in each zero byte exactly: the low seven bits plus 0x7F
        // carry into bit 7 unless they are all zero, and bit 7 itself is
        // taken from the byte.
        let mut zeros = !(((word & 0x7F7F_7F7F).wrapping_add(0x7F7F_7F7F)) | word | 0x7F7F_7F7F);
        while zeros != 0 {
            self.close(frame, at + (zeros.trailing_zeros() / 8) as usize);
            zeros &= zeros - 1;
        }
    }

    /// Closes a block at `frame[at]` if it is zero.
    #[inline(always)]
    pub fn byte(&mut self, frame: &mut [u8], at: usize) {
        if frame.get(at) == Some(&0) {
            self.close(frame, at);
        }
    }

    /// Writes the last code and the delimiter at `frame[end]`, the place
    /// after the data.
    #[inline(always)]
    pub fn finish(mut self, frame: &mut [u8], end: usize) {
        self.close(frame, end);
        if let Some(delimiter) = frame.get_mut(end) {
            *delimiter = 0;
        }
    }

    /// The block ends at `zero_at`: its code is its length, and the zero's
    /// place is the next block's code.
    #[inline(always)]
    fn close(&mut self, frame: &mut [u8], zero_at: usize) {
        if let Some(code) = frame.get_mut(self.code_at) {
            // A block holds at most MAX_BLOCK bytes: the code fits a byte.
            *code = (zero_at - self.code_at) as u8;
        }
        self.code_at = zero_at;
    }
}

/// Undoes stuffing one byte at a time, with no buffer of its own: the caller
/// feeds each non-zero byte to [`Unstuffer::push`], stores what it returns,
/// and calls [`Unstuffer::finish`] at the 0x00 delimiter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unstuffer {
    /// Data bytes still expected in the current block.
    remaining: u8,
    /// Whether the current block ends with an implied zero (code < 0xFF),
    /// released only when a further block shows it was not the last.
    zero_after: bool,
    /// Whether a code byte has been seen since the last delimiter.
    started: bool,
}

impl Unstuffer {
    /// A fresh unstuffer, expecting a code byte.
    pub const fn new() -> Unstuffer {
        Unstuffer {
            remaining: 0,
            zero_after: false,
            started: false,
        }
    }

    /// Takes one byte of a stuffed frame (never the 0x00 delimiter: a zero
    /// here is treated as a code byte of an empty block) and returns the data
    /// byte it releases, if any.
    pub fn push(&mut self, byte: u8) -> Option<u8> {
        if self.remaining == 0 {
            let released = if self.started && self.zero_after {
                Some(0)
            } else {
                None
            };
            self.started = true;
            self.remaining = byte.saturating_sub(1);
            self.zero_after = byte != 0xFF;
            released
        } else {
            self.remaining -= 1;
            Some(byte)
        }
    }

    /// Ends the frame at its delimiter and resets for the next one. Ok when
    /// the last block was complete.
    pub fn finish(&mut self) -> Result<(), CobsError> {
        let complete = self.started && self.remaining == 0;
        *self = Unstuffer::new();
        if complete {
            Ok(())
        } else {
            Err(CobsError::Truncated)
        }
    }
}
