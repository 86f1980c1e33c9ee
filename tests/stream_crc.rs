//! CRC-32C: catalogue check value, table against the bitwise definition, and
//! the Hamming-distance claim of src/protocol/crc.rs at the frame's length.

use std::collections::HashSet;

use rand::{rngs::SmallRng, Rng, SeedableRng};
use triad::protocol::crc32c::{crc32c, crc32c_update, CRC32C_POLY_REFLECTED};
use triad::protocol::{CHECKED_LEN, CRC32C_CHECK, FRAME_LEN};

/// The definition, one bit at a time (reflected, init and xorout all ones).
fn crc32c_bitwise(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in data {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ CRC32C_POLY_REFLECTED
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn check_value_of_123456789_is_the_catalogue_value() {
    assert_eq!(crc32c(b"123456789"), 0xE306_9283);
    assert_eq!(CRC32C_CHECK, 0xE306_9283);
    assert_eq!(crc32c_bitwise(b"123456789"), CRC32C_CHECK);
}

#[test]
fn rfc3720_test_vectors() {
    // RFC 3720 (iSCSI) appendix B.4: 32 bytes of zeros, of ones, ascending.
    assert_eq!(crc32c(&[0u8; 32]), 0x8A91_36AA);
    assert_eq!(crc32c(&[0xFFu8; 32]), 0x62A8_AB43);
    let ascending: Vec<u8> = (0u8..32).collect();
    assert_eq!(crc32c(&ascending), 0x46DD_794E);
}

#[test]
fn table_matches_bitwise_definition_on_random_data() {
    let mut rng = SmallRng::seed_from_u64(0x00C5_C32C);
    for len in 0..300 {
        let data: Vec<u8> = (0..len).map(|_| rng.random()).collect();
        assert_eq!(crc32c(&data), crc32c_bitwise(&data), "length {len}");
        // The running register composes over split points.
        let cut = rng.random_range(0..=len);
        let (a, b) = data.split_at(cut);
        assert_eq!(!crc32c_update(crc32c_update(!0, a), b), crc32c(&data));
    }
}

/// Syndrome of each single-bit error in a FRAME_LEN-byte codeword (CHECKED_LEN
/// data bytes + the CRC): the CRC is affine, so a set of flipped bits goes
/// undetected exactly when the XOR of their syndromes is zero.
fn single_bit_syndromes() -> Vec<u32> {
    let zero = [0u8; CHECKED_LEN];
    let base = crc32c(&zero);
    let mut syndromes = Vec::with_capacity(FRAME_LEN * 8);
    for bit in 0..CHECKED_LEN * 8 {
        let mut data = zero;
        data[bit / 8] ^= 1 << (bit % 8);
        syndromes.push(crc32c(&data) ^ base);
    }
    for bit in 0..32 {
        syndromes.push(1 << bit);
    }
    syndromes
}

#[test]
fn every_error_of_up_to_five_bits_in_a_frame_is_detected() {
    // Hamming distance ≥ 6 over the 408 bits of a frame: no XOR of 1..=5
    // distinct syndromes is zero. Weights 1–2: syndromes non-zero and
    // distinct. Weight 3: no pair XOR equals a third syndrome. Weights 4–5:
    // no two disjoint pairs, and no triple and pair, have equal XORs; with
    // weights ≤ 3 clean, any equality between a pair's XOR and another
    // pair's or a triple's implies an undetected error of weight 4 or 5
    // (shared bits cancel to a lighter pattern, already excluded).
    let s = single_bit_syndromes();
    let n = s.len();
    assert_eq!(n, 408);
    let singles: HashSet<u32> = s.iter().copied().collect();
    assert!(!singles.contains(&0), "a single-bit error is undetected");
    assert_eq!(singles.len(), n, "a two-bit error is undetected");
    let mut pairs = HashSet::with_capacity(n * n / 2);
    for i in 0..n {
        for j in i + 1..n {
            let x = s[i] ^ s[j];
            assert!(
                !singles.contains(&x),
                "three-bit error {i},{j},… undetected"
            );
            assert!(
                pairs.insert(x),
                "four-bit error with bits {i},{j} undetected"
            );
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            let x = s[i] ^ s[j];
            for &sk in &s[j + 1..] {
                assert!(!pairs.contains(&(x ^ sk)), "five-bit error undetected");
            }
        }
    }
}
