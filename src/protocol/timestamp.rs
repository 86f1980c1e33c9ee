//! Extends the frames' wrapping 32-bit microsecond timestamps to 64 bits.

/// Turns the 32-bit µs timestamps, which wrap every 2³² µs ≈ 71.6 min, into
/// a 64-bit count that keeps rising, assuming consecutive frames are less
/// than 71.6 min apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TimestampUnwrapper {
    last: Option<(u32, u64)>,
}

impl TimestampUnwrapper {
    /// An unwrapper that has seen no timestamp yet.
    pub const fn new() -> TimestampUnwrapper {
        TimestampUnwrapper { last: None }
    }

    /// The 64-bit µs count of `timestamp_us`: the first one as it is, each
    /// later one the previous count plus the forward distance modulo 2³².
    pub fn unwrap(&mut self, timestamp_us: u32) -> u64 {
        let extended = match self.last {
            None => u64::from(timestamp_us),
            Some((raw, extended)) => {
                extended.wrapping_add(u64::from(timestamp_us.wrapping_sub(raw)))
            }
        };
        self.last = Some((timestamp_us, extended));
        extended
    }
}
