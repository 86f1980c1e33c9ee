//! COBS stuffing and unstuffing: the published examples, block boundaries,
//! and random round trips.

use rand::{rngs::SmallRng, Rng, SeedableRng};
use triad::protocol::cobs::{
    max_stuffed_len, stuff, stuff_block, stuff_in_place, stuff_short, CobsError, Unstuffer,
    MAX_BLOCK,
};

fn stuffed(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0xAA; max_stuffed_len(data.len())];
    let n = stuff(data, &mut out).expect("buffer of max_stuffed_len");
    out.truncate(n);
    out
}

/// `len` random bytes, each zero with probability 1/`zero_one_in`.
fn block(rng: &mut SmallRng, len: usize, zero_one_in: u32) -> Vec<u8> {
    (0..len)
        .map(|_| match rng.random_ratio(1, zero_one_in) {
            true => 0,
            false => rng.random_range(1..=255),
        })
        .collect()
}

fn unstuffed(bytes: &[u8]) -> Result<Vec<u8>, CobsError> {
    let mut u = Unstuffer::new();
    let mut out = Vec::new();
    for &b in bytes {
        out.extend(u.push(b));
    }
    u.finish().map(|()| out)
}

#[test]
fn published_examples() {
    // Examples from Cheshire & Baker's paper as commonly tabulated.
    let cases: &[(&[u8], &[u8])] = &[
        (&[], &[0x01]),
        (&[0x00], &[0x01, 0x01]),
        (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
        (&[0x00, 0x11, 0x00], &[0x01, 0x02, 0x11, 0x01]),
        (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
        (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
        (&[0x11, 0x00, 0x00, 0x00], &[0x02, 0x11, 0x01, 0x01, 0x01]),
    ];
    for (data, expected) in cases {
        assert_eq!(stuffed(data), *expected, "stuffing {data:02x?}");
        assert_eq!(
            unstuffed(expected).unwrap(),
            *data,
            "unstuffing {expected:02x?}"
        );
    }
}

#[test]
fn block_boundaries_at_254_and_255_bytes() {
    // 254 non-zero bytes fill one 0xFF block.
    let full: Vec<u8> = (1..=254).map(|b| b as u8).collect();
    let s = stuffed(&full);
    assert_eq!(s[0], 0xFF);
    assert_eq!(&s[1..255], &full[..]);
    assert_eq!(unstuffed(&s).unwrap(), full);
    // 255 non-zero bytes: a full block, then a block of one byte.
    let mut longer = full.clone();
    longer.push(0x42);
    let s = stuffed(&longer);
    assert_eq!(s.len(), 257);
    assert_eq!(&s[255..], &[0x02, 0x42]);
    assert_eq!(unstuffed(&s).unwrap(), longer);
    // A zero right after a full block: the 0xFF block implies no zero.
    let mut with_zero = full.clone();
    with_zero.push(0);
    assert_eq!(unstuffed(&stuffed(&with_zero)).unwrap(), with_zero);
}

#[test]
fn random_round_trips_never_contain_zero_and_fit_the_bound() {
    let mut rng = SmallRng::seed_from_u64(7);
    for _ in 0..2000 {
        let len = rng.random_range(0..700);
        let zero_share = rng.random_range(0.0..1.0);
        let data: Vec<u8> = (0..len)
            .map(|_| {
                if rng.random_bool(zero_share) {
                    0
                } else {
                    rng.random_range(1..=255)
                }
            })
            .collect();
        let s = stuffed(&data);
        assert!(s.len() <= max_stuffed_len(len));
        assert!(!s.contains(&0));
        assert_eq!(unstuffed(&s).unwrap(), data);
    }
}

#[test]
fn short_buffer_is_an_error_naming_the_sizes() {
    let mut out = [0u8; 4];
    assert_eq!(
        stuff(&[1, 2, 3, 4], &mut out),
        Err(CobsError::BufferTooSmall {
            needed: 5,
            available: 4
        })
    );
}

#[test]
fn truncated_block_and_empty_input_are_rejected() {
    assert_eq!(unstuffed(&[0x05, 0x11, 0x22]), Err(CobsError::Truncated));
    assert_eq!(unstuffed(&[]), Err(CobsError::Truncated));
}

/// The encoder's fixed-size form writes the same bytes as the general one,
/// for frame-sized blocks with no, some and only zero bytes.
#[test]
fn short_form_equals_the_general_form_on_frame_sized_blocks() {
    fn check<const N: usize, const M: usize>(rng: &mut SmallRng) {
        for zero_percent in [0u32, 5, 30, 100] {
            for _ in 0..500 {
                let mut data = [0u8; N];
                for b in data.iter_mut() {
                    *b = if rng.random_range(0..100) < zero_percent {
                        0
                    } else {
                        rng.random_range(1..=255)
                    };
                }
                let mut out = [0xAAu8; M];
                stuff_short(&data, &mut out);
                assert_eq!(out.to_vec(), stuffed(&data), "{data:?}");
            }
        }
    }
    let mut rng = SmallRng::seed_from_u64(0xC0B5);
    check::<51, 52>(&mut rng);
    check::<1, 2>(&mut rng);
    check::<253, 254>(&mut rng);
}

#[test]
fn the_block_form_equals_the_general_one_up_to_253_bytes_and_refuses_more() {
    let mut rng = SmallRng::seed_from_u64(0xB10C);
    for len in 0..=MAX_BLOCK {
        // Dense zeros, sparse zeros and none: every block shape.
        for zero_one_in in [2u32, 17, u32::MAX] {
            let data = block(&mut rng, len, zero_one_in);
            let mut out = vec![0xAA; len + 1];
            let n = stuff_block(&data, &mut out).expect("fits");
            assert_eq!(out[..n], stuffed(&data)[..], "{len} bytes");
        }
    }
    let long = [7u8; MAX_BLOCK + 1];
    let mut out = [0u8; MAX_BLOCK + 3];
    assert!(stuff_block(&long, &mut out).is_err());
    assert!(stuff_block(&[1, 2, 3], &mut [0u8; 3]).is_err());
}

#[test]
fn stuffing_in_place_equals_the_general_form_up_to_253_bytes_and_refuses_more() {
    let mut rng = SmallRng::seed_from_u64(0x1_7ACE);
    for len in 0..=MAX_BLOCK {
        for zero_one_in in [1u32, 2, 5, 17, u32::MAX] {
            let data = block(&mut rng, len, zero_one_in);
            // The data where the stuffed bytes go, codes and delimiter unwritten.
            let mut frame = vec![0xAA; len + 2];
            frame[1..=len].copy_from_slice(&data);
            assert_eq!(stuff_in_place(&mut frame), Ok(len + 2));
            let mut expected = stuffed(&data);
            expected.push(0);
            assert_eq!(frame, expected, "{len} bytes, a zero in {zero_one_in}");
        }
    }
    assert!(stuff_in_place(&mut [0u8; MAX_BLOCK + 3]).is_err());
    assert!(stuff_in_place(&mut [0u8; 1]).is_err());
    assert!(stuff_in_place(&mut []).is_err());
}
