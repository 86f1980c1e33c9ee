//! Sampled white noise: per-sample variance σ_n²/Ts, no correlation between
//! samples, and the angle random walk it integrates to.

use triad::units::{
    deg_per_s_per_sqrt_hz_to_deg_per_sqrt_h, deg_to_rad, rad_to_deg, random_walk_sigma,
};
use triad_sim::effects::rng::Rng;
use triad_sim::effects::white_noise::WhiteNoise;
use triad_sim::motion::Motion;
use triad_sim::scenes::scene::{Scene, TriadEffects};
use triad_sim::scenes::simulator::Simulator;

#[test]
fn sampled_variance_is_density_squared_over_ts() {
    // N = 200 000 samples of a zero-mean normal: the variance estimate has
    // relative SE √(2/N) = 0.32 %, so 5 SE = 1.6 %. Two sample periods a
    // decade apart check the 1/Ts law (a √Ts or Ts error is off by 3×–10×).
    // The lag-1 autocorrelation of white noise has SE 1/√N; 5 SE bound.
    let n = 200_000;
    let density = 0.3;
    for (i, ts) in [1e-2, 1e-3].into_iter().enumerate() {
        let wn = WhiteNoise::new(density, ts);
        let mut rng = Rng::from_seed(40 + i as u64);
        let xs: Vec<f64> = (0..n).map(|_| wn.sample(&mut rng)).collect();
        let var = xs.iter().map(|x| x * x).sum::<f64>() / n as f64;
        let theory = density * density / ts;
        let tol = 5.0 * (2.0 / n as f64).sqrt();
        assert!(
            ((var - theory) / theory).abs() < tol,
            "Ts = {ts}: variance {var}, theory {theory}"
        );
        let r1 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1) as f64 / var;
        assert!(
            r1.abs() < 5.0 / (n as f64).sqrt(),
            "lag-1 autocorrelation {r1}"
        );
    }
}

#[test]
fn arw_example_0_99_deg_per_s_per_sqrt_hz() {
    // 0.99 (°/s)/√Hz = 0.99 °/√s = 0.99·60 °/√h = 59.4 °/√h, and after 1000 s
    // the integrated angle has σ_θ = 0.99·√1000 = 31.3°.
    let arw = 0.99;
    assert!((deg_per_s_per_sqrt_hz_to_deg_per_sqrt_h(arw) - 59.4).abs() < 1e-12);
    let sigma_theta = random_walk_sigma(arw, 1000.0);
    assert!((sigma_theta - 31.306_548_835_745_3).abs() < 1e-9);

    // End to end through the simulator: a static gyro with this white noise
    // only, no Earth rate, so the measured rate is the noise alone.
    // R = 1000 independent 1000 s windows at 10 Hz; θ = Σω·Ts per window.
    // The SD estimate from R samples has relative SE 1/√(2R) = 2.2 %; 5 SE = 11 %.
    let rate = 10.0;
    let mut scene = Scene::new(rate, Motion::Static { attitude: [0.0; 3] });
    scene.gyro = TriadEffects {
        white_noise: Some([deg_to_rad(arw); 3]),
        ..TriadEffects::NONE
    };
    let mut sim = Simulator::new(&scene, 2024).unwrap();
    let ts = sim.sample_period();
    let windows = 1000;
    let per_window = (1000.0 * rate) as usize;
    let mut sum2 = 0.0;
    for _ in 0..windows {
        let mut theta = 0.0;
        for _ in 0..per_window {
            theta += sim.step().measured.angular_rate[0] * ts;
        }
        sum2 += rad_to_deg(theta).powi(2);
    }
    let sd = (sum2 / windows as f64).sqrt();
    let tol = 5.0 / (2.0 * windows as f64).sqrt();
    assert!(
        ((sd - sigma_theta) / sigma_theta).abs() < tol,
        "σ_θ(1000 s) = {sd}°, theory {sigma_theta}°"
    );
}
