//! Simulator benchmark: figures, not pass/fail.
//!
//!     cargo run --release -p triad-host --example bench_sim [-- SAMPLES]
//!
//! Prints samples per second for each shipped scene and for each effect alone,
//! the cost of an unnamed effect, bias-instability terms vs Allan-floor
//! flatness vs time per sample, and runs bench/sim_numpy.py (the same effects
//! in NumPy) in the same run to quote the ratio. A "sample" is one instant of
//! both triads (6 axes) plus temperature.

use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use triad_host::scene_file;
use triad_sim::effects::bias_instability::BiasInstabilityParams;
use triad_sim::effects::temperature_dependence::TemperatureDependence;
use triad_sim::motion::{Environment, Motion, Trajectory};
use triad_sim::scenes::scene::{GaussMarkovParams, Scene, TriadEffects};
use triad_sim::scenes::simulator::Simulator;

/// Runs `n` steps and returns samples per second (best of 3 runs, to skip
/// warm-up and scheduler noise on a shared machine).
fn rate(scene: &Scene, n: u64) -> f64 {
    let mut best = 0.0f64;
    for _ in 0..3 {
        let mut sim = Simulator::new(scene, 1).expect("valid scene");
        let start = Instant::now();
        let mut acc = 0.0;
        for _ in 0..n {
            let s = sim.step();
            acc += s.measured.specific_force[0] + s.measured.angular_rate[2];
        }
        black_box(acc);
        best = best.max(n as f64 / start.elapsed().as_secs_f64());
    }
    best
}

/// Samples per second writing CSV rows (as `triad sim` does) into a sink.
fn rate_with_csv(scene: &Scene, n: u64) -> f64 {
    let mut sim = Simulator::new(scene, 1).expect("valid scene");
    let mut w = std::io::BufWriter::new(std::io::sink());
    let start = Instant::now();
    for _ in 0..n {
        let s = sim.step();
        let m = s.measured;
        let [ax, ay, az] = m.specific_force;
        let [gx, gy, gz] = m.angular_rate;
        writeln!(w, "{},{ax},{ay},{az},{gx},{gy},{gz},{}", s.t, m.temperature).unwrap();
    }
    w.flush().unwrap();
    n as f64 / start.elapsed().as_secs_f64()
}

fn ns(rate: f64) -> f64 {
    1e9 / rate
}

/// Each effect with representative SI parameters; `gyro` adds g-sensitivity.
fn effect(name: &str, gyro: bool) -> TriadEffects {
    let mut e = TriadEffects::NONE;
    match name {
        "white_noise" => e.white_noise = Some([1e-3; 3]),
        "gauss_markov" => {
            e.gauss_markov = Some(GaussMarkovParams {
                sigma: [1e-3; 3],
                correlation_time: [100.0; 3],
            })
        }
        "random_walk" => e.random_walk = Some([1e-4; 3]),
        "bias_instability" => {
            e.bias_instability = Some([BiasInstabilityParams::with_default_band(1e-3); 3])
        }
        "constant_bias" => e.constant_bias = Some([1e-2, -2e-2, 3e-2]),
        "turn_on_bias" => e.turn_on_bias = Some([1e-2; 3]),
        "scale_misalignment" => {
            e.scale_misalignment =
                Some([[1e-3, 2e-4, -1e-4], [3e-4, -2e-3, 1e-4], [0.0, 5e-4, 5e-4]])
        }
        "turn_on_scale" => e.turn_on_scale = Some([1e-3; 3]),
        "temperature" => {
            e.temperature = Some(TemperatureDependence {
                reference: 25.0,
                bias_per_degree: [1e-3; 3],
                scale_per_degree: [1e-4; 3],
            })
        }
        "g_sensitivity" if gyro => {
            e.g_sensitivity = Some([[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]])
        }
        "increment_quantisation" => e.increment_quantisation = Some([1e-5; 3]),
        "output_lsb" => e.output_lsb = Some([1e-4; 3]),
        "saturation" => e.saturation = Some([100.0; 3]),
        _ => {}
    }
    e
}

const EFFECTS: [&str; 13] = [
    "white_noise",
    "gauss_markov",
    "random_walk",
    "bias_instability",
    "constant_bias",
    "turn_on_bias",
    "scale_misalignment",
    "turn_on_scale",
    "temperature",
    "g_sensitivity",
    "increment_quantisation",
    "output_lsb",
    "saturation",
];

/// Every effect at once.
fn all_effects(gyro: bool) -> TriadEffects {
    let mut e = TriadEffects::NONE;
    for name in EFFECTS {
        let x = effect(name, gyro);
        macro_rules! take {
            ($($f:ident),*) => { $( if x.$f.is_some() { e.$f = x.$f; } )* };
        }
        take!(
            white_noise,
            gauss_markov,
            random_walk,
            bias_instability,
            constant_bias,
            turn_on_bias,
            scale_misalignment,
            turn_on_scale,
            temperature,
            g_sensitivity,
            increment_quantisation,
            output_lsb,
            saturation
        );
    }
    e
}

fn static_scene() -> Scene {
    Scene::new(1000.0, Motion::Static { attitude: [0.0; 3] })
}

fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2_000_000);
    println!("triad simulator benchmark: {n} samples per figure (one sample = 6 axes + temperature), best of 3\n");
    shipped_scenes(n);
    let rates = each_effect(n);
    unnamed_cost(n, &rates);
    bias_instability_terms(n);
    numpy(n, &rates);
}

/// 1. Shipped scenes: samples per second, with CSV, and an hour's time.
fn shipped_scenes(n: u64) {
    println!("== Shipped scenes ==");
    println!(
        "{:<16} {:>14} {:>10} {:>18} {:>14}",
        "scene", "samples/s", "ns/sample", "with CSV, samples/s", "1 h at rate in"
    );
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    for path in &names {
        let loaded = scene_file::load(path.to_str().unwrap()).expect("shipped scene loads");
        let r = rate(&loaded.scene, n);
        let r_csv = rate_with_csv(&loaded.scene, n / 4);
        let hour = 3600.0 * loaded.scene.rate_hz;
        println!(
            "{:<16} {:>14.0} {:>10.1} {:>18.0} {:>12.2} s",
            path.file_stem().unwrap().to_string_lossy(),
            r,
            ns(r),
            r_csv,
            hour / r_csv
        );
    }
}

/// The rates of section 2, which sections 3 and 5 quote.
struct EffectRates {
    /// No effect named.
    base: f64,
    /// `Simulator::step_truth`.
    truth: f64,
    /// `Trajectory::at`.
    motion: f64,
    /// Each effect alone.
    each: Vec<(&'static str, f64)>,
    /// All of them.
    all: f64,
}

/// Samples per second of the truth alone and of the motion alone.
fn truth_and_motion_rates(n: u64) -> (f64, f64) {
    let mut truth_only = Simulator::new(&static_scene(), 1).unwrap();
    let start = Instant::now();
    for _ in 0..n {
        black_box(truth_only.step_truth());
    }
    let truth_rate = n as f64 / start.elapsed().as_secs_f64();
    let traj = Trajectory::new(
        &Motion::Static { attitude: [0.0; 3] },
        &Environment::default(),
    );
    let start = Instant::now();
    for k in 0..n {
        black_box(traj.at(black_box(k as f64 * 1e-3)));
    }
    (truth_rate, n as f64 / start.elapsed().as_secs_f64())
}

/// A row of the effects table: rate, time per sample, time over none.
fn effect_row(name: &str, r: f64, base: f64) {
    println!(
        "{:<20} {:>14.0} {:>10.2} {:>14.2}",
        name,
        r,
        ns(r),
        ns(r) - ns(base)
    );
}

/// 2. Each effect alone (both triads), static scene at 1 kHz.
fn each_effect(n: u64) -> EffectRates {
    println!("\n== Each effect alone (both triads, static, 1 kHz) ==");
    let base = rate(&static_scene(), n);
    let (truth, motion) = truth_and_motion_rates(n);
    println!(
        "{:<20} {:>14} {:>10} {:>14}",
        "effect", "samples/s", "ns/sample", "ns over none"
    );
    println!(
        "{:<20} {:>14.0} {:>10.2} {:>14}",
        "(none)",
        base,
        ns(base),
        "-"
    );
    let mut each = Vec::new();
    for name in EFFECTS {
        let mut s = static_scene();
        s.accel = effect(name, false);
        s.gyro = effect(name, true);
        let r = rate(&s, n);
        each.push((name, r));
        effect_row(name, r, base);
    }
    let mut s = static_scene();
    s.accel = all_effects(false);
    s.gyro = all_effects(true);
    let all = rate(&s, n);
    effect_row("all of them", all, base);
    EffectRates {
        base,
        truth,
        motion,
        each,
        all,
    }
}

/// 3. The cost of an unnamed effect.
fn unnamed_cost(n: u64, rates: &EffectRates) {
    let base = rates.base;
    println!("\n== The cost of an unnamed effect ==");
    println!(
        "motion only (Trajectory::at):           {:>8.2} ns/sample",
        ns(rates.motion)
    );
    println!(
        "truth only (Simulator::step_truth):     {:>8.2} ns/sample",
        ns(rates.truth)
    );
    // Every effect of both triads.
    let unnamed = 2 * EFFECTS.len();
    println!(
        "all {unnamed} effects unnamed (Simulator::step): {:>6.2} ns/sample",
        ns(base)
    );
    println!(
        "=> {unnamed} unnamed effects together cost {:.2} ns/sample over truth only ({:.3} ns each): one `None` test each, no arithmetic",
        ns(base) - ns(rates.truth),
        (ns(base) - ns(rates.truth)) / unnamed as f64
    );
    let mut zero = static_scene();
    zero.accel.white_noise = Some([0.0; 3]);
    zero.gyro.white_noise = Some([0.0; 3]);
    let zero_rate = rate(&zero, n);
    println!(
        "for contrast, white noise named with density 0 (a multiply by zero): {:.2} ns/sample, {:.2} ns over unnamed",
        ns(zero_rate),
        ns(zero_rate) - ns(base)
    );
}

/// 4. Bias-instability terms vs Allan-floor flatness vs time per sample.
fn bias_instability_terms(n: u64) {
    println!("\n== Bias instability: terms vs Allan-floor flatness (default band 0.01 s–10⁵ s) vs time ==");
    println!(
        "{:>5} {:>22} {:>18} {:>12}",
        "terms", "σ_A/(0.664B) min–max", "worst deviation", "ns/sample"
    );
    for terms in [1u8, 2, 3, 4, 5, 6, 7, 9, 11, 13, 16] {
        let p = BiasInstabilityParams {
            terms,
            ..BiasInstabilityParams::with_default_band(1e-3)
        };
        let (lo, hi) = p.flatness();
        let mut s = static_scene();
        s.accel.bias_instability = Some([p; 3]);
        s.gyro.bias_instability = Some([p; 3]);
        let r = rate(&s, n / 2);
        let worst = (1.0 - lo).max(hi - 1.0) * 100.0;
        println!(
            "{terms:>5} {:>10.3} – {:<9.3} {:>16.2} % {:>12.1}",
            lo,
            hi,
            worst,
            ns(r)
        );
    }
}

/// The output of bench/sim_numpy.py for `n` samples ("effect samples_per_second"
/// lines), or None (said why) when it cannot run.
fn numpy_output(n: u64) -> Option<String> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/sim_numpy.py");
    // The same interpreter variable as bench_allan: a venv with NumPy.
    let python = std::env::var("TRIAD_PYTHON").unwrap_or_else(|_| "python3".into());
    let out = Command::new(&python)
        .arg(&script)
        .arg("--samples")
        .arg(n.to_string())
        .output();
    match out {
        Ok(o) if o.status.success() => Some(String::from_utf8_lossy(&o.stdout).into_owned()),
        Ok(o) => {
            println!(
                "{python} {} failed: {}",
                script.display(),
                String::from_utf8_lossy(&o.stderr).trim()
            );
            println!("(install NumPy with `pip install numpy` to get the comparison)");
            None
        }
        Err(e) => {
            println!("{python} not runnable ({e}); no NumPy comparison");
            None
        }
    }
}

/// 5. NumPy, same effects, same run.
fn numpy(n: u64, rates: &EffectRates) {
    println!("\n== Side by side with NumPy (bench/sim_numpy.py) ==");
    let Some(out) = numpy_output(n) else {
        return;
    };
    println!(
        "{:<20} {:>14} {:>14} {:>10}",
        "effect", "Rust samples/s", "NumPy samples/s", "Rust/NumPy"
    );
    let mut rows: Vec<(String, f64)> = rates
        .each
        .iter()
        .map(|(k, v)| (k.to_string(), *v))
        .collect();
    rows.push(("all".to_string(), rates.all));
    for line in out.lines() {
        let mut parts = line.split_whitespace();
        let (Some(name), Some(v)) = (parts.next(), parts.next()) else {
            continue;
        };
        let Ok(np_rate) = v.parse::<f64>() else {
            println!("{line}");
            continue;
        };
        if let Some((_, rust)) = rows.iter().find(|(k, _)| k == name) {
            println!(
                "{:<20} {:>14.0} {:>14.0} {:>9.1}×",
                name,
                rust,
                np_rate,
                rust / np_rate
            );
        }
    }
}
