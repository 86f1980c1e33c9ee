//! Random walk (rate / acceleration random walk): variance grows as K²·t.

use triad_sim::effects::random_walk::RandomWalk;
use triad_sim::effects::rng::Rng;

#[test]
fn variance_grows_as_k_squared_t() {
    // Ensemble of M = 2000 walks from zero; at each checked time the
    // zero-mean variance estimate has relative SE √(2/M) = 3.2 %; 5 SE = 16 %.
    // A walk whose step used Ts instead of √Ts would be off by 10× here.
    let m = 2000;
    let k = 0.05;
    let ts = 0.01;
    let mut walks: Vec<(RandomWalk, Rng)> = (0..m)
        .map(|i| (RandomWalk::new(k, ts), Rng::from_seed(5000 + i as u64)))
        .collect();
    let mut done = 0;
    for steps in [100usize, 1000, 5000] {
        let values: Vec<f64> = walks
            .iter_mut()
            .map(|(w, rng)| {
                for _ in done..steps {
                    w.step(rng);
                }
                w.state()
            })
            .collect();
        done = steps;
        let t = steps as f64 * ts;
        let var = values.iter().map(|v| v * v).sum::<f64>() / m as f64;
        let theory = k * k * t;
        let tol = 5.0 * (2.0 / m as f64).sqrt();
        assert!(
            ((var - theory) / theory).abs() < tol,
            "t = {t} s: variance {var}, theory {theory}"
        );
    }
}
