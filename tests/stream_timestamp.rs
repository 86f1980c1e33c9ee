//! Timestamp extension across the 32-bit wrap, and the link budget formula.

use triad::protocol::{max_frame_rate, TimestampUnwrapper, MAX_ENCODED_LEN};

#[test]
fn timestamps_keep_rising_across_wraps() {
    let mut clock = TimestampUnwrapper::new();
    assert_eq!(clock.unwrap(4_000_000_000), 4_000_000_000);
    assert_eq!(clock.unwrap(u32::MAX), u64::from(u32::MAX));
    // One microsecond later the 32-bit counter reads 0.
    assert_eq!(clock.unwrap(0), 1 << 32);
    assert_eq!(clock.unwrap(10), (1 << 32) + 10);
    // Several wraps, each step below 2³² µs.
    let mut raw = 10u32;
    let mut want = (1u64 << 32) + 10;
    for _ in 0..5 {
        raw = raw.wrapping_add(3_000_000_000);
        want += 3_000_000_000;
        assert_eq!(clock.unwrap(raw), want);
    }
}

#[test]
fn same_timestamp_twice_does_not_advance() {
    let mut clock = TimestampUnwrapper::new();
    assert_eq!(clock.unwrap(77), 77);
    assert_eq!(clock.unwrap(77), 77);
}

#[test]
fn max_frame_rate_is_baud_over_ten_bit_times_per_byte() {
    // 53 bytes per frame × 10 bit times (8N1) = 530 bit times per frame.
    assert_eq!(MAX_ENCODED_LEN, 53);
    assert_eq!(max_frame_rate(115_200), 217); // 217.36…
    assert_eq!(max_frame_rate(921_600), 1738); // 1738.87…
    assert_eq!(max_frame_rate(2_000_000), 3773); // 3773.58…
    assert_eq!(max_frame_rate(0), 0);
    assert_eq!(max_frame_rate(u32::MAX), u32::MAX / 530);
}
