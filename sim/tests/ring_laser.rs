//! The ring laser gyro: its scale factor and fringe angle from the
//! geometry, lock-in below Ω_L (and the beat above it) without dither, the
//! dither breaking the lock-in and leaving the random walk of its passages,
//! whose size per passage is Adler's equation's (integrated here).

use triad_sim::effects::rng::Rng;
use triad_sim::optics::ring_laser::{Dither, RingLaser, RingLaserParams};

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// A triangular cavity of side `side` m at 632.8 nm.
fn triangle(side: f64, lock_in: f64, dither: Option<Dither>) -> RingLaserParams {
    RingLaserParams {
        area: 3f64.sqrt() / 4.0 * side * side,
        path_length: 3.0 * side,
        wavelength: 632.8e-9,
        lock_in,
        dither,
    }
}

#[test]
fn the_fringe_angle_and_scale_factor_come_from_the_geometry() {
    // Triangle: Lλ/(4A) = √3·λ/side; 10 cm gives 2.26 arcsec, 6 cm 3.77
    // (THEORY.md: typically 2–5 arc-seconds per fringe).
    for (side, arcsec) in [(0.1, 2.2608), (0.06, 3.7680)] {
        let p = triangle(side, 0.0, None);
        assert!(
            (p.fringe_angle() / ARCSEC - arcsec).abs() < 1e-3,
            "{}",
            p.fringe_angle() / ARCSEC
        );
        assert!((p.fringes_per_rad() * p.fringe_angle() - 1.0).abs() < 1e-15);
        assert!((p.fringes_per_rad() - 4.0 * p.area / (p.path_length * p.wavelength)).abs() < 1e-9);
    }
    // On a rate table at 1 rad/s for 10 s (no lock-in), the fringes
    // counted are 4A/(Lλ)·ω·T to within one.
    let p = triangle(0.1, 0.0, None);
    let mut axis = RingLaser::new(p, Rng::from_seed(1));
    let (rate, ts, samples) = (1.0, 0.001, 10_000);
    let mut counts = 0.0;
    for _ in 0..samples {
        let sensed = axis.sense(rate, ts);
        counts += axis.count(sensed, ts).0;
    }
    let expected = p.fringes_per_rad() * rate * ts * samples as f64;
    assert!(
        (counts - expected).abs() <= 1.0,
        "{counts} fringes, expected {expected}"
    );
}

#[test]
fn undithered_the_lock_in_holds_below_omega_l_and_beats_above() {
    // A sweep from −3Ω_L to 3Ω_L: over 100 s the mean reported rate is the
    // locked rate, 0 inside the band and √(ω² − Ω_L²) outside, to within
    // one fringe over the time.
    let omega_l = 0.1f64.to_radians();
    let p = triangle(0.1, omega_l, None);
    let (ts, samples) = (0.01, 10_000);
    for i in -12i32..=12 {
        let rate = omega_l * i as f64 / 4.0;
        let mut axis = RingLaser::new(p, Rng::from_seed(2));
        let mut angle = 0.0;
        for _ in 0..samples {
            let sensed = axis.sense(rate, ts);
            angle += axis.count(sensed, ts).1 * ts;
        }
        let mean = angle / (ts * samples as f64);
        let expected = p.locked_rate(rate);
        let bound = p.fringe_angle() / (ts * samples as f64);
        assert!(
            (mean - expected).abs() <= bound,
            "ω {rate}: {mean} vs {expected}"
        );
        if i.abs() < 4 {
            assert_eq!(mean, 0.0, "locked at {rate}");
        }
    }
}

/// `windows` records of `seconds` each at rate `rate` through a dithered
/// axis sampled every `ts`: the counted angle minus the true one at the end
/// of each.
fn angle_errors(p: RingLaserParams, rate: f64, ts: f64, seconds: f64, windows: u64) -> Vec<f64> {
    let per = (seconds / ts).round() as u64;
    (0..windows)
        .map(|seed| {
            let mut axis = RingLaser::new(p, Rng::from_seed(1000 + seed));
            let mut angle = 0.0;
            for _ in 0..per {
                let sensed = axis.sense(rate, ts);
                angle += axis.count(sensed, ts).1 * ts;
            }
            angle - rate * ts * per as f64
        })
        .collect()
}

/// Ω_L = 0.1 °/s, dither 100 °/s peak at 400 Hz, 6 cm cavity.
fn dithered() -> RingLaserParams {
    let dither = Dither {
        peak_rate: 100f64.to_radians(),
        frequency: 400.0,
    };
    triangle(0.06, 0.1f64.to_radians(), Some(dither))
}

/// Prints a measured variance against the expected one and asserts their
/// relative difference is within `bound`.
fn assert_variance(what: &str, var: f64, expected: f64, bound: f64) {
    let rel = var / expected - 1.0;
    println!(
        "{what}: variance {var:.4e}, expected {expected:.4e} ({:+.2} %, bound {:.2} %)",
        100.0 * rel,
        100.0 * bound
    );
    assert!(rel.abs() < bound, "{what}: {var} vs {expected}");
}

#[test]
fn the_dither_breaks_the_lock_in_and_leaves_the_random_walk_of_its_passages() {
    // N = Ω_L/√(KΩ_D). An input of 0.3·Ω_L (locked without dither) is
    // counted; the angle error over 20 s has variance N²·20 s plus the
    // counting error's 2·Δθ²/12 (its two ends). Sampled at 10 Hz (80
    // passages a sample, one normal deviate). 2000 windows: the variance
    // is measured to √(2/2000) = 3.2 %; the bound is 4 of those. 0.2 s.
    let p = dithered();
    let n = p.dither_random_walk();
    println!(
        "N = {n:.3e} rad/sqrt(s) = {:.4} deg/sqrt(h)",
        n.to_degrees() * 60.0
    );
    let (seconds, windows, ts) = (20.0, 2000, 0.1);
    let rate = 0.3 * p.lock_in;
    let errors = angle_errors(p, rate, ts, seconds, windows);
    let mean = errors.iter().sum::<f64>() / windows as f64;
    let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (windows - 1) as f64;
    let expected = n * n * seconds + p.fringe_angle().powi(2) / 6.0;
    assert_variance(
        "20 s angle error",
        var,
        expected,
        4.0 * (2.0 / windows as f64).sqrt(),
    );
    // Not locked: the mean angle error is the walk's, not −rate·T.
    let se = (var / windows as f64).sqrt();
    assert!(mean.abs() < 4.0 * se, "mean error {mean} (± {se})");
    assert!(
        rate * seconds > 100.0 * se,
        "a locked gyro would fail the line above"
    );
}

#[test]
fn passages_drawn_one_by_one_have_the_walks_variance() {
    // At 100 Hz a sample holds 8 passages, drawn one by one: the error a
    // sample adds has variance 8·A²/2 = N²·Ts. 250 000 samples: the sum of
    // 8 arcsine deviates has kurtosis 2.81, so the variance is measured to
    // √(1.81/250 000) = 0.27 %; bound 4 of those.
    let p = dithered();
    let ts = 0.01;
    let mut axis = RingLaser::new(p, Rng::from_seed(4));
    let samples = 250_000;
    let var = (0..samples)
        .map(|_| (axis.sense(0.0, ts) * ts).powi(2))
        .sum::<f64>()
        / samples as f64;
    let expected = p.dither_random_walk().powi(2) * ts;
    assert_variance(
        "per-sample error",
        var,
        expected,
        4.0 * (1.81 / samples as f64).sqrt(),
    );
}

#[test]
fn adlers_equation_gives_the_passage_error() {
    // dψ/ds = K(Ω̇s − Ω_L sin ψ) integrated (RK4) through one passage of
    // the rate through zero, from s = −T to T, for 16 phases ψ_c at the
    // passage: the angle error (ψ(T) less its value without lock-in, over
    // K) is −Ω_L·√(2π/(KΩ̇))·sin(ψ_c + π/4), the error the model draws.
    // Small K (100 fringes/rad) and Ω_L (δψ ≈ 0.013 rad: first order holds
    // to ~1 %), T = 0.5 s (the Fresnel tails beyond it are 0.3 % of the
    // error); tolerance 3 % of the amplitude.
    let fringes_per_rad = 100.0;
    let k = 2.0 * std::f64::consts::PI * fringes_per_rad;
    let (slope, omega_l, t_end) = (100.0, 0.002, 0.5f64);
    // The model's amplitude for the same K and Ω̇ (a dither with 2π·f·Ω_D = Ω̇).
    let p = RingLaserParams {
        area: fringes_per_rad,
        path_length: 4.0,
        wavelength: 1.0,
        lock_in: omega_l,
        dither: Some(Dither {
            peak_rate: slope / (2.0 * std::f64::consts::PI),
            frequency: 1.0,
        }),
    };
    assert!((p.fringes_per_rad() - fringes_per_rad).abs() < 1e-12);
    let amplitude = p.passage_error_amplitude();
    let f = |s: f64, psi: f64| k * (slope * s - omega_l * psi.sin());
    let h = 2e-6;
    let steps = (2.0 * t_end / h).round() as usize;
    let mut worst: f64 = 0.0;
    for j in 0..16 {
        let psi_c = 2.0 * std::f64::consts::PI * j as f64 / 16.0;
        let free = |s: f64| psi_c + k * slope * s * s / 2.0;
        let mut psi = free(-t_end);
        let mut s = -t_end;
        for _ in 0..steps {
            let k1 = f(s, psi);
            let k2 = f(s + h / 2.0, psi + h / 2.0 * k1);
            let k3 = f(s + h / 2.0, psi + h / 2.0 * k2);
            let k4 = f(s + h, psi + h * k3);
            psi += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            s += h;
        }
        let error = (psi - free(s)) / k;
        let model = -amplitude * (psi_c + std::f64::consts::FRAC_PI_4).sin();
        worst = worst.max((error - model).abs() / amplitude);
    }
    println!(
        "passage error vs Adler's equation: worst {:.2} % of the amplitude",
        100.0 * worst
    );
    assert!(worst < 0.03, "{worst}");
}

#[test]
fn optical_models_are_gyro_only_one_at_a_time_and_count_once() {
    use triad_sim::motion::Motion;
    use triad_sim::scenes::scene::{Scene, SceneError, TriadEffects};
    let ring = TriadEffects {
        ring_laser: Some(dithered()),
        ..TriadEffects::NONE
    };
    let mut scene = Scene::new(100.0, Motion::Static { attitude: [0.0; 3] });
    scene.gyro = ring;
    assert_eq!(scene.validate(), Ok(()));
    scene.accel = ring;
    assert_eq!(scene.validate(), Err(SceneError::OpticalOnAccel));
    scene.accel = TriadEffects::NONE;
    scene.gyro.increment_quantisation = Some([1e-5; 3]);
    assert_eq!(scene.validate(), Err(SceneError::CountedTwice));
    scene.gyro.increment_quantisation = None;
    scene.gyro.ring_laser = Some(RingLaserParams {
        wavelength: 0.0,
        ..dithered()
    });
    assert!(matches!(
        scene.validate(),
        Err(SceneError::NotPositive {
            what: "ring_laser wavelength",
            ..
        })
    ));
    assert!(SceneError::CountedTwice
        .to_string()
        .contains("counts its fringes itself"));
}
