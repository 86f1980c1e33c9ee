//! Property tests of the parsers that take bytes from outside (issue 26):
//! COBS, the stream decoder (every packet type), the calibration blob. Any
//! input, valid packets damaged at random included: no panic, and the
//! invariants hold after each input (the decoder's byte accounting
//! balances; what decodes re-encodes to itself). Sized for `cargo xtask
//! test` (a few hundred cases each, well under a second); the long run of
//! 10⁷ inputs per parser is the benchmark's (fuzz/examples/bench_fuzz.rs, with AFL++ on
//! fuzz/'s targets).

use proptest::collection::vec;
use proptest::prelude::*;
use triad::model::blob::{self, BLOB_LEN};
use triad::protocol::cobs::{stuff, Unstuffer};
use triad::protocol::{encode, Decoder, Flags, Frame, MAX_ENCODED_LEN};
use triad::protocol::{Command, Packet, Payload, Reply, Status};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 300,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// A valid data frame on the wire, from arbitrary field values.
fn data_frame() -> impl Strategy<Value = Vec<u8>> {
    (any::<u32>(), any::<u32>(), any::<u16>(), any::<[u32; 7]>()).prop_map(
        |(sequence, timestamp_us, overruns, values)| {
            let v = values.map(f32::from_bits);
            let frame = Frame {
                sequence,
                timestamp_us,
                flags: Flags::empty(),
                overruns,
                dropped: 0,
                calibration_id: 7,
                accel: [v[0], v[1], v[2]],
                gyro: [v[3], v[4], v[5]],
                temperature: v[6],
            };
            let mut out = [0u8; MAX_ENCODED_LEN];
            let n = encode(&frame, &mut out);
            out[..n].to_vec()
        },
    )
}

/// A valid reply or command on the wire.
fn message() -> impl Strategy<Value = Vec<u8>> {
    (any::<u16>(), vec(any::<u8>(), 0..=230), any::<bool>()).prop_map(|(sequence, bytes, reply)| {
        let packet = if reply {
            Reply {
                sequence,
                command: 1,
                status: Status::Ok,
                payload: Payload::new(&bytes).unwrap(),
            }
            .to_packet()
            .unwrap()
        } else {
            let data = Payload::new(&bytes[..bytes.len().min(128)]).unwrap();
            Command::UploadChunk { offset: 0, data }
                .to_packet(sequence)
                .unwrap()
        };
        let mut wire = vec![0u8; triad::protocol::MAX_WIRE_LEN];
        let n = packet.to_wire(&mut wire[..].try_into().unwrap());
        wire.truncate(n);
        wire
    })
}

/// A stream: valid packets, garbage, and damage (flipped bits, lost bytes).
fn stream() -> impl Strategy<Value = Vec<u8>> {
    let piece = prop_oneof![
        4 => data_frame(),
        2 => message(),
        1 => vec(any::<u8>(), 0..80),
    ];
    (vec(piece, 0..12), vec((any::<usize>(), any::<u8>()), 0..4)).prop_map(|(pieces, damage)| {
        let mut bytes: Vec<u8> = pieces.concat();
        for (at, bit) in damage {
            if !bytes.is_empty() {
                let i = at % bytes.len();
                match bit % 3 {
                    0 => bytes[i] ^= 1 << (bit % 8),
                    1 => {
                        bytes.remove(i);
                    }
                    _ => bytes[i] = 0,
                }
            }
        }
        bytes
    })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn cobs_round_trips_and_never_sends_a_zero(data in vec(any::<u8>(), 0..=400)) {
        let mut wire = vec![0u8; data.len() + data.len() / 254 + 2];
        let n = stuff(&data, &mut wire).unwrap();
        prop_assert!(!wire[..n].contains(&0));
        let mut unstuffer = Unstuffer::new();
        let back: Vec<u8> = wire[..n].iter().filter_map(|&b| unstuffer.push(b)).collect();
        prop_assert!(unstuffer.finish().is_ok());
        prop_assert_eq!(back, data);
    }

    #[test]
    fn the_unstuffer_takes_any_bytes(bytes in vec(any::<u8>(), 0..600)) {
        let mut unstuffer = Unstuffer::new();
        for b in bytes {
            if b == 0 {
                let _ = unstuffer.finish();
            } else {
                let _ = unstuffer.push(b);
            }
        }
    }

    #[test]
    fn the_decoders_byte_accounting_balances(bytes in stream(), cut in any::<usize>()) {
        // Fed in two slices at an arbitrary point, as reads arrive.
        let cut = if bytes.is_empty() { 0 } else { cut % bytes.len() };
        let mut decoder = Decoder::new();
        let mut good = 0u64;
        for part in [&bytes[..cut], &bytes[cut..]] {
            // Errors are counted by the decoder (checked below).
            for packet in decoder.feed_packets(part).flatten() {
                good += 1;
                // What decodes re-encodes to the bytes it came from.
                if let Packet::Data(frame) = packet {
                    let mut out = [0u8; MAX_ENCODED_LEN];
                    let n = encode(&frame, &mut out);
                    prop_assert!(bytes.windows(n).any(|w| w == &out[..n]));
                }
            }
        }
        let s = decoder.stats();
        prop_assert_eq!(s.bytes, bytes.len() as u64);
        prop_assert_eq!(s.bytes, s.packet_bytes + s.bytes_skipped + decoder.pending_bytes());
        prop_assert_eq!(good, s.frames + s.messages);
        prop_assert_eq!(s.raw_frames + s.batch_frames, 0);
    }

    #[test]
    fn any_packet_bytes_parse_or_are_refused(bytes in vec(any::<u8>(), 0..=260)) {
        let _ = Packet::parse(&bytes);
    }

    #[test]
    fn a_blob_is_read_whole_or_refused(seed in vec(any::<u8>(), BLOB_LEN..=BLOB_LEN),
                                        valid in any::<bool>(), flips in vec(any::<u16>(), 0..3)) {
        let mut bytes = seed;
        if valid {
            // A well-framed blob of arbitrary values (magic, version, CRC right).
            bytes[..4].copy_from_slice(&blob::MAGIC);
            bytes[4] = blob::VERSION;
            bytes[5] &= 7;
            bytes[6] = 0;
            bytes[7] = 0;
            let crc = triad::protocol::crc32c(&bytes[..BLOB_LEN - 4]);
            bytes[BLOB_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        }
        for f in flips {
            bytes[usize::from(f) % BLOB_LEN] ^= 1 << (f % 8);
        }
        if let Ok(cal) = blob::decode(&bytes) {
            // Decoded values re-encode to a blob that decodes to the same.
            let again = blob::decode(&blob::encode(&cal)).unwrap();
            prop_assert_eq!(format!("{again:?}"), format!("{cal:?}"));
        }
        prop_assert!(blob::decode(&bytes[..BLOB_LEN - 1]).is_err());
    }
}
