//! The per-sample decisions of the firmware, as plain functions a host test
//! can call: averaging N corrected samples into one streamed sample
//! ([`Decimator`]), noticing sample steps that were late or lost
//! ([`StepMonitor`]), and turning samples plus the counters of what went wrong
//! into stream frames ([`Framer`]). The RTIC application only wires them.

pub mod decimator;
pub mod framer;
pub mod sampler;
pub mod step_monitor;

pub use decimator::Decimator;
pub use framer::Framer;
pub use sampler::{Sampler, StepOutcome};
pub use step_monitor::StepMonitor;
