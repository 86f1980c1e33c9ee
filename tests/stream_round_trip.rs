//! Every frame field survives encode → decode bit for bit, extremes included.

use rand::{rngs::SmallRng, Rng, SeedableRng};
use triad::protocol::{encode, Decoder, Flags, Frame, FRAME_LEN, MAX_ENCODED_LEN};

/// Field-by-field, bit-for-bit comparison (NaN ≠ NaN under `==`, and the
/// NaN payload and the sign of zero must survive too).
fn assert_bit_exact(got: &Frame, want: &Frame) {
    assert_eq!(got.sequence, want.sequence, "sequence");
    assert_eq!(got.timestamp_us, want.timestamp_us, "timestamp_us");
    assert_eq!(got.flags.bits(), want.flags.bits(), "flags");
    assert_eq!(got.overruns, want.overruns, "overruns");
    assert_eq!(got.dropped, want.dropped, "dropped");
    assert_eq!(got.calibration_id, want.calibration_id, "calibration_id");
    for axis in 0..3 {
        assert_eq!(
            got.accel[axis].to_bits(),
            want.accel[axis].to_bits(),
            "accel[{axis}]"
        );
        assert_eq!(
            got.gyro[axis].to_bits(),
            want.gyro[axis].to_bits(),
            "gyro[{axis}]"
        );
    }
    assert_eq!(
        got.temperature.to_bits(),
        want.temperature.to_bits(),
        "temperature"
    );
}

fn encoded(frame: &Frame) -> Vec<u8> {
    let mut out = [0u8; MAX_ENCODED_LEN];
    let n = encode(frame, &mut out);
    out[..n].to_vec()
}

fn decode_one(bytes: &[u8]) -> Frame {
    let mut decoder = Decoder::new();
    let results: Vec<_> = decoder.feed(bytes).collect();
    assert_eq!(results.len(), 1, "one frame expected, got {results:?}");
    let stats = decoder.stats();
    assert_eq!(
        (
            stats.frames,
            stats.crc_errors,
            stats.malformed,
            stats.bytes_skipped
        ),
        (1, 0, 0, 0)
    );
    results[0].expect("good frame")
}

fn random_frame(rng: &mut SmallRng) -> Frame {
    // Floats from random bit patterns: NaNs with payloads, infinities,
    // subnormals and signed zeros all occur.
    let mut f = || f32::from_bits(rng.random());
    let accel = [f(), f(), f()];
    let gyro = [f(), f(), f()];
    let temperature = f();
    Frame {
        sequence: rng.random(),
        timestamp_us: rng.random(),
        flags: Flags::from_bits_retain(rng.random()),
        overruns: rng.random(),
        dropped: rng.random(),
        calibration_id: rng.random(),
        accel,
        gyro,
        temperature,
    }
}

#[test]
fn every_field_round_trips_at_its_extremes() {
    let nan_payload = f32::from_bits(0x7FC0_1234);
    let signalling_nan = f32::from_bits(0x7F80_0001);
    let negative_nan = f32::from_bits(0xFFFF_FFFF);
    let cases = [
        Frame::default(),
        Frame {
            sequence: u32::MAX,
            timestamp_us: u32::MAX,
            flags: Flags::from_bits_retain(u16::MAX),
            overruns: u16::MAX,
            dropped: u16::MAX,
            calibration_id: u32::MAX,
            accel: [f32::INFINITY, f32::NEG_INFINITY, nan_payload],
            gyro: [signalling_nan, negative_nan, -0.0],
            temperature: f32::MAX,
        },
        Frame {
            sequence: 1,
            timestamp_us: 1,
            flags: Flags::ACCEL_CLIPPED | Flags::DROPPED,
            overruns: 1,
            dropped: 1,
            calibration_id: 1,
            accel: [f32::MIN_POSITIVE, f32::from_bits(1), -f32::from_bits(1)],
            gyro: [f32::MIN, f32::EPSILON, -f32::MIN_POSITIVE],
            temperature: -273.15,
        },
    ];
    for frame in &cases {
        let bytes = encoded(frame);
        assert_bit_exact(&decode_one(&bytes), frame);
    }
}

#[test]
fn random_frames_round_trip_and_always_take_the_same_bytes() {
    let mut rng = SmallRng::seed_from_u64(2);
    for _ in 0..20_000 {
        let frame = random_frame(&mut rng);
        let bytes = encoded(&frame);
        // A frame shorter than 254 bytes gains exactly one stuffing byte.
        assert_eq!(bytes.len(), MAX_ENCODED_LEN);
        assert_eq!(MAX_ENCODED_LEN, FRAME_LEN + 2);
        assert_eq!(bytes.last(), Some(&0));
        assert!(!bytes[..bytes.len() - 1].contains(&0));
        assert_bit_exact(&decode_one(&bytes), &frame);
        assert_bit_exact(&Frame::from_bytes(&frame.to_bytes()).unwrap(), &frame);
    }
}

#[test]
fn fields_sit_at_their_documented_offsets_little_endian() {
    let frame = Frame {
        sequence: 0x0403_0201,
        timestamp_us: 0x0807_0605,
        flags: Flags::from_bits_retain(0x0A09),
        overruns: 0x0C0B,
        dropped: 0x0E0D,
        calibration_id: 0x1211_100F,
        accel: [1.0, 2.0, 3.0],
        gyro: [-1.0, -2.0, -3.0],
        temperature: 0.5,
    };
    let b = frame.to_bytes();
    assert_eq!(b[0], 1, "version");
    assert_eq!(&b[1..19], &(1u8..=0x12).collect::<Vec<_>>()[..]);
    let f = |at: usize| f32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    assert_eq!([f(19), f(23), f(27)], [1.0, 2.0, 3.0]);
    assert_eq!([f(31), f(35), f(39)], [-1.0, -2.0, -3.0]);
    assert_eq!(f(43), 0.5);
    let crc = u32::from_le_bytes(b[47..51].try_into().unwrap());
    assert_eq!(crc, triad::protocol::crc32c(&b[..47]));
}

#[test]
fn flags_set_clear_and_keep_reserved_bits() {
    let mut flags = Flags::empty();
    assert!(flags.is_empty());
    flags.set(Flags::GYRO_CLIPPED, true);
    flags |= Flags::FIFO_OVERFLOW;
    assert_eq!(flags.bits(), 0b0110);
    assert!(flags.contains(Flags::GYRO_CLIPPED | Flags::FIFO_OVERFLOW));
    assert!(!flags.contains(Flags::OVERRUN));
    flags.set(Flags::GYRO_CLIPPED, false);
    assert_eq!(flags, Flags::FIFO_OVERFLOW);
    let named = [
        Flags::ACCEL_CLIPPED,
        Flags::GYRO_CLIPPED,
        Flags::FIFO_OVERFLOW,
        Flags::OVERRUN,
        Flags::DROPPED,
        Flags::UNCALIBRATED,
        Flags::RAW,
        Flags::SELF_TEST,
        Flags::FLASH_STALL,
    ];
    let all = named.iter().fold(Flags::empty(), |a, &f| a | f);
    assert_eq!(all, Flags::KNOWN);
    assert_eq!(named.iter().map(|f| f.bits().count_ones()).sum::<u32>(), 9);
    let reserved = Flags::from_bits_retain(0x8000);
    assert_eq!((reserved & Flags::KNOWN), Flags::empty());
    assert_eq!(reserved.bits(), 0x8000);
}
