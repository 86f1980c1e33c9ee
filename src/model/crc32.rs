//! CRC-32 (IEEE 802.3; the zlib/PNG CRC): reflected polynomial 0xEDB88320,
//! initial value and final XOR 0xFFFFFFFF. Check value: CRC-32("123456789")
//! = 0xCBF43926 (Williams, "A Painless Guide to CRC Error Detection
//! Algorithms", and the reveng CRC catalogue entry CRC-32/ISO-HDLC).

/// The byte-wise lookup table, built at compile time.
const TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut bit = 0;
        while bit < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            bit += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

/// CRC-32 of `bytes`.
pub fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(!0u32, |crc, &b| {
        TABLE[usize::from((crc as u8) ^ b)] ^ (crc >> 8)
    })
}
