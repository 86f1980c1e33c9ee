//! The bounds of ULog messages that px4-ulog 0.6.1 indexes without
//! checking, checked on the bytes before the parser sees them: its
//! `LogParser` slices a parameter message ('P') at `1 + key_len` without
//! comparing that with the message's size (file_reader.rs:419, "range
//! start index … out of range") and reads a subscription message ('A') as
//! at least 3 bytes (multi id, message id) without checking it has them.
//! Every other message kind it reads, it checks. And what flattening the
//! formats will cost it ([`Formats`]) is worked out from the format
//! messages before the data section starts. The walk follows the
//! parser's own framing: a 16-byte file header, then messages of a 3-byte
//! head (size: u16 little-endian, type: one byte) and `size` bytes.

use super::ulog_formats::Formats;

/// The file header's length, before the first message.
const FILE_HEADER: u64 = 16;

/// A message's head: its size (u16 little-endian) and type.
const HEAD: usize = 3;

/// A message that would take the parser past its end, or past what triad
/// lets it spend.
#[derive(Debug, PartialEq, Eq)]
pub struct OutOfBounds {
    /// The message's first byte in the file.
    pub offset: u64,
    /// What is out of bounds.
    pub reason: String,
}

/// The walk over a ULog's bytes, fed as they are read.
pub struct Bounds {
    /// Bytes fed so far.
    fed: u64,
    /// Where the next message starts.
    next: u64,
    /// The next message's head, as far as seen.
    head: Vec<u8>,
    /// The part of its body the checks read, as far as seen.
    body: Vec<u8>,
    /// The formats, for what flattening them costs.
    formats: Formats,
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds {
            fed: 0,
            next: FILE_HEADER,
            head: Vec::with_capacity(HEAD),
            body: Vec::new(),
            formats: Formats::default(),
        }
    }
}

impl Bounds {
    /// Checks every message that `bytes` (the file's next bytes, after
    /// those fed before) complete.
    pub fn feed(&mut self, bytes: &[u8]) -> Result<(), OutOfBounds> {
        let end = self.fed + bytes.len() as u64;
        while self.next < end {
            // What is seen of a message is kept from one feed to the next,
            // so its unseen bytes start in `bytes`.
            let from = self.next + (self.head.len() + self.body.len()) as u64;
            let mut rest = &bytes[(from.saturating_sub(self.fed) as usize).min(bytes.len())..];
            take(&mut self.head, HEAD, &mut rest);
            let &[lo, hi, kind] = self.head.as_slice() else {
                break;
            };
            let size = u16::from_le_bytes([lo, hi]);
            take(&mut self.body, read_of(kind, size), &mut rest);
            if self.body.len() < read_of(kind, size) {
                break;
            }
            self.message(kind, size).map_err(|reason| OutOfBounds {
                offset: self.next,
                reason,
            })?;
            self.next += (HEAD + usize::from(size)) as u64;
            self.head.clear();
            self.body.clear();
        }
        self.fed = end;
        Ok(())
    }

    /// The work flattening the formats takes, as counted so far.
    pub fn work(&self) -> u64 {
        self.formats.work()
    }

    /// Checks a message of type `kind`, `size` bytes after its head (its
    /// body, as far as read, in `self.body`): the reason it is refused.
    fn message(&mut self, kind: u8, size: u16) -> Result<(), String> {
        match kind {
            b'P' => match self.body.first() {
                None => Err("a parameter message ('P') has no bytes, not even its key length".into()),
                Some(&key) if 1 + usize::from(key) > usize::from(size) => Err(format!(
                    "a parameter message ('P') of {size} bytes has a key length of {key}, more than the {} bytes after it",
                    size - 1
                )),
                Some(_) => Ok(()),
            },
            b'A' if size < 3 => Err(format!(
                "a subscription message ('A') has {size} bytes, fewer than the 3 of its multi id and message id"
            )),
            b'A' => self.formats.subscription(&self.body),
            b'F' => {
                self.formats.format(&self.body);
                Ok(())
            }
            // The messages on which the crate starts its data section.
            b'L' | b'O' | b'S' | b'R' | b'C' => self.formats.flatten(),
            _ => Ok(()),
        }
    }
}

/// How many bytes of a message's body the checks read.
fn read_of(kind: u8, size: u16) -> usize {
    match kind {
        b'F' | b'A' => usize::from(size),
        b'P' => usize::from(size).min(1),
        _ => 0,
    }
}

/// Moves bytes from the front of `rest` to `into` until it holds `want`.
fn take(into: &mut Vec<u8>, want: usize, rest: &mut &[u8]) {
    let n = want.saturating_sub(into.len()).min(rest.len());
    into.extend_from_slice(&rest[..n]);
    *rest = &rest[n..];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::ulog_formats::MAX_WORK;

    /// A ULog's bytes: the file header, then `messages` (type, body).
    fn ulog(messages: &[(u8, &[u8])]) -> Vec<u8> {
        let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
        bytes.extend_from_slice(&[0; 8]);
        for (kind, body) in messages {
            bytes.extend_from_slice(&(body.len() as u16).to_le_bytes());
            bytes.push(*kind);
            bytes.extend_from_slice(body);
        }
        bytes
    }

    /// `bytes` fed in pieces of `piece` bytes: the first out-of-bounds message.
    fn walk(bytes: &[u8], piece: usize) -> Result<(), OutOfBounds> {
        let mut bounds = Bounds::default();
        bytes.chunks(piece).try_for_each(|c| bounds.feed(c))
    }

    /// A well-formed parameter: "int32_t X" and its 4-byte value.
    const PARAMETER: &[u8] = b"\x09int32_t X\x01\x00\x00\x00";

    #[test]
    fn messages_in_bounds_pass_however_the_file_is_cut_into_reads() {
        let bytes = ulog(&[
            (b'I', b"\x0cchar[3] nameabc"),
            (b'P', PARAMETER),
            (b'A', b"\x00\x01\x00m"),
            (b'P', b"\x00"),
            (b'O', b""),
            (b'P', PARAMETER),
        ]);
        for piece in 1..=bytes.len() {
            assert_eq!(walk(&bytes, piece), Ok(()), "pieces of {piece}");
        }
    }

    #[test]
    fn a_parameter_key_past_the_message_end_is_refused_at_the_message_offset() {
        let mut long_key = PARAMETER.to_vec();
        long_key[0] = 98;
        let bytes = ulog(&[(b'I', b"\x00"), (b'P', &long_key)]);
        for piece in 1..=bytes.len() {
            let e = walk(&bytes, piece).unwrap_err();
            assert_eq!(e.offset, 16 + 4, "pieces of {piece}");
            assert!(
                e.reason
                    .contains("has a key length of 98, more than the 13 bytes"),
                "{}",
                e.reason
            );
        }
    }

    #[test]
    fn an_empty_parameter_and_a_short_subscription_are_refused() {
        let e = walk(&ulog(&[(b'P', b"")]), 7).unwrap_err();
        assert_eq!((e.offset, e.reason.contains("no bytes")), (16, true));
        let e = walk(&ulog(&[(b'B', &[0; 40]), (b'A', b"\x00\x01")]), 5).unwrap_err();
        assert_eq!(e.offset, 16 + 43);
        assert!(e.reason.contains("'A') has 2 bytes"), "{}", e.reason);
    }

    #[test]
    fn a_real_px4_log_passes_with_its_flattening_a_small_part_of_the_limit() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/recordings/px4_sample_log_small.ulg"
        );
        let bytes = std::fs::read(path).unwrap();
        let mut bounds = Bounds::default();
        for piece in bytes.chunks(1 << 16) {
            bounds.feed(piece).unwrap();
        }
        assert!(
            bounds.work() > 0 && bounds.work() < MAX_WORK / 100,
            "{}",
            bounds.work()
        );
    }
}
