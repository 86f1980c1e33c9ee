//! The batched data frame (protocol v2, type 0x04): W corrected samples in
//! fixed point, within half a count of each value, clipped and flagged
//! beyond the range, at most 25 bytes per sample on the wire, and decoded
//! back through the stream decoder.

use triad::protocol::batch_frame::{to_counts, BatchFrame, MAX_BATCH};
use triad::protocol::{Decoder, Flags};
use triad::protocol::{Packet, MAX_WIRE_LEN};

/// The device's LSBs for a ±16 g, ±2000 °/s 16-bit chip (the powers of two
/// at least 1.5 chip LSBs: `fixed_point_lsb`).
const ACCEL_LSB: f32 = 1.0 / 128.0;
const GYRO_LSB: f32 = 1.0 / 512.0;

fn sample(i: usize) -> ([f32; 3], [f32; 3]) {
    let x = i as f32;
    (
        [0.1 * x - 0.7, 9.80665 - 0.013 * x, -3.3 + 0.21 * x],
        [0.001 * x, -0.25 + 0.0173 * x, 1.5 - 0.1 * x],
    )
}

#[test]
fn a_full_batch_fits_the_budget_and_reads_back_within_half_a_count() {
    let mut batch = BatchFrame::new(ACCEL_LSB, GYRO_LSB);
    batch.sequence = 7;
    batch.timestamp_us = 1_000_000;
    batch.period_ns = 125_000; // 8 kHz
    batch.calibration_id = 0xCAFE;
    batch.temperature = 31.5;
    for i in 0..MAX_BATCH {
        let (a, g) = sample(i);
        assert!(batch.push(a, g));
    }
    assert!(
        !batch.push([0.0; 3], [0.0; 3]),
        "a full batch takes no more"
    );
    assert_eq!(batch.flags, Flags::empty());
    let packet = batch.to_packet().unwrap();
    let mut wire = [0u8; MAX_WIRE_LEN];
    let n = packet.to_wire(&mut wire);
    // The budget: at most 25 bytes per 6-axis sample on the wire.
    let per_sample = n as f64 / MAX_BATCH as f64;
    assert!(per_sample <= 25.0, "{per_sample} bytes per sample");
    assert_eq!(n, 235);
    let mut decoder = Decoder::new();
    let mut bytes = vec![0u8];
    bytes.extend_from_slice(&wire[..n]);
    let decoded: Vec<_> = decoder.feed_packets(&bytes).collect();
    let [Ok(Packet::Batch(back))] = decoded.as_slice() else {
        panic!("{decoded:?}");
    };
    assert_eq!(*back, batch);
    assert_eq!(decoder.stats().batch_samples, MAX_BATCH as u64);
    for i in 0..MAX_BATCH {
        let (a, g) = sample(i);
        let (ra, rg) = back.sample_si(i).unwrap();
        for k in 0..3 {
            // Half a count, plus the f32 rounding of count × lsb.
            assert!(
                (ra[k] - a[k]).abs() <= 0.5 * ACCEL_LSB * (1.0 + 1e-6),
                "{i} {k}"
            );
            assert!(
                (rg[k] - g[k]).abs() <= 0.5 * GYRO_LSB * (1.0 + 1e-6),
                "{i} {k}"
            );
        }
    }
}

#[test]
fn values_beyond_the_range_are_clipped_and_flagged_per_triad() {
    assert_eq!(to_counts(1e9, 1.0), (32767, true));
    assert_eq!(to_counts(-1e9, 1.0), (-32767, true));
    assert_eq!(to_counts(f32::NAN, 1.0), (0, true));
    // Ties to even, as the FPU's default rounding.
    assert_eq!(to_counts(2.5, 1.0), (2, false));
    assert_eq!(to_counts(-3.5, 1.0), (-4, false));
    assert_eq!(to_counts(3.4, 1.0), (3, false));
    let mut batch = BatchFrame::new(ACCEL_LSB, GYRO_LSB);
    batch.push([0.0; 3], [1e6, 0.0, 0.0]);
    assert_eq!(batch.flags, Flags::GYRO_CLIPPED);
    batch.push([-1e6, 0.0, 0.0], [0.0; 3]);
    assert_eq!(batch.flags, Flags::GYRO_CLIPPED | Flags::ACCEL_CLIPPED);
}

#[test]
fn a_batch_whose_count_disagrees_with_its_length_is_malformed() {
    let mut batch = BatchFrame::new(ACCEL_LSB, GYRO_LSB);
    batch.push([1.0; 3], [0.5; 3]);
    let good = batch.to_packet().unwrap();
    let mut bytes = good.as_bytes().to_vec();
    // Claim two samples while carrying one, CRC recomputed.
    bytes[2 + 34] = 2;
    let crc_at = bytes.len() - 4;
    let crc = triad::protocol::crc32c::crc32c(&bytes[..crc_at]);
    bytes[crc_at..].copy_from_slice(&crc.to_le_bytes());
    assert!(matches!(
        Packet::parse(&bytes),
        Err(triad::protocol::DecodeError::Body { kind: 0x04, .. })
    ));
}

/// The transmitter's form (the packet written where its wire bytes go, then
/// stuffed in place) gives the bytes of the packet built apart, then
/// stuffed: for every batch length, with counts dense in zero bytes.
#[test]
fn a_batch_written_in_place_has_the_wire_bytes_of_its_packet() {
    use triad::protocol::{RawFrame, RawScale};
    for count in 0..=MAX_BATCH {
        let mut batch = BatchFrame::new(ACCEL_LSB, GYRO_LSB);
        batch.sequence = 0x0100 * count as u32;
        batch.timestamp_us = 255;
        batch.flags = Flags::from_bits_retain(count as u16);
        for i in 0..count {
            // Small values: many zero bytes, the shape of a still device.
            let (a, g) = sample(i);
            assert!(batch.push(a.map(|v| v * 0.01), g.map(|v| v * (i % 3) as f32)));
        }
        let mut apart = [0xAA; MAX_WIRE_LEN];
        let n = batch.to_packet().unwrap().to_wire(&mut apart);
        let mut in_place = [0x55; MAX_WIRE_LEN];
        assert_eq!(batch.to_wire(&mut in_place), Ok(n), "{count} samples");
        assert_eq!(in_place[..n], apart[..n], "{count} samples");
    }
    let raw = RawFrame {
        sequence: 3,
        accel: [0.0, 1.0, -1.0],
        scale: RawScale::default(),
        ..RawFrame::default()
    };
    let mut apart = [0xAA; MAX_WIRE_LEN];
    let n = raw.to_packet().unwrap().to_wire(&mut apart);
    let mut in_place = [0x55; MAX_WIRE_LEN];
    assert_eq!(raw.to_wire(&mut in_place), Ok(n));
    assert_eq!(in_place[..n], apart[..n]);
}
