//! A chip FIFO as a ring of fixed-size packets, read out byte by byte through
//! a data port (a partially read packet resumes where the read stopped).

/// A ring of up to `CAP` packets of `LEN` bytes.
#[derive(Clone, Debug)]
pub struct PacketFifo<const CAP: usize, const LEN: usize> {
    packets: [[u8; LEN]; CAP],
    head: usize,
    len: usize,
    read_offset: usize,
}

impl<const CAP: usize, const LEN: usize> Default for PacketFifo<CAP, LEN> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CAP: usize, const LEN: usize> PacketFifo<CAP, LEN> {
    /// An empty FIFO.
    pub const fn new() -> Self {
        Self {
            packets: [[0; LEN]; CAP],
            head: 0,
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

    /// Whether the FIFO holds `CAP` packets.
    pub fn is_full(&self) -> bool {
        self.len >= CAP
    }

    /// Bytes not yet read.
    pub fn bytes(&self) -> usize {
        self.len * LEN - self.read_offset
    }

    /// Empties the FIFO.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
        self.read_offset = 0;
    }

    /// Appends a packet; `false` (and nothing stored) when full.
    pub fn push(&mut self, packet: [u8; LEN]) -> bool {
        if self.is_full() || CAP == 0 {
            return false;
        }
        let tail = (self.head + self.len) % CAP;
        self.packets[tail] = packet;
        self.len += 1;
        true
    }

    /// Appends a packet, dropping the oldest when full.
    pub fn push_overwrite(&mut self, packet: [u8; LEN]) {
        if self.is_full() {
            self.drop_oldest();
        }
        self.push(packet);
    }

    fn drop_oldest(&mut self) {
        if self.len > 0 {
            self.head = (self.head + 1) % CAP;
            self.len -= 1;
            self.read_offset = 0;
        }
    }

    /// Byte `index` of the oldest packet, without removing it; `None` when
    /// empty or `index` is beyond the packet.
    pub fn peek_byte(&self, index: usize) -> Option<u8> {
        if self.len == 0 {
            return None;
        }
        self.packets[self.head].get(index).copied()
    }

    /// Removes the oldest packet (for chips that pop on reading a packet's last register).
    pub fn pop_packet(&mut self) {
        self.drop_oldest();
    }

    /// Reads the next byte; `None` when empty.
    pub fn pop_byte(&mut self) -> Option<u8> {
        if self.len == 0 {
            return None;
        }
        let byte = self.packets[self.head][self.read_offset];
        self.read_offset += 1;
        if self.read_offset == LEN {
            self.read_offset = 0;
            self.drop_oldest();
        }
        Some(byte)
    }
}
