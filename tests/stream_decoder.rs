//! The decoder resynchronises after truncation, corruption, shifted starts
//! and concatenation, and counts exactly what it lost; no input panics it.

use rand::{rngs::SmallRng, Rng, SeedableRng};
use triad::protocol::{encode, DecodeError, Decoder, DecoderStats, Flags, Frame, MAX_ENCODED_LEN};

const L: usize = MAX_ENCODED_LEN;

fn frame(sequence: u32) -> Frame {
    Frame {
        sequence,
        timestamp_us: sequence.wrapping_mul(1000),
        flags: Flags::empty(),
        overruns: 0,
        dropped: 0,
        calibration_id: 0xCA1B_0001,
        // Values with zero bytes in them so that stuffing has work to do.
        accel: [0.0, sequence as f32, 9.80665],
        gyro: [1.0e-3, 0.0, -(sequence as f32)],
        temperature: 25.0,
    }
}

fn encoded(f: &Frame) -> Vec<u8> {
    let mut out = [0u8; L];
    let n = encode(f, &mut out);
    out[..n].to_vec()
}

fn stream(sequences: impl IntoIterator<Item = u32>) -> Vec<u8> {
    sequences
        .into_iter()
        .flat_map(|s| encoded(&frame(s)))
        .collect()
}

/// Frames decoded, errors, and the final counters.
fn decode(bytes: &[u8]) -> (Vec<Frame>, Vec<DecodeError>, DecoderStats, Decoder) {
    let mut decoder = Decoder::new();
    let mut frames = Vec::new();
    let mut errors = Vec::new();
    for result in decoder.feed(bytes) {
        match result {
            Ok(f) => frames.push(f),
            Err(e) => errors.push(e),
        }
    }
    let stats = *decoder.stats();
    // Every byte is in a good frame, skipped, or pending.
    assert_eq!(
        stats.bytes,
        stats.frames * L as u64 + stats.bytes_skipped + decoder.pending_bytes(),
        "byte accounting"
    );
    assert_eq!(stats.frames, frames.len() as u64);
    assert_eq!(stats.crc_errors + stats.malformed, errors.len() as u64);
    (frames, errors, stats, decoder)
}

fn sequences(frames: &[Frame]) -> Vec<u32> {
    frames.iter().map(|f| f.sequence).collect()
}

#[test]
fn clean_stream_decodes_every_frame_with_nothing_counted() {
    let (frames, errors, s, _) = decode(&stream(0..100));
    assert_eq!(sequences(&frames), (0..100).collect::<Vec<_>>());
    assert!(errors.is_empty());
    assert_eq!(
        s,
        DecoderStats {
            bytes: 100 * L as u64,
            frames: 100,
            packet_bytes: 100 * L as u64,
            ..Default::default()
        }
    );
    assert_eq!(frames[7], frame(7));
}

#[test]
fn joining_mid_frame_skips_the_partial_frame_silently() {
    let bytes = stream(0..10);
    for start in 1..L {
        let (frames, errors, s, _) = decode(&bytes[start..]);
        assert_eq!(
            sequences(&frames),
            (1..10).collect::<Vec<_>>(),
            "start {start}"
        );
        assert!(errors.is_empty(), "start {start}: {errors:?}");
        assert_eq!(s.bytes_skipped, (L - start) as u64, "start {start}");
        assert_eq!((s.sequence_gaps, s.frames_lost), (0, 0));
    }
}

#[test]
fn bytes_removed_inside_a_frame_lose_exactly_that_frame() {
    let bytes = stream(0..10);
    for removed in 1..L - 1 {
        // Remove `removed` bytes from the middle of frame 5, keeping its
        // delimiter: the frame comes out short, so it is malformed.
        let start = 5 * L + 1;
        let mut cut = bytes.clone();
        cut.drain(start..start + removed);
        let (frames, errors, s, _) = decode(&cut);
        let mut want: Vec<u32> = (0..10).collect();
        want.remove(5);
        assert_eq!(sequences(&frames), want, "removed {removed}");
        assert_eq!(errors.len(), 1, "removed {removed}");
        assert!(!errors[0].is_crc());
        assert_eq!((s.malformed, s.crc_errors), (1, 0));
        assert_eq!((s.sequence_gaps, s.frames_lost), (1, 1));
        assert_eq!(s.bytes_skipped, (L - removed) as u64);
    }
}

#[test]
fn a_frame_cut_before_its_delimiter_takes_the_next_frame_with_it() {
    // The link drops the tail of frame 3, delimiter included: what is left
    // runs into frame 4, and the merged bytes are one over-long frame.
    let bytes = stream(0..8);
    let kept = 20;
    let mut cut = bytes[..3 * L + kept].to_vec();
    cut.extend_from_slice(&bytes[4 * L..]);
    let (frames, errors, s, _) = decode(&cut);
    assert_eq!(sequences(&frames), vec![0, 1, 2, 5, 6, 7]);
    assert_eq!(errors, vec![DecodeError::Length { len: 19 + 51 + 1 }]);
    assert_eq!(
        (s.malformed, s.crc_errors, s.sequence_gaps, s.frames_lost),
        (1, 0, 1, 2)
    );
    assert_eq!(s.bytes_skipped, (kept + L) as u64);
}

#[test]
fn a_truncated_last_frame_stays_pending_and_is_not_an_error() {
    let bytes = stream(0..4);
    let (frames, errors, s, decoder) = decode(&bytes[..3 * L + 30]);
    assert_eq!(sequences(&frames), vec![0, 1, 2]);
    assert!(errors.is_empty());
    assert_eq!(decoder.pending_bytes(), 30);
    assert_eq!(s.bytes_skipped, 0);
}

#[test]
fn a_corrupted_payload_byte_is_a_crc_error_and_one_lost_frame() {
    let mut bytes = stream(0..6);
    // Byte 30 of frame 2 is inside the accel field, away from code bytes
    // (checked below), and stays non-zero when flipped.
    let at = 2 * L + 30;
    assert!(!code_byte_positions(&bytes[2 * L..3 * L]).contains(&30));
    bytes[at] ^= 0x10;
    assert_ne!(bytes[at], 0);
    let (frames, errors, s, _) = decode(&bytes);
    assert_eq!(sequences(&frames), vec![0, 1, 3, 4, 5]);
    assert!(matches!(errors[..], [DecodeError::Crc { .. }]));
    assert_eq!(
        (s.crc_errors, s.malformed, s.sequence_gaps, s.frames_lost),
        (1, 0, 1, 1)
    );
    assert_eq!(s.bytes_skipped, L as u64);
}

/// Positions of the COBS code bytes in one encoded frame (delimiter included).
fn code_byte_positions(encoded: &[u8]) -> Vec<usize> {
    let mut positions = Vec::new();
    let mut at = 0;
    while at < encoded.len() - 1 {
        positions.push(at);
        at += encoded[at] as usize;
    }
    positions
}

#[test]
fn every_single_bit_flip_is_detected_and_counted_exactly() {
    let mut rng = SmallRng::seed_from_u64(11);
    for trial in 0..8u32 {
        // Frames A, B, C, D; every bit of B is flipped in turn.
        let base = rng.random::<u32>();
        let mut frames_in = Vec::new();
        for i in 0..4 {
            let mut f = frame(base.wrapping_add(i));
            f.accel = [rng.random(), rng.random(), rng.random()];
            f.flags = Flags::from_bits_retain(rng.random());
            frames_in.push(f);
        }
        let parts: Vec<Vec<u8>> = frames_in.iter().map(encoded).collect();
        let codes = code_byte_positions(&parts[1]);
        for bit in 0..L * 8 {
            let mut b = parts[1].clone();
            let at = bit / 8;
            b[at] ^= 1 << (bit % 8);
            let bytes = [
                parts[0].clone(),
                b.clone(),
                parts[2].clone(),
                parts[3].clone(),
            ]
            .concat();
            let (frames, errors, s, _) = decode(&bytes);
            let ctx = format!("trial {trial} bit {bit}");
            let got = sequences(&frames);
            if at == L - 1 {
                // The delimiter became data: B and C merge into one over-long frame.
                assert_eq!(got, vec![base, base.wrapping_add(3)], "{ctx}");
                assert_eq!((s.malformed, s.crc_errors), (1, 0), "{ctx}");
                assert_eq!((s.sequence_gaps, s.frames_lost), (1, 2), "{ctx}");
            } else {
                assert_eq!(
                    got,
                    vec![base, base.wrapping_add(2), base.wrapping_add(3)],
                    "{ctx}"
                );
                assert_eq!((s.sequence_gaps, s.frames_lost), (1, 1), "{ctx}");
                if b[at] == 0 {
                    // A new delimiter splits B; each non-empty piece is malformed.
                    let pieces = usize::from(at > 0) + usize::from(at < L - 2);
                    assert_eq!((s.malformed, s.crc_errors), (pieces as u64, 0), "{ctx}");
                } else if codes.contains(&at) {
                    // A code byte moves the implied zeros: one rejected frame.
                    assert_eq!(errors.len(), 1, "{ctx}");
                } else {
                    assert_eq!((s.malformed, s.crc_errors), (0, 1), "{ctx}");
                }
            }
            for f in &frames {
                let original = &frames_in[f.sequence.wrapping_sub(base) as usize];
                assert_eq!(
                    encoded(f),
                    encoded(original),
                    "{ctx}: altered frame accepted"
                );
            }
        }
    }
}

#[test]
fn sequence_wrap_around_is_not_a_gap() {
    let seqs = [u32::MAX - 2, u32::MAX - 1, u32::MAX, 0, 1, 2];
    let (frames, _, s, decoder) = decode(&stream(seqs));
    assert_eq!(sequences(&frames), seqs);
    assert_eq!(
        (s.sequence_gaps, s.frames_lost, s.sequence_restarts),
        (0, 0, 0)
    );
    assert_eq!(decoder.last_sequence(), Some(2));
    // A jump across the wrap is a gap of the right size.
    let (_, _, s, _) = decode(&stream([u32::MAX - 1, 1]));
    assert_eq!((s.sequence_gaps, s.frames_lost), (1, 2));
}

#[test]
fn gaps_count_events_and_missing_frames() {
    let (_, _, s, _) = decode(&stream([0, 1, 2, 5, 6, 7, 8, 10]));
    assert_eq!(
        (s.sequence_gaps, s.frames_lost, s.sequence_restarts),
        (2, 3, 0)
    );
}

#[test]
fn concatenated_recordings_count_a_restart_not_lost_frames() {
    let mut bytes = stream(100..110);
    bytes.extend(stream(0..10));
    let (frames, errors, s, _) = decode(&bytes);
    assert_eq!(frames.len(), 20);
    assert!(errors.is_empty());
    assert_eq!(
        (s.sequence_gaps, s.frames_lost, s.sequence_restarts),
        (0, 0, 1)
    );
    // A repeated frame (a duplicate) also goes backwards.
    let (_, _, s, _) = decode(&stream([3, 4, 4, 5]));
    assert_eq!(
        (s.sequence_gaps, s.frames_lost, s.sequence_restarts),
        (0, 0, 1)
    );
}

#[test]
fn extra_delimiters_are_skipped_bytes_not_errors() {
    let mut bytes = vec![0, 0, 0];
    bytes.extend(encoded(&frame(0)));
    bytes.extend([0, 0]);
    bytes.extend(encoded(&frame(1)));
    let (frames, errors, s, _) = decode(&bytes);
    assert_eq!(sequences(&frames), vec![0, 1]);
    assert!(errors.is_empty());
    assert_eq!(s.bytes_skipped, 5);
}

#[test]
fn unknown_version_with_good_crc_is_malformed() {
    let mut raw = frame(9).to_bytes();
    raw[0] = 3;
    let crc = triad::protocol::crc32c(&raw[..47]);
    raw[47..].copy_from_slice(&crc.to_le_bytes());
    let mut wire = vec![0u8; 60];
    let n = triad::protocol::cobs::stuff(&raw, &mut wire).unwrap();
    wire.truncate(n);
    wire.push(0);
    let mut bytes = encoded(&frame(8));
    bytes.extend(wire);
    bytes.extend(encoded(&frame(10)));
    let (frames, errors, s, _) = decode(&bytes);
    assert_eq!(sequences(&frames), vec![8, 10]);
    assert_eq!(errors, vec![DecodeError::Version { version: 3 }]);
    assert_eq!((s.malformed, s.crc_errors, s.frames_lost), (1, 0, 1));
}

#[test]
fn random_garbage_between_frames_never_costs_a_frame_that_follows_a_delimiter() {
    let mut rng = SmallRng::seed_from_u64(5);
    let mut bytes = Vec::new();
    let mut garbage_pieces = 0u64;
    for seq in 0..500u32 {
        let len = rng.random_range(0..80);
        let garbage: Vec<u8> = (0..len)
            .map(|_| {
                if rng.random_bool(0.05) {
                    0
                } else {
                    rng.random()
                }
            })
            .collect();
        // Non-empty pieces between delimiters; the last is closed by the 0 below.
        garbage_pieces += garbage.split(|&b| b == 0).filter(|p| !p.is_empty()).count() as u64;
        bytes.extend(&garbage);
        bytes.push(0);
        bytes.extend(encoded(&frame(seq)));
    }
    let (frames, _, s, _) = decode(&bytes);
    assert_eq!(sequences(&frames), (0..500).collect::<Vec<_>>());
    // The first piece came before any delimiter: skipped silently.
    let first_len = bytes.iter().position(|&b| b == 0).unwrap();
    let silent = u64::from(first_len > 0);
    assert_eq!(s.crc_errors + s.malformed, garbage_pieces - silent);
    assert_eq!((s.sequence_gaps, s.frames_lost), (0, 0));
}

#[test]
fn random_bit_errors_in_a_long_stream_lose_only_counted_frames() {
    let mut rng = SmallRng::seed_from_u64(99);
    let n = 3000u32;
    let mut bytes = stream(0..n);
    // The first and last frames stay intact: losses before the first good
    // frame or after the last one leave no gap to count.
    for _ in 0..400 {
        let at = rng.random_range(L..bytes.len() - L);
        bytes[at] ^= 1 << rng.random_range(0..8);
    }
    let (frames, _, s, _) = decode(&bytes);
    // Frames come out in order, each unaltered, and every missing one is
    // counted as lost.
    for w in frames.windows(2) {
        assert!(w[0].sequence < w[1].sequence);
    }
    for f in &frames {
        assert_eq!(*f, frame(f.sequence));
    }
    assert_eq!(s.frames + s.frames_lost, u64::from(n));
    assert_eq!(s.sequence_restarts, 0);
    assert!(s.crc_errors + s.malformed > 0);
}

#[test]
fn random_bytes_never_panic_and_are_fully_accounted() {
    let mut rng = SmallRng::seed_from_u64(1234);
    // A long run of uniform random bytes, then runs biased towards zeros and
    // towards 0xFF (long COBS blocks), fed in random-sized slices.
    let mut decoder = Decoder::new();
    let mut total = 0u64;
    for zero_share in [None, Some(0.02), Some(0.5)] {
        for _ in 0..200 {
            let len = rng.random_range(0..20_000);
            let chunk: Vec<u8> = (0..len)
                .map(|_| match zero_share {
                    None => rng.random(),
                    Some(p) if rng.random_bool(p) => 0,
                    Some(_) => {
                        if rng.random_bool(0.5) {
                            0xFF
                        } else {
                            rng.random()
                        }
                    }
                })
                .collect();
            total += chunk.len() as u64;
            for f in decoder.feed(&chunk).flatten() {
                // Only a CRC collision (p = 2⁻³² per candidate) gets here.
                assert_eq!(f, Frame::from_bytes(&f.to_bytes()).unwrap());
            }
        }
    }
    let s = decoder.stats();
    assert_eq!(s.bytes, total);
    assert_eq!(
        s.bytes,
        s.frames * L as u64 + s.bytes_skipped + decoder.pending_bytes()
    );
}

#[test]
fn device_counters_are_summed() {
    let mut bytes = Vec::new();
    for (seq, (overruns, dropped)) in [(0, (1, 0)), (1, (0, 3)), (2, (u16::MAX, u16::MAX))] {
        let mut f = frame(seq);
        f.overruns = overruns;
        f.dropped = dropped;
        bytes.extend(encoded(&f));
    }
    let (_, _, s, _) = decode(&bytes);
    assert_eq!(s.device_overruns, 1 + 65535);
    assert_eq!(s.device_dropped, 3 + 65535);
}

/// A device's decoder (`push_command`: a command read where it lies, no
/// packet copied) completes exactly what `push` completes, at the same
/// bytes, with the same rejections and counters: commands of every kind,
/// data frames, replies, damaged and cut packets, garbage.
#[test]
fn the_device_decoder_completes_what_push_completes() {
    use triad::protocol::{Command, Mode, Packet, Payload, Received, Reply, Status, MAX_WIRE_LEN};
    let mut rng = SmallRng::seed_from_u64(25);
    let mut bytes = Vec::new();
    for round in 0u16..400 {
        let command = match round % 6 {
            0 => Command::Identify,
            1 => Command::SetMode(Mode::Raw),
            2 => Command::SetDecimation(round),
            3 => Command::UploadChunk {
                offset: round,
                data: Payload::new(&[0, 7, 0, 9][..usize::from(round % 5).min(4)]).unwrap(),
            },
            4 => Command::ReadCalibration { offset: 0 },
            _ => Command::ResetCounters,
        };
        let mut wire = [0u8; MAX_WIRE_LEN];
        let n = command.to_packet(round).unwrap().to_wire(&mut wire);
        let mut packet = wire[..n].to_vec();
        match rng.random_range(0..8) {
            // A flipped bit (CRC error, or broken stuffing), a cut packet.
            0 => {
                let at = rng.random_range(0..packet.len());
                packet[at] ^= 1 << rng.random_range(0..8);
            }
            1 => packet.truncate(rng.random_range(0..packet.len())),
            _ => {}
        }
        bytes.extend(packet);
        match rng.random_range(0..4) {
            0 => bytes.extend(encoded(&frame(u32::from(round)))),
            1 => {
                let reply = Reply {
                    sequence: round,
                    command: 1,
                    status: Status::Ok,
                    payload: Payload::EMPTY,
                };
                let n = reply.to_wire(&mut wire).unwrap();
                bytes.extend(&wire[..n]);
            }
            2 => bytes.extend((0..rng.random_range(1..9)).map(|_| rng.random::<u8>())),
            _ => {}
        }
    }
    let (mut by_value, mut in_place) = (Decoder::new(), Decoder::new());
    let mut commands = 0;
    for &byte in &bytes {
        let expected = by_value.push(byte);
        let got = in_place.push_command(byte);
        match (expected, got) {
            (None, None) => {}
            (Some(expected), Some(got)) => {
                assert_eq!(got.bytes, by_value.last_packet_bytes());
                match (expected, got.decoded) {
                    (Ok(Packet::Command(c)), Ok(Received::Command(r))) => {
                        assert_eq!(c.as_ref(), r);
                        commands += 1;
                    }
                    (Ok(Packet::Command(c)), other) => panic!("{c:?} came as {other:?}"),
                    (Ok(_), Ok(Received::Other)) => {}
                    (Err(e), Err(g)) => assert_eq!(e, g),
                    (e, g) => panic!("push gave {e:?}, push_command {g:?}"),
                }
            }
            (e, g) => panic!("push gave {e:?}, push_command {:?}", g.map(|g| g.decoded)),
        }
    }
    assert_eq!(by_value.stats(), in_place.stats());
    assert!(commands > 200, "{commands} commands");
    assert!(by_value.stats().crc_errors > 0 && by_value.stats().malformed > 0);
}
