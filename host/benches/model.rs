//! Host figures of the benchmark's variants with criterion: the same
//! functions the emulated cores run (`triad_bench`), timed around each
//! batch's kernel only (inputs are made and outputs digested outside the
//! clock). One iteration is BATCH × BATCHES = 1000 6-axis samples.
//!
//! `cargo bench -p triad-host --bench model`; `cargo xtask bench` runs it and
//! reads criterion's estimates into docs/BENCHMARKS.md.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use triad_bench::kernels::Meter;
use triad_bench::{Bench, Variant, BATCH, BATCHES};

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

fn variants(c: &mut Criterion) {
    let bench = Bench::realistic();
    let mut group = c.benchmark_group("model");
    group.throughput(Throughput::Elements((BATCH * BATCHES) as u64));
    for variant in Variant::ALL {
        group.bench_function(variant.name(), |b| {
            b.iter_custom(|iterations| {
                let mut meter = WallMeter::default();
                for _ in 0..iterations {
                    // The calibration is the benchmark's own: it is valid.
                    if let Ok(digest) = bench.run(variant, &mut meter) {
                        std::hint::black_box(digest);
                    }
                }
                meter.total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, variants);
criterion_main!(benches);
