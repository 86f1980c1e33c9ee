//! The calibration model: per triad (I+Σ) and b with optional temperature
//! terms ([`calibration`]), validation with one-line reasons ([`validate`]),
//! inversion in f64 ([`matrix`]), the mounting orientation
//! ([`orientation`]), folding into m = K·raw + k ([`fold`]), and the numeric
//! forms of the hot path: f32 and the f64 reference ([`corrector`]), fixed
//! point ([`fixed`]). [`blob`] is the binary form the firmware embeds.
//!
//! Use: `Corrector::new(&calibration, &imu.scale(), orientation)?` once,
//! then `corrector.correct(&raw)` per sample and `corrector.refold(t)` at a
//! low rate when the calibration has temperature terms.

pub mod batch_kernel;
pub mod blob;
pub mod calibration;
pub mod corrector;
pub mod fixed;
pub mod fixed_narrow;
pub mod fold;
#[cfg(triad_fpu)]
mod fused_pass;
pub mod g_sensitivity;
mod limit_codes;
pub mod matrix;
pub mod orientation;
pub mod validate;

pub use batch_kernel::BatchKernel;
pub use blob::BlobError;
pub use calibration::{Calibration, TemperatureTerms, Triad, TriadCalibration};
pub use corrector::{ClipFlags, Corrector, ReferenceSample, Sample};
pub use fixed::{FixedCorrector, FixedSample};
pub use fold::FoldedTriad;
pub use orientation::{Orientation, UnsupportedOrientation};
pub use validate::{CalibrationError, Entry, Readable};
