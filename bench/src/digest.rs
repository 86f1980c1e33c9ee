//! A 64-bit FNV-1a digest of a variant's outputs: the benchmark firmware
//! prints it, the host recomputes it; equal digests mean equal bits.

/// FNV-1a over 32-bit words (each fed as four little-endian bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Self::new()
    }
}

impl Digest {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    /// The digest of nothing.
    pub const fn new() -> Self {
        Digest(Self::OFFSET)
    }

    /// Feeds one word.
    pub fn word(&mut self, w: u32) {
        for byte in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(Self::PRIME);
        }
    }

    /// Feeds an f32's bits.
    pub fn f32(&mut self, x: f32) {
        self.word(x.to_bits());
    }

    /// Feeds an f64's bits (low word first).
    pub fn f64(&mut self, x: f64) {
        let bits = x.to_bits();
        self.word(bits as u32);
        self.word((bits >> 32) as u32);
    }

    /// The value so far.
    pub fn value(&self) -> u64 {
        self.0
    }
}
