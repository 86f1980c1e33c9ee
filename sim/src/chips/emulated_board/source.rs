//! What the emulated board's chip model measures: the documented demo motion
//! (a static sensor with a known tilt plus a slow rotation), or the simulator
//! running a scene embedded at build (`cargo xtask run --scene NAME`, the
//! `sim-scene` feature), with the scene's effects, at the chip's sample rate.
//!
//! Plain code over `triad` only, so the end-to-end test on the host includes
//! this very file and serves the chip model what the firmware served it.

use crate::chips::source::{SampleSource, TrueSample};
use crate::motion::demo_motion::{DemoMotion, DemoSource};
use crate::scenes::scene::SceneError;
use crate::scenes::scene_blob::{self, SceneBlobError};
use crate::scenes::simulator::Simulator;

/// The truth the chip model quantises.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one of them, built once at start-up
pub enum Source {
    /// The demo motion.
    Demo(DemoSource),
    /// A scene's simulated measurements.
    Scene(Simulator),
}

impl SampleSource for Source {
    fn next_sample(&mut self) -> TrueSample {
        match self {
            Source::Demo(d) => d.next_sample(),
            Source::Scene(s) => s.next_sample(),
        }
    }
}

/// Why a scene cannot feed the chip model.
#[derive(Clone, Copy, Debug)]
pub enum SourceError {
    /// The embedded blob is not a readable scene.
    Blob(SceneBlobError),
    /// The scene is not one the simulator runs.
    Scene(SceneError),
}

/// The demo motion sampled at `rate_hz`.
pub fn demo(rate_hz: f64) -> Source {
    Source::Demo(DemoSource::new(DemoMotion::standard(rate_hz)))
}

/// The scene in `blob` (see `crate::scenes::scene_blob`) with its seed, sampled
/// at `rate_hz`: the chip's rate replaces the scene's, since the chip model
/// takes one sample per output-data-rate tick.
pub fn scene(rate_hz: f64, blob: &[u8]) -> Result<Source, SourceError> {
    let (mut scene, seed) = scene_blob::decode(blob).map_err(SourceError::Blob)?;
    scene.rate_hz = rate_hz;
    let simulator = Simulator::new(&scene, seed).map_err(SourceError::Scene)?;
    Ok(Source::Scene(simulator))
}
