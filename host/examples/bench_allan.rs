//! Allan-deviation benchmark: figures, not pass/fail.
//!
//!     cargo run --release -p triad-host --example bench_allan [-- SIZES...]
//!
//! For each size (default 10⁷ and 10⁸ samples) it writes a rate record
//! (white noise plus a random walk and a 10⁴σ bias, raw little-endian f64,
//! in the system temp directory), then in separate processes, so each peak
//! memory is its own:
//!
//! - `bench_allan oadev FILE`: triad's streaming octave OADEV
//!   ([`OctaveAccumulator`], ring grown as `triad allan` grows it), reading
//!   the file in 1 MiB chunks: time and peak resident memory (VmHWM);
//! - `bench/allan_peer.py FILE`: allantools `oadev(..., taus="octave")` on the
//!   same samples (python from `$TRIAD_PYTHON`, default `python3`);
//!
//! and prints both, the time ratio and the largest relative difference of
//! the deviations over the common τ. With `--csv ROWS` it also times
//! `triad allan` end to end (CSV parsing included) on a ROWS-row, one-column
//! CSV file.

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use triad_lab::allan::accumulate::OctaveAccumulator;
use triad_sim::effects::rng::Rng;

/// Peak resident memory of this process, MiB (Linux /proc; NaN elsewhere).
fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn write_record(path: &Path, n: u64) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, File::create(path)?);
    let mut rng = Rng::from_seed(42);
    let mut walk = 0.0;
    for _ in 0..n {
        walk += 1e-3 * rng.gaussian();
        let y = 1e4 + rng.gaussian() + walk;
        w.write_all(&y.to_le_bytes())?;
    }
    w.flush()
}

/// The child: streaming OADEV of FILE; prints `m oadev` lines, then a summary line.
fn child(path: &str) -> std::io::Result<()> {
    let start = Instant::now();
    let mut file = File::open(path)?;
    // The largest octave with 2m ≤ N needs 2^⌊log2 N⌋ slots (N from the size).
    let n = (file.metadata()?.len() / 8).max(2);
    let ring_cap = 1usize << n.ilog2();
    let mut buf = vec![0u8; 1 << 20];
    let mut acc: Option<OctaveAccumulator<Vec<f64>>> = None;
    loop {
        let mut filled = 0;
        while filled < buf.len() {
            let k = file.read(&mut buf[filled..])?;
            if k == 0 {
                break;
            }
            filled += k;
        }
        if filled == 0 {
            break;
        }
        for chunk in buf[..filled].chunks_exact(8) {
            let y = f64::from_le_bytes(chunk.try_into().expect("8 bytes"));
            // Offset: the first sample (triad allan uses the mean of 4096 rows).
            let a = acc.get_or_insert_with(|| {
                OctaveAccumulator::new(vec![0.0; 4096.min(ring_cap)], y).expect("valid ring")
            });
            let _ = a.grow_before_wrap(ring_cap, |n| vec![0.0; n]);
            a.push(y);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let a = acc.expect("a non-empty file");
    for r in a.results() {
        println!("{} {:e}", r.m, r.overlapping.sqrt());
    }
    println!(
        "summary {} {seconds} {} {}",
        a.samples(),
        peak_rss_mb(),
        a.ring_len()
    );
    Ok(())
}

struct Run {
    m: Vec<u64>,
    dev: Vec<f64>,
    seconds: f64,
    peak_mb: f64,
}

fn run_triad(path: &Path) -> Run {
    let exe = std::env::current_exe().expect("own path");
    let out = Command::new(exe)
        .arg("oadev")
        .arg(path)
        .output()
        .expect("run child");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut run = Run {
        m: vec![],
        dev: vec![],
        seconds: 0.0,
        peak_mb: 0.0,
    };
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f[0] == "summary" {
            run.seconds = f[2].parse().unwrap_or(f64::NAN);
            run.peak_mb = f[3].parse().unwrap_or(f64::NAN);
        } else {
            run.m.push(f[0].parse().unwrap_or(0));
            run.dev.push(f[1].parse().unwrap_or(f64::NAN));
        }
    }
    run
}

fn json_numbers(text: &str, key: &str) -> Vec<f64> {
    let Some(i) = text.find(&format!("\"{key}\": [")) else {
        return vec![];
    };
    let rest = &text[i + key.len() + 5..];
    let end = rest.find(']').unwrap_or(0);
    rest[..end]
        .split(',')
        .filter_map(|x| x.trim().parse().ok())
        .collect()
}

fn json_number(text: &str, key: &str) -> f64 {
    text.find(&format!("\"{key}\": "))
        .and_then(|i| {
            let rest = &text[i + key.len() + 4..];
            rest[..rest.find([',', '}']).unwrap_or(rest.len())]
                .trim()
                .parse()
                .ok()
        })
        .unwrap_or(f64::NAN)
}

fn run_peer(path: &Path) -> Option<(Run, String)> {
    let python = std::env::var("TRIAD_PYTHON").unwrap_or_else(|_| "python3".into());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/allan_peer.py");
    let out = Command::new(python).arg(script).arg(path).output().ok()?;
    if !out.status.success() {
        eprintln!(
            "allantools peer failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let tool = text
        .split("\"tool\": \"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap_or("allantools")
        .to_string();
    Some((
        Run {
            m: json_numbers(&text, "m").iter().map(|&x| x as u64).collect(),
            dev: json_numbers(&text, "oadev"),
            seconds: json_number(&text, "seconds"),
            peak_mb: json_number(&text, "peak_rss_mb"),
        },
        tool,
    ))
}

/// Writes a `rows`-row CSV (`t,gx`, 1 kHz) at `path`.
fn write_csv(path: &Path, rows: u64) {
    let mut w = BufWriter::with_capacity(1 << 20, File::create(path).expect("csv"));
    writeln!(w, "t,gx").expect("csv");
    let mut rng = Rng::from_seed(7);
    for k in 0..rows {
        writeln!(w, "{},{}", k as f64 * 1e-3, 1e-3 * rng.gaussian()).expect("csv");
    }
    w.flush().expect("csv");
}

/// `triad allan --json` end to end on a `rows`-row CSV: time and peak memory.
fn csv_end_to_end(rows: u64) {
    let path = std::env::temp_dir().join(format!("triad-bench-allan-{rows}.csv"));
    write_csv(&path, rows);
    let size = std::fs::metadata(&path).map_or(0, |m| m.len());
    let exe = std::env::current_exe().expect("own path");
    let triad = exe
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("triad"))
        .expect("target dir");
    let start = Instant::now();
    let status = Command::new("/usr/bin/time")
        .args(["-f", "%M"])
        .arg(&triad)
        .arg("allan")
        .arg(&path)
        .arg("--json")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .output();
    let seconds = start.elapsed().as_secs_f64();
    match status {
        Ok(o) if o.status.success() => {
            let kb: f64 = String::from_utf8_lossy(&o.stderr)
                .trim()
                .lines()
                .last()
                .and_then(|l| l.trim().parse().ok())
                .unwrap_or(f64::NAN);
            println!(
                "triad allan on a {rows}-row CSV ({:.0} MB, t and gx): {seconds:.2} s ({:.1} M rows/s, {:.0} MB/s), peak {:.0} MB",
                size as f64 / 1e6,
                rows as f64 / seconds / 1e6,
                size as f64 / seconds / 1e6,
                kb / 1024.0
            );
        }
        Ok(o) => println!(
            "triad allan failed (is {} built? cargo build --release -p triad-host): {}",
            triad.display(),
            String::from_utf8_lossy(&o.stderr).trim()
        ),
        Err(e) => println!("cannot run /usr/bin/time {}: {e}", triad.display()),
    }
    let _ = std::fs::remove_file(&path);
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("oadev") {
        child(&args[1]).expect("read the record");
        return;
    }
    let (sizes, csv_rows) = parse_args(&args);
    println!(
        "overlapping ADEV at octave tau, rate data: white noise + random walk + 1e4 sigma bias"
    );
    for n in sizes {
        compare(n);
    }
    if let Some(rows) = csv_rows {
        println!();
        csv_end_to_end(rows);
    }
}

/// The record sizes (default 10⁷ and 10⁸) and `--csv ROWS`.
fn parse_args(args: &[String]) -> (Vec<u64>, Option<u64>) {
    let mut sizes: Vec<u64> = vec![];
    let mut csv_rows = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--csv" {
            csv_rows = it
                .next()
                .and_then(|x| x.parse::<f64>().ok())
                .map(|x| x as u64);
        } else if let Ok(x) = a.parse::<f64>() {
            sizes.push(x as u64);
        }
    }
    if sizes.is_empty() {
        sizes = vec![10_000_000, 100_000_000];
    }
    (sizes, csv_rows)
}

/// triad and allantools on the same `n`-sample record.
fn compare(n: u64) {
    let path: PathBuf = std::env::temp_dir().join(format!("triad-bench-allan-{n}.f64"));
    write_record(&path, n).expect("write the record");
    let mine = run_triad(&path);
    println!(
        "\nN = {n:e}: triad streaming: {:.2} s ({:.0} M samples/s), peak {:.0} MB, {} octaves",
        mine.seconds,
        n as f64 / mine.seconds / 1e6,
        mine.peak_mb,
        mine.m.len()
    );
    match run_peer(&path) {
        Some((peer, tool)) => print_comparison(n, &mine, &peer, &tool),
        None => println!(
            "N = {n:e}: allantools peer not run (pip install allantools numpy; set TRIAD_PYTHON)"
        ),
    }
    let _ = std::fs::remove_file(&path);
}

/// The peer's figures, the ratios and the largest difference over the common τ.
fn print_comparison(n: u64, mine: &Run, peer: &Run, tool: &str) {
    let mut worst = (0.0f64, 0u64);
    let mut common = 0;
    for (m, d) in mine.m.iter().zip(&mine.dev) {
        if let Some(j) = peer.m.iter().position(|x| x == m) {
            common += 1;
            let rel = (d - peer.dev[j]).abs() / peer.dev[j];
            if rel > worst.0 {
                worst = (rel, *m);
            }
        }
    }
    println!(
        "N = {n:e}: {tool}: {:.2} s, peak {:.0} MB",
        peer.seconds, peer.peak_mb
    );
    println!(
        "N = {n:e}: time ratio allantools/triad = {:.1}, memory ratio = {:.1}; largest relative difference over {common} common tau: {:.2e} (m = {})",
        peer.seconds / mine.seconds,
        peer.peak_mb / mine.peak_mb,
        worst.0,
        worst.1
    );
}
