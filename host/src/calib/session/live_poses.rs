//! Static poses found live, sample by sample, as a board is turned by
//! hand: the stillness test of [`stillness`] (block means against the
//! window's mean, each triad against its floor, and a mean rate no larger
//! than a plausible bias) over a sliding window of the latest samples. A
//! pose is *held* once the window has stayed still for `min_static`
//! seconds of the data's own time stamps (never the wall clock, so a
//! board emulated slower than real time is judged like a real one). A
//! held pose whose gravity direction is within `min_turn_deg` of the
//! previous pose's is the same pose again, not a new one.

use std::collections::VecDeque;

use triad::units::deg_to_rad;
use triad_lab::calib_fit::static_segments;

use triad_lab::calib_fit::stillness::{self, ACCEL_FLOOR, DEFAULT_MAX_BIAS_DPS, GYRO_FLOOR_DPS};

/// The window the stillness test looks at, seconds of data: long enough
/// for 8 blocks of a few samples at 100 Hz, short enough to follow a hand.
pub const WINDOW_S: f64 = 0.5;

/// How often (a fraction of the window) the test is run again.
const CHECKS_PER_WINDOW: f64 = 5.0;

/// One static pose: its time span and means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// First and last sample time, s.
    pub from: f64,
    /// Last sample time, s.
    pub to: f64,
    /// Mean specific force, m/s².
    pub accel: [f64; 3],
    /// Standard error of that mean per axis (white noise: s/√n).
    pub accel_standard_error: [f64; 3],
    /// Mean rate, rad/s.
    pub gyro: [f64; 3],
    /// Samples.
    pub count: usize,
}

impl Pose {
    /// The unit vector of the mean specific force: the body's "up".
    pub fn up(&self) -> [f64; 3] {
        let n = norm(&self.accel);
        self.accel.map(|x| x / n)
    }
}

/// What a new sample made of the stream.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A new static pose has been held for `min_static` seconds.
    Held(Pose),
    /// A pose was held, but it is the previous one again (turned by this
    /// many degrees only).
    SamePose {
        /// The angle between the two gravity directions, degrees.
        turned_deg: f64,
    },
}

/// Running sums of a pose's samples.
#[derive(Clone, Copy, Debug, Default)]
struct Sums {
    from: f64,
    to: f64,
    accel: [f64; 3],
    accel_sq: [f64; 3],
    gyro: [f64; 3],
    count: usize,
}

impl Sums {
    fn add(&mut self, t: f64, accel: &[f64; 3], gyro: &[f64; 3]) {
        if self.count == 0 {
            self.from = t;
        }
        self.to = t;
        for k in 0..3 {
            self.accel[k] += accel[k];
            self.accel_sq[k] += accel[k] * accel[k];
            self.gyro[k] += gyro[k];
        }
        self.count += 1;
    }

    fn pose(&self) -> Pose {
        let n = self.count.max(1) as f64;
        let accel = self.accel.map(|s| s / n);
        let accel_standard_error = core::array::from_fn(|k| {
            let var = (self.accel_sq[k] - n * accel[k] * accel[k]).max(0.0) / (n - 1.0).max(1.0);
            (var / n).sqrt()
        });
        Pose {
            from: self.from,
            to: self.to,
            accel,
            accel_standard_error,
            gyro: self.gyro.map(|s| s / n),
            count: self.count,
        }
    }
}

/// The live detector.
pub struct LivePoses {
    min_static: f64,
    min_turn: f64,
    window: VecDeque<(f64, [f64; 3], [f64; 3])>,
    next_check: f64,
    /// Worst ratio of the stillness test to its limit (≤ 1: still).
    meter: f64,
    still_since: Option<f64>,
    held: bool,
    sums: Sums,
    previous_up: Option<[f64; 3]>,
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The angle between two unit vectors, radians.
pub fn angle(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
        .clamp(-1.0, 1.0)
        .acos()
}

impl LivePoses {
    /// A detector holding poses still for `min_static` s and counting a
    /// pose as new when it turned by at least `min_turn_deg`.
    pub fn new(min_static: f64, min_turn_deg: f64) -> LivePoses {
        LivePoses {
            min_static,
            min_turn: deg_to_rad(min_turn_deg),
            window: VecDeque::new(),
            next_check: f64::NEG_INFINITY,
            meter: f64::INFINITY,
            still_since: None,
            held: false,
            sums: Sums::default(),
            previous_up: None,
        }
    }

    /// The stillness meter: the worst of the tests' ratios to their limits
    /// (≤ 1: still; infinite before a whole window has come).
    pub fn meter(&self) -> f64 {
        self.meter
    }

    /// Seconds the board has been still (0 while it moves).
    pub fn still_for(&self) -> f64 {
        match (self.still_since, self.window.back()) {
            (Some(since), Some(&(t, _, _))) => t - since,
            _ => 0.0,
        }
    }

    /// Seconds of stillness a pose needs.
    pub fn min_static(&self) -> f64 {
        self.min_static
    }

    /// Whether a sample taken after a gap in the stream (`accel`, `gyro`)
    /// shows the board where it was: still before the gap, and the sample
    /// within the stillness floors ([`ACCEL_FLOOR`], [`GYRO_FLOOR_DPS`]) of
    /// the window's means. Then nothing turned during the gap (a turn
    /// moves gravity or shows a rate), and the record can go on across it.
    pub fn continues(&self, accel: &[f64; 3], gyro: &[f64; 3]) -> bool {
        if self.meter > 1.0 || self.window.is_empty() {
            return false;
        }
        let (a, g) = self.window_means();
        let gyro_floor = deg_to_rad(GYRO_FLOOR_DPS);
        (0..3)
            .all(|k| (accel[k] - a[k]).abs() <= ACCEL_FLOOR && (gyro[k] - g[k]).abs() <= gyro_floor)
    }

    /// The window's specific forces and rates.
    fn window_triads(&self) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        self.window.iter().map(|s| (s.1, s.2)).unzip()
    }

    /// The window's mean specific force and rate.
    fn window_means(&self) -> ([f64; 3], [f64; 3]) {
        let (accel, gyro) = self.window_triads();
        (static_segments::mean(&accel), static_segments::mean(&gyro))
    }

    /// The stillness test's ratio on the window.
    fn measure(&self) -> f64 {
        let span = match (self.window.front(), self.window.back()) {
            (Some(a), Some(b)) => b.0 - a.0,
            _ => 0.0,
        };
        if span < 0.8 * WINDOW_S {
            return f64::INFINITY;
        }
        let (accel, gyro) = self.window_triads();
        let ratio =
            |s: Option<stillness::Steadiness>| s.map_or(f64::INFINITY, |s| s.stray / s.limit);
        let mean_rate = static_segments::mean(&gyro);
        let rate_ratio = mean_rate
            .iter()
            .map(|w| w.abs() / deg_to_rad(DEFAULT_MAX_BIAS_DPS))
            .fold(0.0, f64::max);
        ratio(stillness::steadiness(&accel, ACCEL_FLOOR))
            .max(ratio(stillness::steadiness(
                &gyro,
                deg_to_rad(GYRO_FLOOR_DPS),
            )))
            .max(rate_ratio)
    }

    /// Takes the sample at `t` (s, increasing); a held pose when this
    /// sample completes one.
    pub fn push(&mut self, t: f64, accel: [f64; 3], gyro: [f64; 3]) -> Option<Event> {
        self.window.push_back((t, accel, gyro));
        while self
            .window
            .front()
            .is_some_and(|&(first, _, _)| t - first > WINDOW_S)
        {
            self.window.pop_front();
        }
        if t >= self.next_check {
            self.next_check = t + WINDOW_S / CHECKS_PER_WINDOW;
            self.meter = self.measure();
            let still = self.meter <= 1.0;
            match (still, self.still_since) {
                (true, None) => {
                    // The whole window is still: the pose starts with it.
                    self.sums = Sums::default();
                    for (ts, a, g) in &self.window {
                        self.sums.add(*ts, a, g);
                    }
                    self.still_since = self.window.front().map(|s| s.0);
                    return self.hold(t);
                }
                (false, _) => {
                    self.still_since = None;
                    self.held = false;
                    return None;
                }
                (true, Some(_)) => {}
            }
        }
        if self.still_since.is_some() {
            self.sums.add(t, &accel, &gyro);
            return self.hold(t);
        }
        None
    }

    /// The pose held, once it has been still for long enough.
    fn hold(&mut self, t: f64) -> Option<Event> {
        let since = self.still_since?;
        if self.held || t - since < self.min_static {
            return None;
        }
        self.held = true;
        let pose = self.sums.pose();
        let up = pose.up();
        if let Some(previous) = self.previous_up {
            let turned = angle(&previous, &up);
            if turned < self.min_turn {
                return Some(Event::SamePose {
                    turned_deg: turned.to_degrees(),
                });
            }
        }
        self.previous_up = Some(up);
        Some(Event::Held(pose))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 9.80665;

    /// A deterministic ±`amplitude` noise (a fixed pattern, not random).
    fn wiggle(i: usize, amplitude: f64) -> f64 {
        amplitude * [1.0, -0.6, 0.3, -0.9, 0.7, -0.2, 0.5, -0.8][i % 8]
    }

    /// Feeds `seconds` at `rate` Hz of a board at rest with "up" `up`
    /// (then turning about x at `rate_dps` if given), from time `t0`;
    /// returns the events.
    fn feed(
        poses: &mut LivePoses,
        t0: f64,
        seconds: f64,
        rate: f64,
        up: [f64; 3],
        rate_dps: f64,
    ) -> Vec<Event> {
        let n = (seconds * rate) as usize;
        (0..n)
            .filter_map(|i| {
                let t = t0 + i as f64 / rate;
                let a = [0, 1, 2].map(|k| G * up[k] + wiggle(i + k, 0.01));
                let g = [
                    deg_to_rad(rate_dps) + wiggle(i + 3, 0.002),
                    wiggle(i + 5, 0.002),
                    0.0,
                ];
                poses.push(t, a, g)
            })
            .collect()
    }

    #[test]
    fn a_pose_is_held_after_min_static_seconds_of_data_and_not_before() {
        let mut p = LivePoses::new(1.0, 10.0);
        // 1.2 s still: the window fills at 0.4 s (0.8 × 0.5 s), the pose
        // starts with the window (t = 0), and is held at about 1.0 s.
        let events = feed(&mut p, 0.0, 0.95, 100.0, [0.0, 0.0, 1.0], 0.0);
        assert!(events.is_empty(), "{events:?}");
        let events = feed(&mut p, 0.95, 0.3, 100.0, [0.0, 0.0, 1.0], 0.0);
        let [Event::Held(pose)] = events.as_slice() else {
            panic!("{events:?}")
        };
        assert!(pose.to - pose.from >= 1.0 - 1e-9, "{pose:?}");
        // The mean is the level's to within the wiggle's mean (|mean| < 0.01).
        assert!((pose.accel[2] - G).abs() < 0.01, "{pose:?}");
        assert!(p.meter() <= 1.0);
    }

    #[test]
    fn a_turn_ends_the_pose_and_the_same_place_again_is_not_a_new_pose() {
        let mut p = LivePoses::new(1.0, 10.0);
        assert_eq!(feed(&mut p, 0.0, 1.5, 100.0, [0.0, 0.0, 1.0], 0.0).len(), 1);
        // A turn at 30 °/s (above the 10 °/s plausible bias): not still.
        let moving = feed(&mut p, 1.5, 1.0, 100.0, [0.0, 0.0, 1.0], 30.0);
        assert!(moving.is_empty() && p.meter() > 1.0 && p.still_for() == 0.0);
        // Back at rest 5° away: the same pose, not a new one.
        let tilt = 5f64.to_radians();
        let events = feed(&mut p, 2.5, 1.5, 100.0, [0.0, tilt.sin(), tilt.cos()], 0.0);
        let [Event::SamePose { turned_deg }] = events.as_slice() else {
            panic!("{events:?}")
        };
        assert!((turned_deg - 5.0).abs() < 0.2, "{turned_deg}");
        // Turned to +x up: a new pose.
        feed(&mut p, 4.0, 1.0, 100.0, [0.0, 0.0, 1.0], 30.0);
        let events = feed(&mut p, 5.0, 1.5, 100.0, [1.0, 0.0, 0.0], 0.0);
        let [Event::Held(pose)] = events.as_slice() else {
            panic!("{events:?}")
        };
        assert!(angle(&pose.up(), &[1.0, 0.0, 0.0]) < 0.01, "{pose:?}");
    }

    #[test]
    fn after_a_gap_the_board_continues_only_if_it_was_still_and_is_where_it_was() {
        let mut p = LivePoses::new(1.0, 10.0);
        let level = [0.0, 0.0, G];
        assert!(!p.continues(&level, &[0.0; 3]), "no window yet");
        feed(&mut p, 0.0, 1.5, 100.0, [0.0, 0.0, 1.0], 0.0);
        assert!(p.continues(&level, &[0.0; 3]));
        // Tilted by 2° (0.34 m/s² across), or turning at 1 °/s: it moved.
        let tilt = 2f64.to_radians();
        assert!(!p.continues(&[G * tilt.sin(), 0.0, G * tilt.cos()], &[0.0; 3]));
        assert!(!p.continues(&level, &[0.0, 0.0, deg_to_rad(1.0)]));
        // While turning, nothing continues.
        feed(&mut p, 1.5, 1.0, 100.0, [0.0, 0.0, 1.0], 30.0);
        assert!(!p.continues(&level, &[0.0; 3]));
    }

    #[test]
    fn a_tilt_within_the_window_is_not_still() {
        let mut p = LivePoses::new(1.0, 10.0);
        feed(&mut p, 0.0, 1.5, 100.0, [0.0, 0.0, 1.0], 0.0);
        // A 10° step of the gravity direction: the block means jump by
        // 1.7 m/s², far above the accelerometer's 0.1 m/s² floor.
        let tilt = 10f64.to_radians();
        let events = feed(&mut p, 1.5, 0.2, 100.0, [tilt.sin(), 0.0, tilt.cos()], 0.0);
        assert!(events.is_empty());
        assert!(p.meter() > 1.0, "{}", p.meter());
    }
}
