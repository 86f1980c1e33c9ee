//! Every target over its seeds (the files under fuzz/seeds, which must be
//! what `triad_fuzz::seeds::examples` makes from the project's encoders)
//! and their cuts: no broken invariant, and the valid examples accepted.
//! Then the invariants themselves: each says no when it should.

use triad_fuzz::invariants::{self, DeviceState};
use triad_fuzz::seeds;
use triad_fuzz::Broken;

type Target = fn(&[u8]) -> Result<u64, Broken>;

/// Each target and its seed directory.
const TARGETS: [(&str, Target); 6] = [
    ("commands", triad_fuzz::command_path),
    ("stream", triad_fuzz::stream_decoder),
    ("cobs", triad_fuzz::cobs),
    ("calibration_blob", triad_fuzz::calibration_blob),
    ("scene_blob", triad_fuzz::scene_blob),
    ("calibration_toml", triad_fuzz::calibration_toml),
];

/// The seed files are the examples the encoders make today (or are
/// written, with TRIAD_FUZZ_WRITE_SEEDS=1).
#[test]
fn the_seed_files_are_the_encoders_examples() {
    let write = std::env::var_os("TRIAD_FUZZ_WRITE_SEEDS").is_some();
    for (dir, examples) in seeds::examples() {
        let path = seeds::root().join(dir);
        if write {
            let _ = std::fs::remove_dir_all(&path);
            std::fs::create_dir_all(&path).unwrap();
            for (name, bytes) in &examples {
                std::fs::write(path.join(name), bytes).unwrap();
            }
        }
        let mut want = examples.clone();
        want.sort();
        assert_eq!(
            seeds::read(dir),
            want,
            "fuzz/seeds/{dir} is not what the encoders make: \
             TRIAD_FUZZ_WRITE_SEEDS=1 cargo test -p triad-fuzz writes it anew"
        );
    }
}

/// What each seed gives: every one accepted, but the self-test (the
/// firmware runs it and replies; the handler alone carries out nothing)
/// and a commit with nothing uploaded (refused: the refusal's path);
/// a stream seed is four good packets; a COBS seed one delimited frame.
fn expected(dir: &str, name: &str) -> u64 {
    // An upload: its chunks and the commit.
    let upload = triad::model::blob::BLOB_LEN.div_ceil(triad::protocol::CHUNK_LEN) as u64 + 1;
    match (dir, name) {
        ("commands", "self_test.bin" | "upload_commit.bin") => 0,
        ("commands", "upload.bin") => upload,
        ("commands", "upload_save_erase_reset.bin") => upload + 4,
        ("stream", _) => 4,
        _ => 1,
    }
}

#[test]
fn every_target_accepts_its_seeds_and_survives_their_cuts() {
    for (dir, target) in TARGETS {
        let seeds = seeds::read(dir);
        assert!(!seeds.is_empty(), "no seeds in fuzz/seeds/{dir}");
        for (name, bytes) in &seeds {
            assert_eq!(
                target(bytes),
                Ok(expected(dir, name)),
                "{dir}/{name} as a whole"
            );
            for keep in [bytes.len() * 2 / 3, bytes.len() / 3, 17, 5, 1, 0] {
                let cut = &bytes[..keep.min(bytes.len())];
                if let Err(broken) = target(cut) {
                    panic!("{dir}/{name} cut to {keep} bytes: {broken}");
                }
            }
        }
    }
}

/// The recording readers over their seeds (valid files of each format,
/// and their cuts): no broken invariant, and each whole seed read to its
/// samples (the ULog seed is a cut file, read up to its cut).
#[test]
fn the_record_readers_read_their_seeds_and_survive_their_cuts() {
    let mut read = Vec::new();
    for (name, bytes) in seeds::read("record") {
        if !name.ends_with(".ulg") {
            read.push((name.clone(), triad_fuzz::record(&bytes)));
        }
        for keep in [bytes.len() * 2 / 3, bytes.len() / 3, 17, 0] {
            for (target, verdict) in [
                ("record", triad_fuzz::record(&bytes[..keep])),
                ("triad_csv", triad_fuzz::triad_csv(&bytes[..keep])),
            ] {
                if let Err(broken) = verdict {
                    panic!("{target} on record/{name} cut to {keep} bytes: {broken}");
                }
            }
        }
    }
    read.sort_by(|a, b| a.0.cmp(&b.0));
    let want: Vec<(String, Result<u64, Broken>)> = [
        ("euroc3.csv", 3),
        ("imu.bag", 200),
        ("imu.db3", 200),
        ("imu20.csv", 20),
        ("imu20.mcap", 20),
        ("imu_tk3.txt", 3),
    ]
    .iter()
    .map(|(n, k)| (n.to_string(), Ok(*k)))
    .collect();
    assert_eq!(read, want);
}

/// The MCAP on which AFL++ found the mcap crate's overflow (fuzz/findings)
/// no longer reaches the library's bug (triad walks its chunks itself): a
/// clear error, every invariant holding, no sample read.
#[test]
fn the_mcap_finding_is_a_clear_error_to_the_record_target() {
    let findings = seeds::root().join("../findings");
    let bytes = std::fs::read(findings.join("mcap_scan_subtract_overflow.mcap")).unwrap();
    for verdict in [triad_fuzz::record(&bytes), triad_fuzz::triad_csv(&bytes)] {
        assert_eq!(verdict.map_err(|b| b.0), Ok(0));
    }
}

/// The ULogs px4-ulog 0.6.1 panics on (AFL++'s finding) or spends minutes
/// and tens of GiB on (two made from reading its code: its flattening of
/// the formats) are refused by triad's checks before the library sees
/// them: no panic, an error naming the file, nothing read.
#[test]
fn the_ulog_findings_are_refused_before_the_library_sees_them() {
    let findings = seeds::root().join("../findings");
    for name in [
        "ulog_header_slice_out_of_range.ulg",
        "ulog_flatten_empty_format_arrays.ulg",
        "ulog_flatten_nested_long_names.ulg",
    ] {
        let bytes = std::fs::read(findings.join(name)).unwrap();
        for verdict in [triad_fuzz::record(&bytes), triad_fuzz::triad_csv(&bytes)] {
            assert_eq!(verdict, Ok(0), "{name}");
        }
    }
}

/// A corrupted upload (one byte of a chunk flipped, so the commit's CRC
/// fails) is refused and the device is as before: the invariant holds and
/// nothing was accepted past the chunks.
#[test]
fn a_corrupted_upload_is_refused_and_holds() {
    let seeds = seeds::read("commands");
    let (_, upload) = seeds.iter().find(|(n, _)| n == "upload.bin").unwrap();
    let mut corrupted = upload.clone();
    // A data byte of the first chunk (past its packet header), not a zero.
    let at = (20..corrupted.len())
        .find(|&i| corrupted[i] != 0 && corrupted[i] != 0xFF)
        .unwrap();
    corrupted[at] ^= 0x01;
    let accepted = triad_fuzz::command_path(&corrupted).unwrap();
    assert!(accepted < 5, "the corrupted upload was accepted whole");
}

fn state(id: u32, writes: u32) -> DeviceState {
    DeviceState {
        active: (None, id, triad::protocol::CalibrationSource::None),
        stored: triad::protocol::StoredState::Empty,
        flash_ops: (writes, 0),
    }
}

/// Each invariant says no to what breaks it.
#[test]
fn the_invariants_can_fail() {
    use triad::protocol::{Payload, Reply, Status};
    let refused = Reply {
        sequence: 1,
        command: 0x05,
        status: Status::BadCrc,
        payload: Payload::new(b"calibration CRC").unwrap(),
    };
    assert!(invariants::refused_changes_nothing(&refused, &state(1, 0), &state(1, 0)).is_ok());
    assert!(invariants::refused_changes_nothing(&refused, &state(1, 0), &state(2, 0)).is_err());
    assert!(invariants::refused_changes_nothing(&refused, &state(1, 0), &state(1, 1)).is_err());
    let ok = Reply {
        status: Status::Ok,
        ..refused
    };
    assert!(invariants::refused_changes_nothing(&ok, &state(1, 0), &state(2, 1)).is_ok());
    assert!(invariants::counters_add_up(3, 1, 2, 1).is_ok());
    assert!(invariants::counters_add_up(3, 1, 3, 1).is_err());
    assert!(invariants::counters_add_up(3, 0, 2, 1).is_err());
    assert!(invariants::one_reply_per_packet(2, 1).is_err());
    let stats = triad::protocol::DecoderStats {
        bytes: 10,
        packet_bytes: 6,
        bytes_skipped: 3,
        ..Default::default()
    };
    assert!(invariants::byte_accounting_balances(&stats, 10, 1).is_ok());
    assert!(invariants::byte_accounting_balances(&stats, 10, 0).is_err());
    assert!(invariants::byte_accounting_balances(&stats, 11, 1).is_err());
    assert!(invariants::good_packets_counted_once(&stats, 1).is_err());
    assert!(invariants::errors_counted_once(&stats, 1).is_err());
    assert!(invariants::stuffing_undoes(&[1, 0], &[2, 1, 1], 3, Some(&[1, 0])).is_ok());
    assert!(invariants::stuffing_undoes(&[1, 0], &[2, 1, 0], 3, Some(&[1, 0])).is_err());
    assert!(invariants::stuffing_undoes(&[1, 0], &[2, 1, 1], 3, None).is_err());
    assert!(invariants::stuffers_agree(&[1], &[&[2, 1], &[2, 2]]).is_err());
    assert!(invariants::reencodes_to_itself("x", &[1], &[2]).is_err());
    assert!(invariants::error_has_message(" ").is_err());
    assert!(invariants::chunk_has_samples(0).is_err());
    assert!(invariants::sample_time_finite(f64::NAN).is_err());
    assert!(invariants::sample_time_finite(f64::INFINITY).is_err());
    assert!(invariants::places_increase(3, 3).is_err());
    assert!(invariants::places_increase(4, 3).is_ok());
    assert!(invariants::error_names_file("a.csv: line 2: bad", "b.csv").is_err());
    let panicked = format!(
        "a.csv: {}, so it cannot be read",
        triad_host::record::producer::LIBRARY_FAILED
    );
    assert!(invariants::no_library_panic(&panicked).is_err());
    assert!(invariants::no_library_panic("a.csv: line 2: no number").is_ok());
}
