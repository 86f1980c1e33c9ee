//! Angle (velocity) quantisation counts whole steps of the integrated
//! output: no angle is lost however long the record, each sample is a whole
//! number of steps, and a step of zero passes the rate through.

use triad_sim::effects::increment_quantisation::IncrementQuantiser;
use triad_sim::effects::rng::Rng;

#[test]
fn the_counted_angle_stays_within_a_step_of_the_true_one() {
    let (step, ts) = (1e-5, 0.01);
    let mut q = IncrementQuantiser::new(step);
    let mut rng = Rng::from_seed(9);
    let (mut truth, mut counted) = (0.0, 0.0);
    for k in 0..1_000_000 {
        // A turn of 0.3 rad/s with noise, reversing every 1000 samples.
        let sign = if (k / 1000) % 2 == 0 { 1.0 } else { -1.0 };
        let rate = sign * 0.3 + 1e-3 * rng.gaussian();
        let (counts, out) = q.step(rate, ts);
        assert_eq!(counts, counts.round(), "whole steps");
        assert!((out - counts * step / ts).abs() <= 1e-12 * out.abs());
        truth += rate * ts;
        counted += counts * step;
        // Started half a step in: the count trails the angle by [−½, ½) step.
        let lag = truth - counted;
        assert!(
            (-0.5 * step - 1e-9..0.5 * step + 1e-9).contains(&lag),
            "k {k}: {lag}"
        );
    }
}

#[test]
fn a_step_of_zero_passes_the_rate_through() {
    let mut q = IncrementQuantiser::new(0.0);
    assert_eq!(q.step(0.123, 0.01), (0.0, 0.123));
}

#[test]
fn a_slow_input_counts_a_step_only_when_it_has_turned_one() {
    // 0.1 step per sample: a count every ten samples, none in between.
    let (step, ts) = (1.0, 1.0);
    let mut q = IncrementQuantiser::new(step);
    let counts: Vec<f64> = (0..40).map(|_| q.step(0.1, ts).0).collect();
    assert_eq!(counts.iter().sum::<f64>(), 4.0);
    assert!(counts.iter().all(|&c| c == 0.0 || c == 1.0));
}
