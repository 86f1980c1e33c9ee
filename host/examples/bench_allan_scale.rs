//! Allan at the scale of real recordings: figures, not pass/fail.
//!
//!     cargo run --release -p triad-host --example bench_allan_scale [-- --long]
//!
//! (`cargo xtask bench --allan` builds `triad`, installs allantools in a
//! venv under target/ and runs this.) An 8-hour, 400 Hz six-axis record
//! (11.52 M samples: white noise, a random walk, 1 g on az) is written as
//! triad's CSV and, when `triad convert` can, as an MCAP bag of
//! sensor_msgs/msg/Imu; then, one after the other on this machine:
//!
//! - `triad allan REC --json --kalibr imu.yaml` (octave Allan deviation of
//!   the six columns, the noise-term fit, the grade, Kalibr's YAML), under
//!   `/usr/bin/time`: wall time, CPU time, peak resident memory;
//! - allantools' `oadev(..., taus="octave")` on the same six columns already
//!   in memory (bench/allan_peer.py, python from `$TRIAD_PYTHON`, else
//!   target/allan-peer-venv/bin/python): the oadev calls' time, its peak;
//!
//! each run [`RUNS`] times, the run of median wall time kept (every run's
//! time is printed: this machine's speed drifts by 10 % and more from one
//! minute to the next),
//! and prints both, their ratio and the largest relative difference of the
//! deviations over the common τ (fully overlapping octaves, where the
//! estimator is allantools', and strided ones apart). Then what bounds
//! triad's time from below: the bag read as triad reads it (its own walk
//! of the records, each chunk's data read at its place, an uncompressed
//! one without a CRC a window at a time) and its zstd chunks
//! decompressed, alone, on one core, by this program (`unzstd`), under the
//! same timer. With `--long` also the
//! 24-hour, 2 kHz case (172.8 M samples), streamed as CSV from a generator
//! (this program, `gen`) through a pipe into `triad allan -`: time and peak
//! memory of triad alone (allantools is not run: its six columns alone
//! would take 8.3 GB).
//!
//! Its parts alone, for profiling: `gen N RATE` (the CSV on stdout),
//! `uncompressed FROM.mcap TO.mcap` (the copy rosbag2's defaults give),
//! `unzstd BAG.mcap` (the floor).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::Value;
use triad_sim::effects::rng::Rng;

/// The six columns, in the CSV's order.
const COLUMNS: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

/// Runs of allantools and of triad on each bag: the median's is reported.
const RUNS: usize = 3;

/// Fully overlapping octaves go up to this m (`triad_lab::allan::strided::BASE`).
const BASE: u64 = triad_lab::allan::strided::BASE;

/// The record's generator: per column, white noise and a random walk (SI),
/// 1 g added to az.
struct Generator {
    rng: Rng,
    walk: [f64; 6],
}

impl Generator {
    fn new() -> Self {
        Generator {
            rng: Rng::from_seed(24),
            walk: [0.0; 6],
        }
    }

    fn next(&mut self) -> [f64; 6] {
        let mut row = [0.0; 6];
        for (c, v) in row.iter_mut().enumerate() {
            let (white, step) = if c < 3 { (2e-3, 2e-6) } else { (1e-3, 1e-6) };
            self.walk[c] += step * self.rng.gaussian();
            *v = white * self.rng.gaussian() + self.walk[c];
        }
        row[2] += 9.806_65;
        row
    }
}

/// Writes `n` rows at `rate` Hz as CSV (`t,ax,…,gz`) to `w`.
fn write_csv(w: &mut impl Write, n: u64, rate: f64, mut raw: Option<&mut [Vec<f64>; 6]>) {
    let mut g = Generator::new();
    writeln!(w, "t,{}", COLUMNS.join(",")).expect("write");
    for k in 0..n {
        let r = g.next();
        let t = k as f64 / rate;
        writeln!(
            w,
            "{t},{},{},{},{},{},{}",
            r[0], r[1], r[2], r[3], r[4], r[5]
        )
        .expect("write");
        if let Some(cols) = raw.as_deref_mut() {
            for (col, v) in cols.iter_mut().zip(r) {
                col.push(v);
            }
        }
    }
    w.flush().expect("write");
}

/// The record as CSV at `csv` and as raw f64 columns, one after the other, at `raw`.
fn write_record(csv: &Path, raw: &Path, n: u64, rate: f64) {
    let mut cols: [Vec<f64>; 6] = Default::default();
    let mut w = BufWriter::with_capacity(1 << 20, File::create(csv).expect("create the CSV"));
    write_csv(&mut w, n, rate, Some(&mut cols));
    let mut w = BufWriter::with_capacity(1 << 20, File::create(raw).expect("create the raw file"));
    for v in cols.iter().flatten() {
        w.write_all(&v.to_le_bytes()).expect("write");
    }
    w.flush().expect("write");
}

/// Wall s, CPU s (user + system) and peak MiB of a command run under
/// `/usr/bin/time -f "%e %U %S %M"`, from its stderr's last line.
fn timed(stderr: &[u8]) -> (f64, f64, f64) {
    let text = String::from_utf8_lossy(stderr);
    let f: Vec<f64> = text
        .lines()
        .last()
        .unwrap_or("")
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    match f[..] {
        [wall, user, sys, kb] => (wall, user + sys, kb / 1024.0),
        _ => (f64::NAN, f64::NAN, f64::NAN),
    }
}

/// `triad` next to this example (target/release/).
fn triad_exe() -> PathBuf {
    let exe = std::env::current_exe().expect("own path");
    exe.parent()
        .and_then(Path::parent)
        .map(|d| d.join("triad"))
        .expect("target dir")
}

/// The run of median wall time of [`RUNS`] of `run` (None: one failed),
/// and every run's wall time, in order.
fn median_run<T>(mut run: impl FnMut() -> Option<(T, f64)>) -> Option<((T, f64), Vec<f64>)> {
    let mut runs = Vec::new();
    for _ in 0..RUNS {
        runs.push(run()?);
    }
    let walls: Vec<f64> = runs.iter().map(|r| r.1).collect();
    runs.sort_by(|a, b| a.1.total_cmp(&b.1));
    Some((runs.swap_remove(RUNS / 2), walls))
}

/// Wall times, for the reports: "0.61, 0.58, 0.60 s".
fn walls(w: &[f64]) -> String {
    let each: Vec<String> = w.iter().map(|s| format!("{s:.2}")).collect();
    format!("{} s", each.join(", "))
}

/// `triad allan INPUT --json --kalibr YAML` under /usr/bin/time: the
/// report and (wall, CPU, peak MiB).
fn run_triad(input: &Path, yaml: &Path) -> Option<(Value, (f64, f64, f64))> {
    let out = Command::new("/usr/bin/time")
        .args(["-f", "%e %U %S %M"])
        .arg(triad_exe())
        .arg("allan")
        .arg(input)
        .args(["--json", "--kalibr"])
        .arg(yaml)
        .output()
        .expect("run /usr/bin/time triad allan");
    if !out.status.success() {
        println!(
            "triad allan failed (is it built? cargo build --release -p triad-host): {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
        return None;
    }
    let report = serde_json::from_slice(&out.stdout).expect("triad allan's JSON");
    Some((report, timed(&out.stderr)))
}

/// `triad convert CSV MCAP`: true when the bag was written.
fn convert_to_mcap(csv: &Path, mcap: &Path) -> bool {
    let out = Command::new(triad_exe())
        .arg("convert")
        .arg(csv)
        .arg(mcap)
        .stderr(Stdio::piped())
        .output();
    match out {
        Ok(o) if o.status.success() => true,
        Ok(o) => {
            let why = String::from_utf8_lossy(&o.stderr);
            println!(
                "no MCAP (triad convert: {}): triad reads the CSV",
                why.lines().next().unwrap_or("").trim()
            );
            false
        }
        Err(e) => {
            println!("no MCAP ({e}): triad reads the CSV");
            false
        }
    }
}

/// allantools on the raw columns: its JSON report, or why not.
fn run_peer(raw: &Path, rate: f64) -> Result<Value, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let python = std::env::var("TRIAD_PYTHON").map_or_else(
        |_| root.join("target/allan-peer-venv/bin/python"),
        PathBuf::from,
    );
    let out = Command::new(&python)
        .arg(root.join("bench/allan_peer.py"))
        .arg(raw)
        .arg(COLUMNS.len().to_string())
        .arg(rate.to_string())
        .output()
        .map_err(|e| {
            format!(
                "{}: {e} (cargo xtask bench --allan installs it)",
                python.display()
            )
        })?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        return Err(err.lines().last().unwrap_or("").to_string());
    }
    serde_json::from_slice(&out.stdout).map_err(|e| e.to_string())
}

/// The largest relative difference of triad's deviations from the peer's
/// over the common m, (fully overlapping, strided), each with its m.
fn differences(report: &Value, peer: &Value) -> [(f64, u64); 2] {
    let mut worst = [(0.0f64, 0u64); 2];
    let peer_m: Vec<u64> = peer["m"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(Value::as_u64)
        .collect();
    let rate = report["rate_hz"].as_f64().unwrap_or(f64::NAN);
    for (c, column) in report["columns"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        for p in column["curve"].as_array().into_iter().flatten() {
            let m = (p["tau"].as_f64().unwrap_or(0.0) * rate).round() as u64;
            let Some(j) = peer_m.iter().position(|&x| x == m) else {
                continue;
            };
            let theirs = peer["columns"][c][j].as_f64().unwrap_or(f64::NAN);
            let rel = (p["oadev"].as_f64().unwrap_or(f64::NAN) - theirs).abs() / theirs;
            let slot = usize::from(m > BASE);
            if rel > worst[slot].0 {
                worst[slot] = (rel, m);
            }
        }
    }
    worst
}

/// A copy of the MCAP at `from` at `to` with the same records in chunks
/// stored uncompressed and without chunk CRCs: what rosbag2's MCAP storage
/// writes by default (rosbag2_storage_mcap/src/mcap_storage.cpp sets
/// `compression = None`, `noChunkCRC = true` unless a preset or a config
/// file says otherwise). The records are read by the `mcap` crate and
/// written again by it.
fn uncompressed_copy(from: &Path, to: &Path) -> Result<(), String> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    use std::io::Read;
    let mut file = File::open(from).map_err(|e| e.to_string())?;
    let out = BufWriter::with_capacity(1 << 20, File::create(to).map_err(|e| e.to_string())?);
    let mut writer = mcap::WriteOptions::new()
        .profile("ros2")
        .compression(None)
        .calculate_chunk_crcs(false)
        .create(out)
        .map_err(|e| e.to_string())?;
    let options = LinearReaderOptions::default().with_record_length_limit(1 << 30);
    let mut reader = LinearReader::new_with_options(options);
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| e.to_string())? {
            LinearReadEvent::ReadRequest(need) => {
                let n = file.read(reader.insert(need)).map_err(|e| e.to_string())?;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                let written = match mcap::parse_record(opcode, data).map_err(|e| e.to_string())? {
                    Record::Schema { header, data } => writer
                        .add_schema_with_id(header.id, &header.name, &header.encoding, &data)
                        .map(drop),
                    Record::Channel(c) => writer
                        .add_channel_with_id(
                            c.id,
                            c.schema_id,
                            &c.topic,
                            &c.message_encoding,
                            &c.metadata,
                        )
                        .map(drop),
                    Record::Message { header, data } => {
                        writer.write_to_known_channel(&header, &data)
                    }
                    _ => Ok(()),
                };
                written.map_err(|e| e.to_string())?;
            }
        }
    }
    writer.finish().map_err(|e| e.to_string())?;
    Ok(())
}

/// The 8-hour case (or `hours` at `rate`): allantools, then triad on each
/// form of the record (the zstd MCAP `triad convert` writes, the same
/// messages uncompressed as rosbag2 writes by default; the CSV when there
/// is no MCAP), each beside the peer and the floor under its time.
fn record_case(dir: &Path, hours: f64, rate: f64) {
    let n = (hours * 3600.0 * rate) as u64;
    let (csv, raw, mcap, plain, yaml) = (
        dir.join("record.csv"),
        dir.join("record.f64"),
        dir.join("record.mcap"),
        dir.join("record-uncompressed.mcap"),
        dir.join("imu.yaml"),
    );
    write_record(&csv, &raw, n, rate);
    let bag = convert_to_mcap(&csv, &mcap);
    if bag {
        // The CSV is not read again: its disk space is the uncompressed bag's.
        let _ = std::fs::remove_file(&csv);
    }
    println!("{hours} h at {rate} Hz, six columns: {n} samples each");
    let mut failure = None;
    let runs = median_run(|| match run_peer(&raw, rate) {
        Ok(peer) => {
            let seconds = peer["seconds"].as_f64().unwrap_or(f64::NAN);
            Some((peer, seconds))
        }
        Err(why) => {
            failure = Some(why);
            None
        }
    });
    let peer = match runs {
        Some(((peer, seconds), all)) => {
            let cpu = peer["cpu_seconds"].as_f64().unwrap_or(f64::NAN);
            let peak = peer["peak_rss_mb"].as_f64().unwrap_or(f64::NAN);
            println!(
                "{} oadev, octave taus, the six columns in memory (one core): {seconds:.2} s wall (median of {RUNS} runs: {}), {cpu:.2} s CPU, peak {peak:.0} MiB",
                peer["tool"].as_str().unwrap_or("allantools"),
                walls(&all)
            );
            Some((peer, (seconds, cpu, peak)))
        }
        None => {
            println!("allantools not run: {}", failure.unwrap_or_default());
            None
        }
    };
    let _ = std::fs::remove_file(&raw);
    let mut inputs: Vec<(&Path, &str)> = Vec::new();
    if bag {
        inputs.push((&mcap, "zstd chunks, as triad convert writes"));
        match uncompressed_copy(&mcap, &plain) {
            Ok(()) => inputs.push((
                &plain,
                "uncompressed chunks without CRCs, rosbag2's default",
            )),
            Err(e) => println!("no uncompressed MCAP ({e})"),
        }
    } else {
        inputs.push((&csv, "CSV"));
    }
    let reports: Vec<Value> = inputs
        .iter()
        .filter_map(|&(input, form)| triad_row(input, form, &yaml, peer.as_ref()))
        .collect();
    if let [first, second] = &reports[..] {
        // Each names its input; every other field is compared.
        let figures = |r: &Value| {
            let mut r = r.clone();
            r.as_object_mut().map(|o| o.remove("input"));
            r
        };
        println!(
            "the two bags' reports: {}",
            if figures(first) == figures(second) {
                "the same, every figure (their input's name apart)"
            } else {
                "NOT the same"
            }
        );
    }
    for p in [&csv, &raw, &mcap, &plain] {
        let _ = std::fs::remove_file(p);
    }
}

/// triad allan on `input` (`form` says what it is): its figures, their
/// ratios to the peer's, and (a bag) the floor under its time.
fn triad_row(
    input: &Path,
    form: &str,
    yaml: &Path,
    peer: Option<&(Value, (f64, f64, f64))>,
) -> Option<Value> {
    let size = std::fs::metadata(input).map_or(0, |m| m.len());
    let name = input.file_name().and_then(|s| s.to_str()).unwrap_or("?");
    let (((report, (cpu, peak)), wall), all) = median_run(|| {
        let (report, (wall, cpu, peak)) = run_triad(input, yaml)?;
        Some(((report, (cpu, peak)), wall))
    })?;
    let octaves = report["columns"][0]["curve"].as_array().map_or(0, Vec::len);
    println!(
        "triad allan on {name} ({form}, {:.0} MB; octave ADEV, noise-term fit, grade, Kalibr imu.yaml): {wall:.2} s wall (median of {RUNS} runs: {}), {cpu:.2} s CPU, peak {peak:.0} MiB, {octaves} octaves per column",
        size as f64 / 1e6,
        walls(&all)
    );
    if let Some((peer, (seconds, peer_cpu, peer_peak))) = peer {
        let [full, strided] = differences(&report, peer);
        println!(
            "allantools/triad on {name}: time {:.1}x (wall, triad on every core), {:.1}x (CPU), peak memory {:.1}x; largest relative difference: {:.1e} over the fully overlapping octaves (m = {}), {:.1e} over the strided ones (m = {})",
            seconds / wall,
            peer_cpu / cpu,
            peer_peak / peak,
            full.0,
            full.1,
            strided.0,
            strided.1
        );
    }
    if input.extension().is_some_and(|e| e == "mcap") {
        reader_floor(input, cpu);
    }
    Some(report)
}

/// Reads the MCAP at `path` as triad does (its own walk of the records,
/// each chunk's data read at its place: triad_host::record::mcap_walk; an
/// uncompressed one without a CRC a window at a time, mcap_windows) and
/// decompresses every zstd chunk, on this thread: the bytes of records,
/// and the chunks.
fn unzstd(path: &Path) -> (u64, u64) {
    use triad_host::record::mcap_walk::{self, Top};
    use triad_host::record::mcap_windows;
    let file = File::open(path).expect("open the MCAP");
    let mut zstd = zstd::bulk::Decompressor::new().expect("zstd");
    let (mut stored, mut buffer) = (Vec::new(), Vec::new());
    let (mut bytes, mut chunks) = (0u64, 0u64);
    let broken = |at, why| anyhow::anyhow!("broken at byte {at}: {why}");
    mcap_walk::walk(path, "the bag", &broken, |top| {
        if let Top::Chunk(chunk) = top {
            if mcap_windows::applies(&chunk.header) {
                // A window at a time, into one buffer, as triad decodes these.
                let len = chunk.header.compressed_size;
                stored.resize(mcap_windows::WINDOW, 0);
                let mut read = 0;
                while read < len {
                    let piece = (len - read).min(mcap_windows::WINDOW as u64) as usize;
                    chunk
                        .read_part(&file, read, &mut stored[..piece])
                        .map_err(anyhow::Error::msg)?;
                    read += piece as u64;
                }
                bytes += len;
                chunks += 1;
                return Ok(());
            }
            chunk.read(&file, &mut stored).map_err(anyhow::Error::msg)?;
            let records = if chunk.header.compression == "zstd" {
                buffer.clear();
                buffer.reserve(chunk.header.uncompressed_size as usize);
                zstd.decompress_to_buffer(&stored, &mut buffer)?;
                buffer.len()
            } else {
                stored.len()
            };
            bytes += records as u64;
            chunks += 1;
        }
        Ok(())
    })
    .expect("a readable MCAP");
    (bytes, chunks)
}

/// The floor under triad's time: `unzstd` of the bag under /usr/bin/time.
fn reader_floor(mcap: &Path, triad_cpu: f64) {
    let exe = std::env::current_exe().expect("own path");
    let out = Command::new("/usr/bin/time")
        .args(["-f", "%e %U %S %M"])
        .arg(exe)
        .arg("unzstd")
        .arg(mcap)
        .output()
        .expect("run /usr/bin/time unzstd");
    let (wall, cpu, _) = timed(&out.stderr);
    let said = String::from_utf8_lossy(&out.stdout);
    println!(
        "{} read as triad reads it and its chunks decompressed (zstd) alone (one core, no CRC, no CDR, no Allan): {wall:.2} s wall, {cpu:.2} s CPU, {}: {:.0} % of triad allan's CPU",
        mcap.file_name().and_then(|s| s.to_str()).unwrap_or("?"),
        said.trim(),
        100.0 * cpu / triad_cpu
    );
}

/// The 24-hour, 2 kHz case: CSV from `gen` piped into `triad allan -`.
fn long_case(hours: f64, rate: f64) {
    let n = (hours * 3600.0 * rate) as u64;
    let exe = std::env::current_exe().expect("own path");
    let mut generator = Command::new(exe)
        .args(["gen", &n.to_string(), &rate.to_string()])
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the generator");
    let stdout = generator.stdout.take().expect("piped");
    let out = Command::new("/usr/bin/time")
        .args(["-f", "%e %U %S %M"])
        .arg(triad_exe())
        .args(["allan", "-", "--json"])
        .stdin(stdout)
        .output()
        .expect("run /usr/bin/time triad allan -");
    let _ = generator.wait();
    if !out.status.success() {
        println!(
            "triad allan - failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
        return;
    }
    let report: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let (wall, cpu, peak) = timed(&out.stderr);
    let octaves = report["columns"][0]["curve"].as_array().map_or(0, Vec::len);
    println!(
        "{hours} h at {rate} Hz, six columns ({} samples each), CSV streamed from a generator through a pipe: triad allan {wall:.1} s wall (the generator sharing the cores), {cpu:.1} s CPU, peak {peak:.0} MiB, {octaves} octaves per column",
        report["samples"]
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("gen") {
        let n: u64 = args[1].parse().expect("rows");
        let rate: f64 = args[2].parse().expect("rate");
        let stdout = std::io::stdout().lock();
        write_csv(
            &mut BufWriter::with_capacity(1 << 20, stdout),
            n,
            rate,
            None,
        );
        return;
    }
    if args.first().map(String::as_str) == Some("uncompressed") {
        if let Err(e) = uncompressed_copy(Path::new(&args[1]), Path::new(&args[2])) {
            eprintln!("{e}");
            std::process::exit(1);
        }
        return;
    }
    if args.first().map(String::as_str) == Some("unzstd") {
        let (bytes, chunks) = unzstd(Path::new(&args[1]));
        println!(
            "{:.2} GB decompressed from {chunks} chunks",
            bytes as f64 / 1e9
        );
        return;
    }
    // Other work on the machine stretches the wall times (not the CPU times much).
    load("at the start");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/allan-bench");
    std::fs::create_dir_all(&dir).expect("target/allan-bench");
    record_case(&dir, 8.0, 400.0);
    if args.iter().any(|a| a == "--long") {
        long_case(24.0, 2000.0);
    }
    load("at the end");
}

/// Prints the machine's cores and load average (`when`).
fn load(when: &str) {
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        println!(
            "this machine: {cores} cores, load average {} (1, 5, 15 min) {when}",
            load.split_whitespace()
                .take(3)
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
