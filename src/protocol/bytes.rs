//! Little-endian field writer and reader over a fixed buffer: no allocation,
//! no panic. A write past the end or a read past the end is remembered, not
//! a crash, and the caller turns it into an error.

/// Appends little-endian fields to a byte buffer.
pub struct Writer<'a> {
    buf: &'a mut [u8],
    len: usize,
    overflow: bool,
}

impl<'a> Writer<'a> {
    /// A writer at the start of `buf`.
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self {
            buf,
            len: 0,
            overflow: false,
        }
    }

    /// Appends `bytes`; when they do not fit nothing is written and the
    /// writer remembers the overflow.
    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        match self.buf.get_mut(self.len..self.len + bytes.len()) {
            Some(slot) => {
                slot.copy_from_slice(bytes);
                self.len += bytes.len();
            }
            None => self.overflow = true,
        }
        self
    }

    /// Appends one byte.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.bytes(&[v])
    }

    /// Appends a `u16`, little-endian.
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    /// Appends a `u32`, little-endian.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    /// Appends an `f32`, its IEEE 754 bits little-endian.
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    /// Appends a short string: one length byte, then its UTF-8 bytes
    /// (longer than 255 bytes is an overflow).
    pub fn str(&mut self, s: &str) -> &mut Self {
        match u8::try_from(s.len()) {
            Ok(n) => self.u8(n).bytes(s.as_bytes()),
            Err(_) => {
                self.overflow = true;
                self
            }
        }
    }

    /// Bytes written so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when nothing was written.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// True when some write did not fit.
    pub fn overflowed(&self) -> bool {
        self.overflow
    }
}

/// Reads little-endian fields from the front of a byte slice.
#[derive(Clone, Debug)]
pub struct Reader<'a> {
    rest: &'a [u8],
    short: bool,
}

impl<'a> Reader<'a> {
    /// A reader over `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Self {
            rest: bytes,
            short: false,
        }
    }

    /// The next `N` bytes; past the end, zeros, and the reader remembers it
    /// ran short.
    pub fn array<const N: usize>(&mut self) -> [u8; N] {
        match self.rest.split_first_chunk::<N>() {
            Some((head, tail)) => {
                self.rest = tail;
                *head
            }
            None => {
                self.short = true;
                self.rest = &[];
                [0; N]
            }
        }
    }

    /// The next byte.
    pub fn u8(&mut self) -> u8 {
        let [b] = self.array::<1>();
        b
    }

    /// The next `u16`.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.array())
    }

    /// The next `u32`.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.array())
    }

    /// The next `f32`.
    pub fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.array())
    }

    /// The next `n` bytes (fewer at the end, and the reader remembers it).
    pub fn slice(&mut self, n: usize) -> &'a [u8] {
        if n > self.rest.len() {
            self.short = true;
        }
        let (head, tail) = self.rest.split_at(n.min(self.rest.len()));
        self.rest = tail;
        head
    }

    /// A string written by [`Writer::str`]; invalid UTF-8 reads as "?".
    pub fn str(&mut self) -> &'a str {
        let n = usize::from(self.u8());
        core::str::from_utf8(self.slice(n)).unwrap_or("?")
    }

    /// Whatever is left.
    pub fn rest(&mut self) -> &'a [u8] {
        core::mem::take(&mut self.rest)
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.rest.len()
    }

    /// True when a read went past the end.
    pub fn ran_short(&self) -> bool {
        self.short
    }
}
