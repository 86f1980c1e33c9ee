//! The long mutation run of every parser that takes outside bytes (issue
//! 26): figures, not pass/fail. `cargo xtask bench --fuzz` runs it (then
//! AFL++ on the same targets); alone:
//!
//!     cargo run --release -p triad-fuzz --example bench_fuzz [-- INPUTS [PARSER]]
//!
//! (PARSER: run only the parsers whose name contains it, e.g. `recording`.)
//! `bench_fuzz --time FILE…` reads each file through the recording
//! readers 30 times and prints its fastest, median and slowest time (a
//! saved hang timed alone).
//!
//! INPUTS per parser (default 10⁷; a hundredth for the recording readers,
//! whose every input is a file), each a valid example (a seed under
//! fuzz/seeds) mutated at random (bits flipped, bytes set, inserted,
//! deleted, a run duplicated, the input cut, two seeds spliced, a 0x00 put
//! in) with its CRC fixed up half the time for the formats that end in one,
//! so the mutation reaches past the checksum. After each input the
//! target's invariants are checked: the same functions AFL++'s binaries
//! call (fuzz/src/targets, fuzz/src/invariants.rs).
//!
//! Printed per parser: inputs, time, inputs/s, the slowest input (the
//! shorter of two timings when it passed 100 ms: the machine may be
//! shared), the inputs accepted, panics (a panic prints the input and ends
//! the run: a finished run had none), hangs (inputs slower than 100 ms
//! twice, each saved under target/bench_fuzz-inputs/ to be timed alone,
//! as is each parser's slowest input)
//! and broken invariants (with the first; each input saved there too). Mutation is not
//! coverage-guided: AFL++ (the same benchmark) is.

use std::time::{Duration, Instant};

use triad::protocol::cobs::Unstuffer;
use triad::protocol::{crc32c, Packet};
use triad_fuzz::{seeds, Broken};

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
    slowest_input: Vec<u8>,
    hangs: u64,
    broken: u64,
    accepted: u64,
    first_broken: Option<String>,
}

impl Tally {
    fn count(&mut self, verdict: Result<u64, Broken>) {
        match verdict {
            Ok(accepted) => self.accepted += accepted,
            Err(broken) => {
                self.broken += 1;
                if self.first_broken.is_none() {
                    self.first_broken = Some(broken.0);
                }
            }
        }
    }
}

/// Runs `check` on `inputs` mutations of `seeds` (CRC fixed up half the
/// time by `reseal`); prints the figures.
fn run(
    only: &str,
    name: &str,
    inputs: u64,
    seeds: &[Vec<u8>],
    reseal: fn(&mut [u8]),
    mut check: impl FnMut(&[u8], &mut Tally),
) {
    if !name.contains(only) {
        return;
    }
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
        let (t, broken) = (Instant::now(), tally.broken);
        check(&input, &mut tally);
        let mut took = t.elapsed();
        if tally.broken > broken {
            eprintln!(
                "bench_fuzz: {name}: input {} broke an invariant: {}",
                tally.inputs,
                keep(name, &format!("broken-{}", tally.inputs), &input)
            );
        }
        if took > HANG {
            // The machine is shared: an input is slow when it is slow twice
            // (the parsers are deterministic), not when the process was
            // preempted once.
            let again = Instant::now();
            check(&input, &mut Tally::default());
            took = took.min(again.elapsed());
            if took > HANG {
                tally.hangs += 1;
                eprintln!(
                    "bench_fuzz: {name}: input {} took {:.1} ms twice: {}",
                    tally.inputs,
                    took.as_secs_f64() * 1e3,
                    keep(name, &tally.inputs.to_string(), &input)
                );
            }
        }
        if took > tally.slowest {
            tally.slowest = took;
            tally.slowest_input.clone_from(&input);
        }
        tally.inputs += 1;
    }
    let secs = start.elapsed().as_secs_f64();
    let slowest_file = keep(name, "slowest", &tally.slowest_input);
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
    println!("{:<22} (slowest input: {slowest_file})", "");
}

/// Saves `input` as target/bench_fuzz-inputs/PARSER-LABEL.bin, so it can
/// be timed alone; where it went.
fn keep(parser: &str, label: &str, input: &[u8]) -> String {
    let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = fuzz
        .parent()
        .unwrap_or(fuzz)
        .join("target/bench_fuzz-inputs");
    let file = dir.join(format!("{}-{label}.bin", parser.replace(' ', "_")));
    match std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&file, input)) {
        Ok(()) => file.display().to_string(),
        Err(e) => format!("(not saved: {e})"),
    }
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

/// The seeds of `dir` under fuzz/seeds.
fn seeds_of(dir: &str) -> Vec<Vec<u8>> {
    seeds::read(dir)
        .into_iter()
        .map(|(_, bytes)| bytes)
        .collect()
}

/// The unstuffed packets of the COBS seeds (packets on the wire): the
/// packet parser's input.
fn packets() -> Vec<Vec<u8>> {
    seeds_of("cobs")
        .iter()
        .map(|wire| {
            let mut unstuffer = Unstuffer::new();
            wire.iter()
                .take_while(|&&b| b != 0)
                .filter_map(|&b| unstuffer.push(b))
                .collect()
        })
        .collect()
}

/// `--time FILE…`: each file through the recording readers 30 times.
fn time_files(files: &[String]) {
    for file in files {
        let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("{file}: {e}"));
        let mut took: Vec<Duration> = (0..30)
            .map(|_| {
                let t = Instant::now();
                let _ = triad_fuzz::record(&bytes);
                t.elapsed()
            })
            .collect();
        took.sort();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "{file}: {} bytes, read 30 times: fastest {:.2} ms, median {:.2} ms, slowest {:.2} ms",
            bytes.len(),
            ms(took[0]),
            ms(took[15]),
            ms(took[29])
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--time") {
        return time_files(&args[1..]);
    }
    let inputs: u64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("INPUTS: a whole number"))
        .unwrap_or(10_000_000);
    let only = std::env::args().nth(2).unwrap_or_default();
    std::panic::set_hook(Box::new(|info| {
        let input = CURRENT.with(|c| c.borrow().clone());
        eprintln!("bench_fuzz: PANIC {info} on input {input:02x?}");
    }));
    println!("mutation run, {inputs} inputs per parser (seeded from fuzz/seeds):");
    let target = |f: fn(&[u8]) -> Result<u64, Broken>| {
        move |bytes: &[u8], tally: &mut Tally| tally.count(f(bytes))
    };
    run(
        &only,
        "stream decoder",
        inputs,
        &seeds_of("stream"),
        leave,
        target(triad_fuzz::stream_decoder),
    );
    run(
        &only,
        "packet parser",
        inputs,
        &packets(),
        reseal_tail,
        |bytes, tally| {
            tally.accepted += u64::from(Packet::parse(bytes).is_ok());
        },
    );
    run(
        &only,
        "device command path",
        inputs,
        &seeds_of("commands"),
        leave,
        target(triad_fuzz::command_path),
    );
    run(
        &only,
        "COBS",
        inputs,
        &seeds_of("cobs"),
        leave,
        target(triad_fuzz::cobs),
    );
    run(
        &only,
        "calibration blob",
        inputs,
        &seeds_of("calibration_blob"),
        reseal_tail,
        target(triad_fuzz::calibration_blob),
    );
    run(
        &only,
        "scene blob",
        inputs,
        &seeds_of("scene_blob"),
        reseal_tail,
        target(triad_fuzz::scene_blob),
    );
    run(
        &only,
        "calibration TOML",
        inputs,
        &seeds_of("calibration_toml"),
        leave,
        target(triad_fuzz::calibration_toml),
    );
    // Each input a file (on /dev/shm) read through `triad`'s reader thread:
    // 3 600–7 000 inputs/s (2026-11-27, a shared 2-core machine), so 10⁷
    // would take 25–45 min per target; a hundredth here, and AFL++ (the
    // same benchmark) fuzzes both, coverage-guided.
    let file_inputs = (inputs / 100).max(1);
    run(
        &only,
        "recording readers",
        file_inputs,
        &seeds_of("record"),
        leave,
        target(triad_fuzz::record),
    );
    run(
        &only,
        "triad CSV",
        file_inputs,
        &seeds_of("record"),
        leave,
        target(triad_fuzz::triad_csv),
    );
}
