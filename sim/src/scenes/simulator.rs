//! The simulator: a scene's truth plus only the error effects the scene names.
//!
//! Per triad and sample, in this order (each step skipped entirely when its
//! effect is `None`):
//!
//! 1. scale: x·(1 + s_T(T)) (temperature), ·(1 + s_0) (turn-on), (I + Σ)·x;
//! 2. biases: constant, turn-on, temperature, Gauss–Markov, random walk, bias
//!    instability, g-sensitivity (gyros: G·f_true);
//! 3. an optical gyro's optics on that rate: a fibre-optic gyro's response
//!    ([`crate::optics::fibre_optic`]), a ring laser's lock-in or dither
//!    ([`crate::optics::ring_laser`]);
//! 4. white noise;
//! 5. a ring laser's fringe counting, or angle (velocity) quantisation: the
//!    output integrated, counted in whole steps, differenced
//!    ([`crate::effects::increment_quantisation`]);
//! 6. the output register's LSB ([`crate::effects::output_lsb`]), then saturation.
//!
//! Each stochastic effect draws from its own stream, keyed by (seed, triad,
//! axis, effect) (see [`crate::effects::rng`]), so naming or removing one effect leaves
//! every other effect's contribution bit-identical.

use super::scene::{Scene, SceneError, TriadEffects};
use super::temperature_profile::TemperatureProfile;
use crate::chips::source::{SampleSource, TrueSample};
use crate::effects::bias::draw_turn_on;
use crate::effects::bias_instability::BiasInstability;
use crate::effects::g_sensitivity::rate_error;
use crate::effects::gauss_markov::GaussMarkov;
use crate::effects::increment_quantisation::IncrementQuantiser;
use crate::effects::output_lsb::round_to_lsb;
use crate::effects::random_walk::RandomWalk;
use crate::effects::rng::{EffectId, Rng};
use crate::effects::saturation::saturate;
use crate::effects::scale_misalignment;
use crate::effects::temperature_dependence::TemperatureDependence;
use crate::effects::white_noise::WhiteNoise;
use crate::motion::Trajectory;
use crate::optics::fibre_optic::FibreOpticParams;
use crate::optics::ring_laser::RingLaser;
use triad::model::Triad;

/// The last additive contribution of each stochastic or bias effect of one
/// triad (zero for effects that are off), for inspection and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Contributions {
    /// White noise.
    pub white_noise: [f64; 3],
    /// Gauss–Markov bias.
    pub gauss_markov: [f64; 3],
    /// Random walk.
    pub random_walk: [f64; 3],
    /// Bias instability.
    pub bias_instability: [f64; 3],
    /// Turn-on bias (constant over the run).
    pub turn_on_bias: [f64; 3],
    /// Turn-on scale-factor error (ratio, constant over the run).
    pub turn_on_scale: [f64; 3],
}

/// One simulated instant: the truth and what the sensor measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimSample {
    /// Time since the start, seconds (k·Ts).
    pub t: f64,
    /// What an ideal sensor would measure.
    pub truth: TrueSample,
    /// What the simulated sensor measures (the scene's effects applied).
    pub measured: TrueSample,
}

fn streams(seed: u64, triad: Triad, effect: EffectId) -> [Rng; 3] {
    [
        Rng::for_stream(seed, triad, 0, effect),
        Rng::for_stream(seed, triad, 1, effect),
        Rng::for_stream(seed, triad, 2, effect),
    ]
}

/// The running state of one triad's effects.
#[derive(Clone, Copy, Debug)]
struct TriadState {
    white_noise: Option<([WhiteNoise; 3], [Rng; 3])>,
    gauss_markov: Option<([GaussMarkov; 3], [Rng; 3])>,
    random_walk: Option<([RandomWalk; 3], [Rng; 3])>,
    bias_instability: Option<([BiasInstability; 3], [Rng; 3])>,
    constant_bias: Option<[f64; 3]>,
    turn_on_bias: Option<[f64; 3]>,
    turn_on_scale: Option<[f64; 3]>,
    scale_misalignment: Option<[[f64; 3]; 3]>,
    temperature: Option<TemperatureDependence>,
    g_sensitivity: Option<[[f64; 3]; 3]>,
    fibre_optic: Option<FibreOpticParams>,
    ring_laser: Option<[RingLaser; 3]>,
    increment_quantisation: Option<[IncrementQuantiser; 3]>,
    output_lsb: Option<[f64; 3]>,
    saturation: Option<[f64; 3]>,
    /// False when the scene names no effect for this triad: `measure` is
    /// then skipped with one test instead of twelve.
    active: bool,
    contributions: Contributions,
}

impl TriadState {
    fn new(effects: &TriadEffects, triad: Triad, seed: u64, ts: f64) -> Self {
        let mut contributions = Contributions::default();
        let white_noise = effects.white_noise.map(|n| {
            let rngs = streams(seed, triad, EffectId::WhiteNoise);
            (n.map(|d| WhiteNoise::new(d, ts)), rngs)
        });
        let gauss_markov = effects.gauss_markov.map(|p| {
            let mut rngs = streams(seed, triad, EffectId::GaussMarkov);
            let gm = core::array::from_fn(|i| {
                GaussMarkov::new_stationary(p.sigma[i], p.correlation_time[i], ts, &mut rngs[i])
            });
            (gm, rngs)
        });
        let random_walk = effects.random_walk.map(|k| {
            let rngs = streams(seed, triad, EffectId::RandomWalk);
            (k.map(|k| RandomWalk::new(k, ts)), rngs)
        });
        let bias_instability = effects.bias_instability.map(|p| {
            let mut rngs = streams(seed, triad, EffectId::BiasInstability);
            let bi = core::array::from_fn(|i| BiasInstability::new(&p[i], ts, &mut rngs[i]));
            (bi, rngs)
        });
        let turn_on_bias = effects.turn_on_bias.map(|sigma| {
            let b = draw_turn_on(&sigma, &mut streams(seed, triad, EffectId::TurnOnBias));
            contributions.turn_on_bias = b;
            b
        });
        let turn_on_scale = effects.turn_on_scale.map(|sigma| {
            let s = draw_turn_on(&sigma, &mut streams(seed, triad, EffectId::TurnOnScale));
            contributions.turn_on_scale = s;
            s
        });
        Self {
            white_noise,
            gauss_markov,
            random_walk,
            bias_instability,
            constant_bias: effects.constant_bias,
            turn_on_bias,
            turn_on_scale,
            scale_misalignment: effects.scale_misalignment,
            temperature: effects.temperature,
            g_sensitivity: effects.g_sensitivity,
            fibre_optic: effects.fibre_optic,
            ring_laser: effects.ring_laser.map(|p| {
                let rngs = streams(seed, triad, EffectId::RingLaser);
                rngs.map(|rng| RingLaser::new(p, rng))
            }),
            increment_quantisation: effects
                .increment_quantisation
                .map(|s| s.map(IncrementQuantiser::new)),
            output_lsb: effects.output_lsb,
            saturation: effects.saturation,
            active: !effects.is_none(),
            contributions,
        }
    }

    /// The measurement of `truth` at temperature `temp`; `f_true` is the true
    /// specific force (for g-sensitivity).
    fn measure(&mut self, truth: [f64; 3], temp: f64, f_true: &[f64; 3], ts: f64) -> [f64; 3] {
        let mut y = truth;
        if !self.active {
            return y;
        }
        if let Some(td) = &self.temperature {
            y = scale_misalignment::apply_diagonal(&td.scale(temp), y);
        }
        if let Some(s) = &self.turn_on_scale {
            y = scale_misalignment::apply_diagonal(s, y);
        }
        if let Some(m) = &self.scale_misalignment {
            y = scale_misalignment::apply(m, y);
        }
        if let Some(b) = &self.constant_bias {
            add(&mut y, b);
        }
        if let Some(b) = &self.turn_on_bias {
            add(&mut y, b);
        }
        if let Some(td) = &self.temperature {
            add(&mut y, &td.bias(temp));
        }
        if let Some((gm, rngs)) = &mut self.gauss_markov {
            let c = core::array::from_fn(|i| gm[i].step(&mut rngs[i]));
            self.contributions.gauss_markov = c;
            add(&mut y, &c);
        }
        if let Some((rw, rngs)) = &mut self.random_walk {
            let c = core::array::from_fn(|i| rw[i].step(&mut rngs[i]));
            self.contributions.random_walk = c;
            add(&mut y, &c);
        }
        if let Some((bi, rngs)) = &mut self.bias_instability {
            let c = core::array::from_fn(|i| bi[i].step(&mut rngs[i]));
            self.contributions.bias_instability = c;
            add(&mut y, &c);
        }
        if let Some(g) = &self.g_sensitivity {
            add(&mut y, &rate_error(g, f_true));
        }
        if let Some(f) = &self.fibre_optic {
            y = y.map(|w| f.output(w, temp));
        }
        if let Some(rl) = &mut self.ring_laser {
            y = core::array::from_fn(|i| rl[i].sense(y[i], ts));
        }
        if let Some((wn, rngs)) = &mut self.white_noise {
            let c = core::array::from_fn(|i| wn[i].sample(&mut rngs[i]));
            self.contributions.white_noise = c;
            add(&mut y, &c);
        }
        if let Some(rl) = &mut self.ring_laser {
            y = core::array::from_fn(|i| rl[i].count(y[i], ts).1);
        }
        if let Some(q) = &mut self.increment_quantisation {
            y = core::array::from_fn(|i| q[i].step(y[i], ts).1);
        }
        if let Some(lsb) = &self.output_lsb {
            y = core::array::from_fn(|i| round_to_lsb(y[i], lsb[i]));
        }
        if let Some(range) = &self.saturation {
            y = core::array::from_fn(|i| saturate(y[i], range[i]));
        }
        y
    }
}

fn add(y: &mut [f64; 3], c: &[f64; 3]) {
    y[0] += c[0];
    y[1] += c[1];
    y[2] += c[2];
}

/// Produces a scene's samples one at a time (no allocation; a few kB of state).
#[derive(Clone, Copy, Debug)]
pub struct Simulator {
    ts: f64,
    index: u64,
    trajectory: Trajectory,
    temperature: TemperatureProfile,
    accel: TriadState,
    gyro: TriadState,
}

impl Simulator {
    /// A simulator of `scene` whose random streams all derive from `seed`.
    pub fn new(scene: &Scene, seed: u64) -> Result<Self, SceneError> {
        scene.validate()?;
        let ts = 1.0 / scene.rate_hz;
        Ok(Self {
            ts,
            index: 0,
            trajectory: Trajectory::new(&scene.motion, &scene.environment),
            temperature: scene.temperature,
            accel: TriadState::new(&scene.accel, Triad::Accel, seed, ts),
            gyro: TriadState::new(&scene.gyro, Triad::Gyro, seed, ts),
        })
    }

    /// The sample period Ts, seconds.
    pub fn sample_period(&self) -> f64 {
        self.ts
    }

    /// How many samples have been produced.
    pub fn samples_done(&self) -> u64 {
        self.index
    }

    /// The truth at the next instant, without advancing any effect.
    fn next_truth(&self) -> (f64, TrueSample) {
        // t = k·Ts, not a running sum: no drift over hours of samples.
        let t = self.index as f64 * self.ts;
        let k = self.trajectory.at(t);
        let truth = TrueSample {
            specific_force: k.specific_force,
            angular_rate: k.angular_rate,
            temperature: self.temperature.at(t),
        };
        (t, truth)
    }

    /// The next instant: truth and measurement.
    pub fn step(&mut self) -> SimSample {
        let (t, truth) = self.next_truth();
        self.index += 1;
        let measured = TrueSample {
            specific_force: self.accel.measure(
                truth.specific_force,
                truth.temperature,
                &truth.specific_force,
                self.ts,
            ),
            angular_rate: self.gyro.measure(
                truth.angular_rate,
                truth.temperature,
                &truth.specific_force,
                self.ts,
            ),
            temperature: truth.temperature,
        };
        SimSample { t, truth, measured }
    }

    /// The next instant's truth only; no effect is computed or advanced.
    pub fn step_truth(&mut self) -> SimSample {
        let (t, truth) = self.next_truth();
        self.index += 1;
        SimSample {
            t,
            truth,
            measured: truth,
        }
    }

    /// The accelerometers' last effect contributions.
    pub fn accel_contributions(&self) -> &Contributions {
        &self.accel.contributions
    }

    /// The gyros' last effect contributions.
    pub fn gyro_contributions(&self) -> &Contributions {
        &self.gyro.contributions
    }

    /// A source that serves this scene's truth (no errors): what a chip model
    /// wants when it quantises and saturates by itself.
    pub fn into_truth_source(self) -> TruthSource {
        TruthSource(self)
    }
}

/// Serves the measured samples (the scene's effects applied).
impl SampleSource for Simulator {
    fn next_sample(&mut self) -> TrueSample {
        self.step().measured
    }
}

/// A simulator serving the truth only (see [`Simulator::into_truth_source`]).
#[derive(Clone, Copy, Debug)]
pub struct TruthSource(pub Simulator);

impl SampleSource for TruthSource {
    fn next_sample(&mut self) -> TrueSample {
        self.0.step_truth().truth
    }
}
