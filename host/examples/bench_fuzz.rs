//! The long mutation run of every parser that takes outside bytes (issue
//! 26): figures, not pass/fail. `cargo xtask bench` runs it; alone:
//!
//!     cargo run --release -p triad-host --example bench_fuzz [-- INPUTS]
//!
//! INPUTS per parser (default 10⁷), each a valid example (seed) mutated at
//! random (bits flipped, bytes set, inserted, deleted, a run duplicated,
//! the input cut, two seeds spliced, a 0x00 put in) with its CRC fixed up
//! half the time so the mutation reaches past the checksum. After each
//! input the parser's invariants are checked:
//!
//! - stream decoder: the byte accounting balances (bytes = good packets'
//!   bytes + skipped + pending), every good packet counted once;
//! - device command path (decoder and handler, RAM flash): at most one
//!   reply per packet, a refused command leaves the calibration in force,
//!   the counters `identify` reports add up;
//! - calibration blob, scene blob: what decodes re-encodes to the same;
//! - calibration TOML (`triad calib` files): parsed or refused with an error.
//!
//! Printed per parser: inputs, time, inputs/s, the slowest input (the
//! shorter of two timings when it passed 100 ms: the machine may be
//! shared), panics (a panic prints the input and aborts the run: the
//! release profile aborts on panic, so a finished run had none), hangs
//! (inputs slower than 100 ms twice) and broken invariants. coverage-guided fuzzing (cargo-fuzz,
//! libFuzzer) needs a nightly compiler's sanitizers; this stable-toolchain
//! run is random mutation.

use std::path::Path;
use std::time::{Duration, Instant};

use triad::device::{
    ActiveCalibration, CalibrationStore, CommandHandler, DeviceFacts, Handled, SharedCounters,
};
use triad::model::{blob, Orientation};
use triad::protocol::{crc32c, encode, Decoder, Flags, Frame, MAX_ENCODED_LEN};
use triad::protocol::{
    CalibrationSource, Command, Packet, PacketBuf, Payload, RawFrame, Reply, Status, StoredState,
    MAX_WIRE_LEN,
};
use triad_bench::ram_flash::{RamFlash, ERASE_SIZE};

/// An input slower than this is counted as a hang.
const HANG: Duration = Duration::from_millis(100);

/// xorshift64*: the mutations' randomness, seeded per parser.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// `seed` mutated 1 to 4 times (`other`: a second seed to splice in).
fn mutate(rng: &mut Rng, seed: &[u8], other: &[u8], out: &mut Vec<u8>) {
    out.clear();
    out.extend_from_slice(seed);
    for _ in 0..1 + rng.below(4) {
        let len = out.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                out[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                out[i] = rng.next() as u8;
            }
            2 => {
                let i = rng.below(len + 1);
                out.insert(i, rng.next() as u8);
            }
            3 if len > 0 => {
                out.remove(rng.below(len));
            }
            4 if len > 0 => {
                let from = rng.below(len);
                let to = (from + 1 + rng.below(16)).min(len);
                let run = out[from..to].to_vec();
                let at = rng.below(len + 1);
                out.splice(at..at, run);
            }
            5 => out.truncate(rng.below(len + 1)),
            6 if !other.is_empty() => {
                let cut = rng.below(len + 1);
                let from = rng.below(other.len());
                out.truncate(cut);
                out.extend_from_slice(&other[from..]);
            }
            _ if len > 0 => {
                let i = rng.below(len);
                out[i] = 0;
            }
            _ => out.push(rng.next() as u8),
        }
    }
}

/// One parser's run.
#[derive(Default)]
struct Tally {
    inputs: u64,
    slowest: Duration,
    hangs: u64,
    broken: u64,
    accepted: u64,
    first_broken: Option<String>,
}

impl Tally {
    fn broke(&mut self, what: impl FnOnce() -> String) {
        self.broken += 1;
        if self.first_broken.is_none() {
            self.first_broken = Some(what());
        }
    }
}

/// Runs `check` on `inputs` mutations of `seeds` (CRC fixed up half the
/// time by `reseal`); prints the figures.
fn run(
    name: &str,
    inputs: u64,
    seeds: &[Vec<u8>],
    reseal: fn(&mut [u8]),
    mut check: impl FnMut(&[u8], &mut Tally),
) {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ crc32c(name.as_bytes()) as u64);
    let mut tally = Tally::default();
    let mut input = Vec::new();
    let start = Instant::now();
    for _ in 0..inputs {
        let seed = &seeds[rng.below(seeds.len())];
        let other = &seeds[rng.below(seeds.len())];
        mutate(&mut rng, seed, other, &mut input);
        if rng.next() & 1 == 0 {
            reseal(&mut input);
        }
        CURRENT.with(|c| c.replace(input.clone()));
        let t = Instant::now();
        check(&input, &mut tally);
        let mut took = t.elapsed();
        if took > HANG {
            // The machine is shared: an input is slow when it is slow twice
            // (the parsers are deterministic), not when the process was
            // preempted once.
            let again = Instant::now();
            check(&input, &mut Tally::default());
            took = took.min(again.elapsed());
            if took > HANG {
                tally.hangs += 1;
            }
        }
        tally.slowest = tally.slowest.max(took);
        tally.inputs += 1;
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{name:<22} {:>9} inputs  {secs:>7.1} s  {:>9.0} /s  slowest {:>8.1} µs  accepted {:>9}  panics 0  hangs {}  broken invariants {}{}",
        tally.inputs,
        tally.inputs as f64 / secs,
        tally.slowest.as_secs_f64() * 1e6,
        tally.accepted,
        tally.hangs,
        tally.broken,
        tally
            .first_broken
            .map(|w| format!(" (first: {w})"))
            .unwrap_or_default()
    );
}

thread_local! {
    /// The input being checked, for the panic hook.
    static CURRENT: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Fixes up a packet's trailing CRC-32C (what a version-2 packet or the
/// calibration blob ends with) over everything before it.
fn reseal_tail(bytes: &mut [u8]) {
    if bytes.len() >= 5 {
        let n = bytes.len() - 4;
        let crc = crc32c(&bytes[..n]);
        bytes[n..].copy_from_slice(&crc.to_le_bytes());
    }
}

fn leave(_: &mut [u8]) {}

/// Wire bytes of `packet`.
fn wire(packet: &PacketBuf) -> Vec<u8> {
    let mut out = [0u8; MAX_WIRE_LEN];
    let n = packet.to_wire(&mut out);
    out[..n].to_vec()
}

/// Valid packets of each kind, unstuffed and on the wire.
fn packet_seeds() -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let mut packets: Vec<PacketBuf> = Vec::new();
    let commands = [
        Command::Identify,
        Command::SetMode(triad::protocol::Mode::Raw),
        Command::SetDecimation(4),
        Command::UploadChunk {
            offset: 0,
            data: Payload::new(&blob::encode(&triad::model::Calibration::identity(3))[..128])
                .unwrap(),
        },
        Command::UploadCommit { len: 512, crc: 7 },
        Command::ReadCalibration { offset: 128 },
        Command::Save,
        Command::Erase,
        Command::ResetCounters,
    ];
    for (i, c) in commands.iter().enumerate() {
        packets.push(c.to_packet(i as u16).unwrap());
    }
    let reply = Reply {
        sequence: 3,
        command: 1,
        status: Status::BadArgument,
        payload: Payload::new(b"command 0x03: decimation must be at least 1").unwrap(),
    };
    packets.push(reply.to_packet().unwrap());
    packets.push(RawFrame::default().to_packet().unwrap());
    let unstuffed = packets.iter().map(|p| p.as_bytes().to_vec()).collect();
    let mut on_wire: Vec<Vec<u8>> = packets.iter().map(wire).collect();
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
    on_wire.push(out[..n].to_vec());
    (unstuffed, on_wire)
}

fn stream_decoder(inputs: u64, on_wire: &[Vec<u8>]) {
    // Seeds: a few packets in a row, as a stream carries them.
    let seeds: Vec<Vec<u8>> = (0..on_wire.len())
        .map(|i| {
            (0..4)
                .flat_map(|k| on_wire[(i + k) % on_wire.len()].clone())
                .collect()
        })
        .collect();
    run("stream decoder", inputs, &seeds, leave, |bytes, tally| {
        let mut decoder = Decoder::new();
        let mut good = 0u64;
        for item in decoder.feed_packets(bytes) {
            good += u64::from(item.is_ok());
        }
        let s = decoder.stats();
        tally.accepted += good;
        let counted = s.frames + s.raw_frames + s.batch_frames + s.messages;
        if s.bytes != bytes.len() as u64
            || s.bytes != s.packet_bytes + s.bytes_skipped + decoder.pending_bytes()
            || good != counted
        {
            tally.broke(|| format!("{s:?} for {bytes:02x?}"));
        }
    });
}

/// A device over a RAM flash, its built-in calibration `built_in`.
fn device(built_in: [u8; blob::BLOB_LEN]) -> CommandHandler<RamFlash> {
    let store = CalibrationStore::new(RamFlash::new(), 0, ERASE_SIZE as u32).unwrap();
    let facts = DeviceFacts {
        firmware: "0.1.0",
        board: "fuzz",
        chip: "icm42688",
        bus: "spi",
        sample_rate_hz: 1000.0,
        baud: 921_600,
        scale: triad_bench::inputs::scale(),
        orientation: Orientation::RotationNone,
        cycles_hz: 84_000_000,
    };
    let active = ActiveCalibration {
        blob: Some(built_in),
        id: 0x0B11_7100,
        source: CalibrationSource::BuiltIn,
    };
    CommandHandler::new(facts, active, 1, Some(store), StoredState::Empty)
}

fn command_path(inputs: u64, on_wire: &[Vec<u8>]) {
    let mut cal = triad_bench::inputs::realistic();
    cal.id = 0x0B11_7100;
    let built_in = blob::encode(&cal);
    // Seeds: an upload of the calibration (chunks and commit) and each command.
    let mut seeds: Vec<Vec<u8>> = on_wire.to_vec();
    let mut upload = Vec::new();
    for (i, chunk) in built_in.chunks(128).enumerate() {
        let data = Payload::new(chunk).unwrap();
        let c = Command::UploadChunk {
            offset: (i * 128) as u16,
            data,
        };
        upload.extend(wire(&c.to_packet(100 + i as u16).unwrap()));
    }
    let commit = Command::UploadCommit {
        len: 512,
        crc: crc32c(&built_in),
    };
    upload.extend(wire(&commit.to_packet(104).unwrap()));
    seeds.push(upload);
    let counters = SharedCounters::new();
    run(
        "device command path",
        inputs,
        &seeds,
        leave,
        |bytes, tally| {
            let mut handler = device(built_in);
            let mut decoder = Decoder::new();
            decoder.push(0);
            let (mut replies, mut errors, mut delimiters) = (0u32, 0u32, 0u32);
            let mut since_reset = None;
            // The last command handled (its number and CRC): the same again is
            // a retry, answered but not applied (a reset does not reset twice).
            let mut last_command = None;
            for &b in bytes {
                delimiters += u32::from(b == 0);
                let Some(decoded) = decoder.push(b) else {
                    continue;
                };
                let before = handler.active().clone();
                let key = match &decoded {
                    Ok(Packet::Command(p)) => {
                        let raw = decoder.last_packet_bytes();
                        Some((p.sequence, raw[raw.len().saturating_sub(4)..].to_vec()))
                    }
                    _ => None,
                };
                let retry = key.is_some() && key == last_command;
                if key.is_some() {
                    last_command = key;
                }
                let handled = handler.on_packet(
                    &decoded,
                    decoder.last_packet_bytes(),
                    &counters,
                    &mut |_| true,
                );
                match handled {
                    Handled::Reply(reply) => {
                        replies += 1;
                        if reply.status != Status::Ok {
                            errors += 1;
                            let after = handler.active();
                            if after.blob != before.blob || after.id != before.id {
                                tally
                                    .broke(|| format!("refused {reply:?} changed the calibration"));
                            }
                        } else {
                            tally.accepted += 1;
                            if reply.command == 0x09 && !retry {
                                since_reset = Some((replies - 1, errors));
                            }
                        }
                    }
                    // The firmware runs a self-test and replies (counted then):
                    // nothing to run here, nothing counted.
                    Handled::SelfTest { .. } => last_command = None,
                    Handled::Nothing => {}
                }
            }
            let (base_replies, base_errors) = since_reset.unwrap_or((0, 0));
            let info = handler.info(&counters);
            if replies > delimiters
                || info.counters.commands != replies - base_replies + 1
                || info.counters.command_errors != errors - base_errors
            {
                tally.broke(|| {
                    format!(
                        "{replies} replies, {errors} errors, identify says {} and {}",
                        info.counters.commands, info.counters.command_errors
                    )
                });
            }
        },
    );
}

fn calibration_blob(inputs: u64) {
    let seeds = vec![
        blob::encode(&triad_bench::inputs::realistic()).to_vec(),
        blob::encode(&triad_bench::inputs::with_temperature_terms()).to_vec(),
    ];
    run(
        "calibration blob",
        inputs,
        &seeds,
        reseal_tail,
        |bytes, tally| {
            if let Ok(cal) = blob::decode(bytes) {
                tally.accepted += 1;
                let again = blob::decode(&blob::encode(&cal));
                if format!("{again:?}") != format!("{:?}", Ok::<_, blob::BlobError>(cal)) {
                    tally.broke(|| format!("{cal:?} re-encodes to {again:?}"));
                }
            }
        },
    );
}

fn scene_blob(inputs: u64) {
    use triad_sim::scenes::scene_blob::{decode, encode, MAX_BLOB_LEN};
    let mut seeds = Vec::new();
    for name in ["static-bench", "tumble-6"] {
        let loaded = triad_host::scene_file::load(name).expect("a shipped scene");
        let mut out = [0u8; MAX_BLOB_LEN];
        let n = encode(&loaded.scene, 1, &mut out).expect("it packs");
        seeds.push(out[..n].to_vec());
    }
    run("scene blob", inputs, &seeds, reseal_tail, |bytes, tally| {
        if let Ok((scene, seed)) = decode(bytes) {
            tally.accepted += 1;
            // Compared as bytes: a NaN parameter (refused later, by the
            // simulator) is not equal to itself.
            let (mut first, mut second) = ([0u8; MAX_BLOB_LEN], [0u8; MAX_BLOB_LEN]);
            let again = encode(&scene, seed, &mut first).and_then(|n| {
                let (scene, seed) = decode(&first[..n])?;
                let m = encode(&scene, seed, &mut second)?;
                Ok((n, m, seed))
            });
            match again {
                Ok((n, m, s)) if first[..n] == second[..m] && s == seed => {}
                other => tally.broke(|| format!("re-encoded: {other:?} from {scene:?}")),
            }
        }
    });
}

fn calibration_toml(inputs: u64) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../calibrations");
    let seeds: Vec<Vec<u8>> = ["default.toml", "lab-example.toml"]
        .iter()
        .map(|f| std::fs::read(root.join(f)).expect("a shipped calibration"))
        .collect();
    let path = Path::new("fuzz.toml");
    run("calibration TOML", inputs, &seeds, leave, |bytes, tally| {
        let text = String::from_utf8_lossy(bytes);
        match triad_host::calib::file::parse(&text, path) {
            Ok(_) => tally.accepted += 1,
            Err(e) => {
                if e.to_string().is_empty() {
                    tally.broke(|| "an error without a message".into());
                }
            }
        }
    });
}

fn main() {
    let inputs: u64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("INPUTS: a whole number"))
        .unwrap_or(10_000_000);
    std::panic::set_hook(Box::new(|info| {
        let input = CURRENT.with(|c| c.borrow().clone());
        eprintln!("bench_fuzz: PANIC {info} on input {input:02x?}");
    }));
    let (unstuffed, on_wire) = packet_seeds();
    println!("mutation run, {inputs} inputs per parser (seeded from valid examples):");
    stream_decoder(inputs, &on_wire);
    run(
        "packet parser",
        inputs,
        &unstuffed,
        reseal_tail,
        |bytes, tally| {
            tally.accepted += u64::from(Packet::parse(bytes).is_ok());
        },
    );
    command_path(inputs, &on_wire);
    calibration_blob(inputs);
    scene_blob(inputs);
    calibration_toml(inputs);
}
