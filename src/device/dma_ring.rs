//! The reader's side of a ring that a DMA stream fills in circles, as pure
//! arithmetic: how far the stream has written since it was last looked at,
//! and whether it has lapped the reader. A board's receiver (the NUCLEO's
//! `serial_rx.rs`) feeds it the stream's registers: NDTR's position and the
//! half-transfer and transfer-complete flags. Tested on the host against a
//! model of the DMA (tests/device_dma_ring.rs).
//!
//! Its position alone (from NDTR) says where the stream is, not how many
//! times it went round. The stream also raises two flags: half transfer (HTIF)
//! on reaching the middle of the ring, position `LEN / 2`, and transfer
//! complete (TCIF) on reaching its end, position `LEN` ≡ 0. Cleared at each
//! look, they say which of these two boundaries it reached since the last one.
//! Moving `steps < LEN` positions forward, the stream reaches exactly the
//! boundaries on that arc; a whole lap or more reaches both. So:
//!
//! - flags equal to the arc's boundaries, not both: it moved exactly `steps`;
//! - flags not equal to the arc's: it went round at least once (lapped);
//! - an arc holding both boundaries, flags both: `steps` or `steps + LEN` or
//!   more, which cannot be told apart; taken as lapped.
//!
//! An arc holds both boundaries only if it is longer than `LEN / 2`, so up to
//! `LEN / 2` bytes between two looks are always counted exactly; from `LEN`
//! on, the loss is always reported; in between it may be reported though
//! nothing was lost.

/// The ring's two boundaries the stream reached: its middle (`half`, HTIF)
/// and its end (`end`, TCIF).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Boundaries {
    /// Position `LEN / 2` was reached.
    pub half: bool,
    /// Position `LEN` ≡ 0 was reached (the stream wrapped).
    pub end: bool,
}

impl Boundaries {
    /// The boundaries a stream reaches moving `steps` positions forward from
    /// `from` in a ring of `len` positions (`len` even, `from < len`).
    pub fn on_arc(len: usize, from: usize, steps: usize) -> Self {
        // Boundary `b` is reached at step (b − from) mod len. Step 0 means the
        // stream is on it already: it reaches it again only a lap later.
        let reached = |boundary: usize| {
            let at_step = (boundary + len - from) % len;
            at_step != 0 && at_step <= steps
        };
        Self {
            half: reached(len / 2),
            end: reached(0),
        }
    }

    /// Either's boundaries.
    pub fn union(self, other: Self) -> Self {
        Self {
            half: self.half || other.half,
            end: self.end || other.end,
        }
    }

    fn both(self) -> bool {
        self.half && self.end
    }
}

/// How far the stream moved from position `last` to `now` in a ring of `len`
/// positions, having reached `reached` in between: `None` when it may have
/// gone round the whole ring (see the module's comment).
pub fn advance(len: usize, last: usize, now: usize, reached: Boundaries) -> Option<usize> {
    let steps = (now + len - last) % len;
    let arc = Boundaries::on_arc(len, last, steps);
    (reached == arc && !arc.both()).then_some(steps)
}

/// Bytes were lost: the stream overwrote some before they were read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lapped;

/// Which bytes of a `LEN`-byte ring are written and not yet read, the stream
/// having started at position 0 with its flags clear.
#[derive(Debug)]
pub struct RingReader<const LEN: usize> {
    /// The stream's position at the last [`RingReader::sync`].
    stream_at: usize,
    /// The next byte to read.
    read_at: usize,
    /// Bytes written and not yet read.
    unread: usize,
}

impl<const LEN: usize> RingReader<LEN> {
    /// The two boundaries must be distinct positions.
    const EVEN: () = assert!(
        LEN >= 2 && LEN.is_multiple_of(2),
        "the ring's length must be even"
    );

    /// An empty ring, the stream at position 0.
    pub const fn new() -> Self {
        let () = Self::EVEN;
        Self {
            stream_at: 0,
            read_at: 0,
            unread: 0,
        }
    }

    /// Takes in the stream's position `now` and the boundaries it reached
    /// since the last sync. When bytes may have been lost ([`advance`] cannot
    /// tell, or the unread bytes fill the ring, so the stream is about to
    /// overwrite the oldest), the reader skips to the stream's position,
    /// dropping what was unread, and says so.
    pub fn sync(&mut self, now: usize, reached: Boundaries) -> Result<(), Lapped> {
        let lapped = match advance(LEN, self.stream_at, now, reached) {
            Some(steps) => {
                self.unread += steps;
                self.unread >= LEN
            }
            None => true,
        };
        self.stream_at = now;
        if lapped {
            self.read_at = now;
            self.unread = 0;
            return Err(Lapped);
        }
        Ok(())
    }

    /// The ring index of the next unread byte, now counted as read.
    pub fn take(&mut self) -> Option<usize> {
        if self.unread == 0 {
            return None;
        }
        let at = self.read_at;
        self.read_at = (at + 1) % LEN;
        self.unread -= 1;
        Some(at)
    }
}

impl<const LEN: usize> Default for RingReader<LEN> {
    fn default() -> Self {
        Self::new()
    }
}
