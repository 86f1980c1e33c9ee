//! CRC-32C (Castagnoli): the one CRC of the project. It closes every stream
//! frame, the calibration blob and the scene blob.
//!
//! Parameters in the Rocksoft/Williams model ("CRC-32/ISCSI" in the
//! catalogue of parametrised CRC algorithms): width 32, polynomial
//! 0x1EDC6F41 (reflected 0x82F63B78), init 0xFFFFFFFF, input and output
//! reflected, xorout 0xFFFFFFFF, check value 0xE3069283 for the ASCII bytes
//! "123456789". The same CRC is used by iSCSI (RFC 3720 §12.1), SCTP
//! (RFC 4960 App. B) and ext4, and x86 SSE4.2 and ARMv8 compute it in one
//! instruction, so decoders in any language are easy to get right.
//!
//! Why CRC-32C and not the Ethernet CRC-32 or a CRC-16: at the 376 data bits
//! a frame protects, CRC-32C has Hamming distance 6 (every error of up to 5
//! flipped bits is detected; Koopman, "32-Bit Cyclic Redundancy Codes for
//! Internet Applications", DSN 2002, and RFC 3385), where the Ethernet
//! polynomial has 5 and CRC-16/CCITT has 4; and a random corruption slips
//! through with probability 2⁻³² instead of 2⁻¹⁶. The two extra bytes over a
//! CRC-16 cost 4 % of the wire budget. `tests/stream_crc.rs` checks the
//! distance-6 claim exhaustively at the frame's length.

/// Reflected form of the CRC-32C generator polynomial 0x1EDC6F41.
pub const CRC32C_POLY_REFLECTED: u32 = 0x82F6_3B78;

/// CRC-32C of the ASCII bytes "123456789" (the catalogue's check value).
pub const CRC32C_CHECK: u32 = 0xE306_9283;

/// Slicing-by-4 tables (Intel's "slicing-by-N", Kounavis & Berry 2005):
/// `TABLES[0]` is the classic one-byte table, `TABLES[k][n]` the CRC of byte
/// n followed by k zero bytes. 4 KiB of flash buy one step per four bytes
/// (four lookups and XORs) instead of one per byte: about half the
/// instructions of the byte-wise loop on a Cortex-M4 for a 47-byte frame.
static TABLES: [[u32; 256]; 4] = build_tables();

const fn build_tables() -> [[u32; 256]; 4] {
    let mut tables = [[0u32; 256]; 4];
    let mut n = 0;
    while n < 256 {
        let mut crc = n as u32;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ CRC32C_POLY_REFLECTED
            } else {
                crc >> 1
            };
            bit += 1;
        }
        tables[0][n] = crc;
        n += 1;
    }
    let mut k = 1;
    while k < 4 {
        let mut n = 0;
        while n < 256 {
            let prev = tables[k - 1][n];
            tables[k][n] = (prev >> 8) ^ tables[0][(prev & 0xFF) as usize];
            n += 1;
        }
        k += 1;
    }
    tables
}

/// Advances a running CRC-32C register over `data` (no init, no xorout):
/// `crc32c(d) == !crc32c_update(!0, d)`.
pub fn crc32c_update(mut crc: u32, data: &[u8]) -> u32 {
    let mut words = data.chunks_exact(4);
    for word in &mut words {
        crc = crc32c_word(
            crc,
            u32::from_le_bytes([word[0], word[1], word[2], word[3]]),
        );
    }
    for &byte in words.remainder() {
        crc = crc32c_byte(crc, byte);
    }
    crc
}

/// Advances a running CRC-32C register over four bytes, `word` being
/// their little-endian value (for a pass that reads the bytes for another
/// reason too: the packet encoder's stuffing).
#[inline(always)]
pub fn crc32c_word(crc: u32, word: u32) -> u32 {
    let t = &TABLES;
    let crc = crc ^ word;
    // Every index is masked or shifted into 0..=255: always inside a table.
    t[3][(crc & 0xFF) as usize]
        ^ t[2][((crc >> 8) & 0xFF) as usize]
        ^ t[1][((crc >> 16) & 0xFF) as usize]
        ^ t[0][(crc >> 24) as usize]
}

/// Advances a running CRC-32C register over one byte.
#[inline(always)]
pub fn crc32c_byte(crc: u32, byte: u8) -> u32 {
    (crc >> 8) ^ TABLES[0][((crc ^ u32::from(byte)) & 0xFF) as usize]
}

/// CRC-32C of `data` (init 0xFFFFFFFF, reflected, xorout 0xFFFFFFFF).
pub fn crc32c(data: &[u8]) -> u32 {
    !crc32c_update(!0, data)
}
