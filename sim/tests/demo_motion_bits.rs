//! The demo motion's source computes its constant terms once (the emulated
//! board's chip model samples it on a core without `f64` hardware): the
//! samples must be the very bits of the motion's formula evaluated whole at
//! each index, since the end-to-end tests recompute the board's stream.

use triad::units::STANDARD_GRAVITY;
use triad_sim::chips::source::{SampleSource, TrueSample};
use triad_sim::motion::demo_motion::{DemoMotion, DemoSource};

/// The module's formula written out, every term evaluated per sample.
fn formula(m: &DemoMotion, n: u64) -> TrueSample {
    let t = n as f64 / m.sample_rate;
    let (sin_roll, cos_roll) = (libm::sin(m.roll), libm::cos(m.roll));
    let (sin_pitch, cos_pitch) = (libm::sin(m.pitch), libm::cos(m.pitch));
    let up = [-sin_pitch, sin_roll * cos_pitch, cos_roll * cos_pitch];
    let vibration =
        m.vibration_amplitude * libm::sin(2.0 * core::f64::consts::PI * m.vibration_hz * t);
    TrueSample {
        specific_force: [
            STANDARD_GRAVITY * up[0] + vibration,
            STANDARD_GRAVITY * up[1],
            STANDARD_GRAVITY * up[2],
        ],
        angular_rate: up.map(|u| m.table_rate * u),
        temperature: m.temperature_start + m.temperature_ramp * t,
    }
}

fn bits(s: &TrueSample) -> [u64; 7] {
    let [a, b, c] = s.specific_force.map(f64::to_bits);
    let [d, e, f] = s.angular_rate.map(f64::to_bits);
    [a, b, c, d, e, f, s.temperature.to_bits()]
}

#[test]
fn the_source_serves_the_formulas_bits() {
    // Both chips' rates on the emulated board (the LSM6DSOX's is not whole).
    for rate in [1000.0, 833.0, 8000.0] {
        let motion = DemoMotion::standard(rate);
        let mut source = DemoSource::new(motion);
        for n in 0..20_000 {
            let served = source.next_sample();
            assert_eq!(
                bits(&served),
                bits(&formula(&motion, n)),
                "sample {n} at {rate} Hz"
            );
            assert_eq!(bits(&motion.at(n)), bits(&served), "at({n}) at {rate} Hz");
        }
    }
}

#[test]
fn far_into_a_day_too() {
    // 24 h at 1 kHz and beyond: the sine's argument past 2²⁰·π/2, where
    // its reduction takes another path.
    let motion = DemoMotion::standard(1000.0);
    for n in [86_400_000u64, 52_000_000, 90_000_000, u64::from(u32::MAX)] {
        assert_eq!(
            bits(&motion.at(n)),
            bits(&formula(&motion, n)),
            "sample {n}"
        );
    }
}
