//! What the command handler asks of the sampling task. The handler runs
//! below the data-ready task and never touches its state: it queues a
//! [`Control`], and the data-ready task applies it between two samples
//! ([`super::Sampler::apply`]), so a new calibration takes effect whole.

// A calibration travels inline (no heap on the device): the enum is the
// size of a corrector, moved once per change, never per sample.
#![allow(clippy::large_enum_variant)]

use crate::model::Corrector;
use crate::protocol::Mode;

/// One change to the sampling pipeline.
#[derive(Clone, Debug)]
pub enum Control {
    /// Correct with this calibration from the next sample on.
    Calibrate(Corrector),
    /// Stream corrected or raw samples from the next sample on.
    SetMode(Mode),
    /// Average this many samples per frame from the next sample on.
    SetDecimation(u16),
}
