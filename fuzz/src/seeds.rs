//! The seeds: valid examples of each target's input, under fuzz/seeds/NAME
//! (AFL++ starts from them, the mutation run mutates them, the tests run
//! every target over them). The files of the binary formats are made here,
//! from the project's own encoders ([`examples`]); a test checks that the
//! files are what these make (`TRIAD_FUZZ_WRITE_SEEDS=1 cargo test -p
//! triad-fuzz` writes them anew after a format changed).

use std::path::{Path, PathBuf};

use triad::model::blob;
use triad::protocol::{
    crc32c, encode, Command, Flags, Frame, Mode, PacketBuf, Payload, RawFrame, Reply, Status,
    CHUNK_LEN, MAX_ENCODED_LEN, MAX_WIRE_LEN,
};

use crate::targets::command_path::built_in;

/// fuzz/seeds.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds")
}

/// Seeds: each file's name and bytes.
pub type Seeds = Vec<(String, Vec<u8>)>;

/// The seeds of directory `name` under fuzz/seeds, sorted by file name.
pub fn read(name: &str) -> Seeds {
    let dir = root().join(name);
    let mut seeds: Seeds = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("the seeds {}: {e}", dir.display()))
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p.file_name().unwrap().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    seeds.sort();
    seeds
}

/// Wire bytes of `packet` (stuffed, delimited).
fn wire(packet: &PacketBuf) -> Vec<u8> {
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = packet.to_wire(&mut out);
    out[..n].to_vec()
}

/// A command on the wire with sequence number `sequence`.
fn command(c: &Command, sequence: u16) -> Vec<u8> {
    wire(&c.to_packet(sequence).expect("a valid command packs"))
}

/// An upload of the built-in calibration (its chunks and the commit), from
/// sequence number `first`.
fn upload(first: u16) -> Vec<u8> {
    let blob = built_in();
    let mut bytes = Vec::new();
    for (i, chunk) in blob.chunks(CHUNK_LEN).enumerate() {
        let data = Payload::new(chunk).expect("a chunk fits a payload");
        let c = Command::UploadChunk {
            offset: (i * CHUNK_LEN) as u16,
            data,
        };
        bytes.extend(command(&c, first + i as u16));
    }
    let commit = Command::UploadCommit {
        len: blob::BLOB_LEN as u16,
        crc: crc32c(blob),
    };
    bytes.extend(command(&commit, first + 4));
    bytes
}

/// Each command a host sends, named.
fn commands() -> Vec<(&'static str, Vec<u8>)> {
    let chunk = Payload::new(&built_in()[..CHUNK_LEN]).expect("a chunk fits a payload");
    vec![
        ("identify", command(&Command::Identify, 1)),
        ("set_mode", command(&Command::SetMode(Mode::Raw), 2)),
        ("set_decimation", command(&Command::SetDecimation(4), 3)),
        (
            "upload_chunk",
            command(
                &Command::UploadChunk {
                    offset: 0,
                    data: chunk,
                },
                4,
            ),
        ),
        (
            "upload_commit",
            command(&Command::UploadCommit { len: 512, crc: 7 }, 5),
        ),
        (
            "read_calibration",
            command(&Command::ReadCalibration { offset: 128 }, 6),
        ),
        ("save", command(&Command::Save, 7)),
        ("erase", command(&Command::Erase, 8)),
        ("reset_counters", command(&Command::ResetCounters, 9)),
        ("self_test", command(&Command::SelfTest, 10)),
    ]
}

/// What a device sends: a reply, a raw frame, a version-1 data frame.
fn device_packets() -> Vec<(&'static str, Vec<u8>)> {
    let reply = Reply {
        sequence: 3,
        command: 3,
        status: Status::BadArgument,
        payload: Payload::new(b"command 0x03: decimation must be at least 1")
            .expect("a short reason"),
    };
    let frame = Frame {
        sequence: 42,
        timestamp_us: 1_000_000,
        flags: Flags::empty(),
        overruns: 0,
        dropped: 0,
        calibration_id: 0x1234_5678,
        accel: [0.5, -0.25, 9.80665],
        gyro: [0.0, 0.001, -0.0175],
        temperature: 25.0,
    };
    let mut out = [0u8; MAX_ENCODED_LEN];
    let n = encode(&frame, &mut out);
    vec![
        ("reply", wire(&reply.to_packet().expect("a reply packs"))),
        (
            "raw_frame",
            wire(&RawFrame::default().to_packet().expect("a raw frame packs")),
        ),
        ("data_frame", out[..n].to_vec()),
    ]
}

/// The seeds each target but the record readers' starts from, by
/// directory name under fuzz/seeds, each file's name and bytes (the record
/// readers' seeds are files from elsewhere: see seeds/README.md).
pub fn examples() -> Vec<(&'static str, Seeds)> {
    let named = |list: Vec<(&str, Vec<u8>)>| -> Seeds {
        list.into_iter()
            .map(|(n, b)| (format!("{n}.bin"), b))
            .collect()
    };
    let mut host_sends = commands();
    host_sends.push(("upload", upload(100)));
    let mut session = upload(200);
    for (i, c) in [
        Command::Save,
        Command::Identify,
        Command::Erase,
        Command::ResetCounters,
    ]
    .iter()
    .enumerate()
    {
        session.extend(command(c, 300 + i as u16));
    }
    host_sends.push(("upload_save_erase_reset", session));
    // A stream: a device's packets several in a row, each kind first once.
    let on_line: Vec<(&str, Vec<u8>)> = device_packets().into_iter().chain(commands()).collect();
    let streams = (0..on_line.len())
        .map(|i| {
            let bytes = (0..4)
                .flat_map(|k| on_line[(i + k) % on_line.len()].1.clone())
                .collect();
            (on_line[i].0, bytes)
        })
        .collect();
    // COBS: stuffed packets as on the line (their delimiters too).
    let stuffed = device_packets()
        .into_iter()
        .chain(commands().into_iter().take(4))
        .collect();
    let calibrations = vec![
        (
            "realistic",
            blob::encode(&triad_bench::inputs::realistic()).to_vec(),
        ),
        (
            "temperature_terms",
            blob::encode(&triad_bench::inputs::with_temperature_terms()).to_vec(),
        ),
    ];
    let scenes = ["static-bench", "tumble-6"]
        .into_iter()
        .map(|name| {
            use triad_sim::scenes::scene_blob::{encode, MAX_BLOB_LEN};
            let loaded = triad_host::scene_file::load(name).expect("a shipped scene");
            let mut out = [0u8; MAX_BLOB_LEN];
            let n = encode(&loaded.scene, 1, &mut out).expect("a shipped scene packs");
            (name, out[..n].to_vec())
        })
        .collect();
    vec![
        ("commands", named(host_sends)),
        ("stream", named(streams)),
        ("cobs", named(stuffed)),
        ("calibration_blob", named(calibrations)),
        ("scene_blob", named(scenes)),
        ("calibration_toml", calibration_files()),
    ]
}

/// The shipped calibration files (calibrations/), the TOML target's seeds.
fn calibration_files() -> Seeds {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../calibrations");
    ["default.toml", "lab-example.toml"]
        .iter()
        .map(|f| {
            let bytes = std::fs::read(dir.join(f)).expect("a shipped calibration file");
            (f.to_string(), bytes)
        })
        .collect()
}
