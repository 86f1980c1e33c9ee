//! Honest noise terms from strided octaves (`triad_lab::allan::strided`):
//! with every octave above m = 64 strided (terms every m/64 samples: an
//! overlap ratio 2048 times smaller than `triad allan`'s 2^17, where the
//! covariance model's O(d/m) approximation is the coarsest), the truth still
//! lies within ±2σ of 90–98 % of the reported terms and an absent term is
//! reported in at most 5 % of the records. The terms of these scenarios are
//! decided at τ above the base, by strided points alone.
//!
//! Run in release (`cargo test --release -p triad-lab --test
//! allan_strided_coverage`, as `cargo xtask test` does); it prints the
//! coverage of the strided and, for comparison, the fully overlapping fits
//! of the same records.

mod common;

use common::{axes, static_scene, OctaveFitter};
use triad::units;
use triad_lab::allan::noise_terms::{Term, TERMS};
use triad_sim::effects::bias_instability::BiasInstabilityParams;
use triad_sim::scenes::scene::TriadEffects;

/// The base M of this test's strided octaves.
const BASE: u64 = 64;

/// 10 Hz, 2^16 samples (1.8 h): octaves 128 … 2^15 strided (d = 2 … 512).
const RATE: f64 = 10.0;
const SAMPLES: usize = 1 << 16;

/// Runs (three axes each) per scenario.
const RUNS: u64 = 24;

/// Counts over the records of both scenarios.
#[derive(Default)]
struct Tally {
    reported: usize,
    covered: usize,
    /// Σ ((estimate − truth)/σ)² over the reported terms.
    z2: f64,
    absent: [usize; TERMS],
    false_reports: [usize; TERMS],
}

/// Fits every record of both scenarios with `fitter` (by scenario: each has its own covariance).
fn tally(base: u64) -> Tally {
    let n = units::arw_deg_per_sqrt_h_to_si(0.15);
    let b = units::deg_per_h_to_rad_per_s(1.0);
    // N+K: K crosses N at τ ≈ 47 s; N+B+K: the floor from ≈ 200 s to ≈ 1100 s.
    let scenarios = [
        (0.0, units::rrw_deg_per_h_per_sqrt_h_to_si(20.0)),
        (b, units::rrw_deg_per_h_per_sqrt_h_to_si(2.0)),
    ];
    let mut t = Tally::default();
    for (b, k) in scenarios {
        let mut scene = static_scene(RATE);
        scene.gyro = TriadEffects {
            white_noise: Some([n; 3]),
            bias_instability: (b > 0.0).then(|| [BiasInstabilityParams::with_default_band(b); 3]),
            random_walk: Some([k; 3]),
            ..TriadEffects::NONE
        };
        let truth = [0.0, n, b, k, 0.0];
        let mut fitter = OctaveFitter::with_base(base);
        for seed in 0..RUNS {
            for y in axes(&scene, true, SAMPLES, 5000 + seed) {
                let fit = fitter.fit(&y, RATE);
                for (k, truth) in truth.iter().enumerate() {
                    let e = &fit.terms[k];
                    if *truth > 0.0 && e.significant {
                        t.reported += 1;
                        t.z2 += ((e.value - truth) / e.sigma).powi(2);
                        if (e.value - truth).abs() <= 2.0 * e.sigma {
                            t.covered += 1;
                        }
                    } else if *truth == 0.0 {
                        t.absent[k] += 1;
                        if e.significant {
                            t.false_reports[k] += 1;
                        }
                    }
                }
            }
        }
    }
    t
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "a statistical sweep: run in release (cargo test --release -p triad-lab --test allan_strided_coverage; cargo xtask test does)"
)]
fn strided_octaves_keep_the_terms_honest() {
    let (strided, full) = std::thread::scope(|scope| {
        let full = scope.spawn(|| tally(1 << 40));
        (tally(BASE), full.join().unwrap())
    });
    for (name, t) in [
        ("strided above m = 64", &strided),
        ("fully overlapping", &full),
    ] {
        println!(
            "{name}: covered {}/{} = {:.1} %, rms error {:.3} sigma",
            t.covered,
            t.reported,
            100.0 * t.covered as f64 / t.reported.max(1) as f64,
            (t.z2 / t.reported.max(1) as f64).sqrt()
        );
        for (k, term) in Term::ALL.iter().enumerate() {
            if t.absent[k] > 0 {
                println!(
                    "  {} absent in {}, reported in {}",
                    term.symbol(),
                    t.absent[k],
                    t.false_reports[k]
                );
            }
        }
    }
    assert!(strided.reported >= 100, "{} reported", strided.reported);
    let coverage = strided.covered as f64 / strided.reported as f64;
    assert!(
        (0.90..=0.98).contains(&coverage),
        "strided coverage {:.1} % outside 90–98 %",
        100.0 * coverage
    );
    for (k, term) in Term::ALL.iter().enumerate() {
        let rate = strided.false_reports[k] as f64 / strided.absent[k].max(1) as f64;
        assert!(
            rate <= 0.05,
            "{} reported in {:.1} % of the records without it",
            term.symbol(),
            100.0 * rate
        );
    }
}
