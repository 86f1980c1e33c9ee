//! Host figures of the benchmark's variants: ns per 6-axis sample and
//! samples per second of the same functions the emulated cores run
//! (`triad::bench`), timed around each batch's kernel only. Indicative: this
//! machine, not the device. `cargo xtask bench` runs it and puts the figures
//! in docs/BENCHMARKS.md.
//!
//! `cargo run -p triad-host --release --example bench_model [-- --json]`

use std::hint::black_box;
use std::time::{Duration, Instant};

use triad::bench::kernels::Meter;
use triad::bench::{Bench, Variant, BATCH, BATCHES};

/// Wall-clock time around each kernel call.
#[derive(Default)]
struct WallMeter {
    started: Option<Instant>,
    total: Duration,
}

impl Meter for WallMeter {
    fn start(&mut self) {
        self.started = Some(Instant::now());
    }
    fn stop(&mut self) {
        if let Some(t0) = self.started.take() {
            self.total += t0.elapsed();
        }
    }
}

/// Runs of BATCH·BATCHES samples per variant; the median run is reported.
const RUNS: usize = 101;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let json = std::env::args().any(|a| a == "--json");
    let bench = Bench::realistic();
    let mut rows = Vec::new();
    for variant in Variant::ALL {
        let mut per_run = Vec::with_capacity(RUNS);
        for _ in 0..RUNS {
            let mut meter = WallMeter::default();
            black_box(bench.run(black_box(variant), &mut meter)?);
            per_run.push(meter.total.as_secs_f64());
        }
        per_run.sort_by(f64::total_cmp);
        let ns = per_run[RUNS / 2] * 1e9 / (BATCH * BATCHES) as f64;
        rows.push((variant.name(), ns));
    }
    if json {
        let items: Vec<String> = rows
            .iter()
            .map(|(name, ns)| format!("{{\"variant\":\"{name}\",\"ns_per_sample\":{ns:.3}}}"))
            .collect();
        println!("[{}]", items.join(","));
    } else {
        println!("{:<20} {:>12} {:>16}", "variant", "ns/sample", "samples/s");
        for (name, ns) in rows {
            println!("{name:<20} {ns:>12.2} {:>16.3e}", 1e9 / ns);
        }
    }
    Ok(())
}
