//! Scenes: motion, environment and temperature, their binary form, and the
//! simulator that turns a scene into samples.

pub mod scene;
#[cfg(feature = "scene-blob")]
pub mod scene_blob;
pub mod simulator;
pub mod temperature_profile;
