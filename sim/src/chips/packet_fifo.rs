//! A chip FIFO as a ring of bytes holding whole packets of varying length
//! (the ICM-42688-P mixes 8-, 16- and 20-byte packets in its 2 KiB; the
//! LSM6DSOX stores 7-byte tagged words), read out byte by byte through a
//! data port (a partially read packet resumes where the read stopped).
//! Shared by every chip model.

/// Up to `BYTES` bytes in at most `PACKETS` packets.
#[derive(Clone, Debug)]
pub struct PacketFifo<const BYTES: usize, const PACKETS: usize> {
    bytes: [u8; BYTES],
    lengths: [u8; PACKETS],
    /// Index in `bytes` of the oldest packet's first byte.
    head_byte: usize,
    /// Index in `lengths` of the oldest packet.
    head_packet: usize,
    used_bytes: usize,
    len: usize,
    read_offset: usize,
}

impl<const BYTES: usize, const PACKETS: usize> Default for PacketFifo<BYTES, PACKETS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const BYTES: usize, const PACKETS: usize> PacketFifo<BYTES, PACKETS> {
    /// An empty FIFO.
    pub const fn new() -> Self {
        Self {
            bytes: [0; BYTES],
            lengths: [0; PACKETS],
            head_byte: 0,
            head_packet: 0,
            used_bytes: 0,
            len: 0,
            read_offset: 0,
        }
    }

    /// Packets held (a partly read packet counts until its last byte is read).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no packet is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether a packet of `length` bytes fits beside what is held.
    pub fn has_room(&self, length: usize) -> bool {
        self.len < PACKETS && self.used_bytes + length <= BYTES
    }

    /// Bytes not yet read.
    pub fn bytes(&self) -> usize {
        self.used_bytes - self.read_offset
    }

    /// Empties the FIFO.
    pub fn clear(&mut self) {
        self.head_byte = 0;
        self.head_packet = 0;
        self.used_bytes = 0;
        self.len = 0;
        self.read_offset = 0;
    }

    /// Appends a packet; `false` (and nothing stored) when it does not fit
    /// or is longer than 255 bytes.
    pub fn push(&mut self, packet: &[u8]) -> bool {
        let Ok(length) = u8::try_from(packet.len()) else {
            return false;
        };
        if !self.has_room(packet.len()) || BYTES == 0 {
            return false;
        }
        let tail = (self.head_byte + self.used_bytes) % BYTES;
        for (i, &b) in packet.iter().enumerate() {
            self.bytes[(tail + i) % BYTES] = b;
        }
        self.lengths[(self.head_packet + self.len) % PACKETS] = length;
        self.used_bytes += packet.len();
        self.len += 1;
        true
    }

    /// Appends a packet, dropping the oldest ones until it fits.
    pub fn push_overwrite(&mut self, packet: &[u8]) {
        while !self.has_room(packet.len()) && !self.is_empty() {
            self.drop_oldest();
        }
        self.push(packet);
    }

    fn drop_oldest(&mut self) {
        if self.len > 0 {
            let length = usize::from(self.lengths[self.head_packet]);
            self.head_byte = (self.head_byte + length) % BYTES;
            self.head_packet = (self.head_packet + 1) % PACKETS;
            self.used_bytes -= length;
            self.len -= 1;
            self.read_offset = 0;
        }
    }

    /// Byte `index` of the oldest packet, without removing it; `None` when
    /// empty or `index` is beyond the packet.
    pub fn peek_byte(&self, index: usize) -> Option<u8> {
        if self.len == 0 || index >= usize::from(self.lengths[self.head_packet]) {
            return None;
        }
        Some(self.bytes[(self.head_byte + index) % BYTES])
    }

    /// Removes the oldest packet (for chips that pop on reading a packet's last register).
    pub fn pop_packet(&mut self) {
        self.drop_oldest();
    }

    /// Reads the next byte; `None` when empty.
    pub fn pop_byte(&mut self) -> Option<u8> {
        let byte = self.peek_byte(self.read_offset)?;
        self.read_offset += 1;
        if self.read_offset == usize::from(self.lengths[self.head_packet]) {
            self.drop_oldest();
        }
        Some(byte)
    }
}
