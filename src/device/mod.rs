//! What the firmware decides, as plain functions a host test can call: the
//! board traits ([`board`]), which calibration the device starts with
//! ([`startup`]), the data-ready step ([`data_ready`]) over the per-sample
//! pipeline: averaging N corrected samples into one streamed sample
//! ([`Decimator`]), noticing sample steps that were late or lost
//! ([`StepMonitor`]), and turning samples plus the counters of what went wrong
//! into stream frames ([`Framer`]), and the calibration kept in flash
//! ([`CalibrationStore`]). The RTIC application only wires them.

pub mod board;
pub mod commands;
pub mod control;
pub mod counters;
pub mod data_ready;
pub mod decimator;
pub mod dma_ring;
pub mod frame_sink;
pub mod framer;
pub mod load;
pub mod sampler;
pub mod sensor_health;
pub mod slot_queue;
pub mod startup;
pub mod step_monitor;
pub mod storage;
pub mod tx_ring;

pub use commands::{ActiveCalibration, Answer, CommandHandler, DeviceFacts, Handled, NO_SENSOR};
pub use control::Control;
pub use counters::{SamplerTotals, SharedCounters};
pub use data_ready::{on_data_ready, on_fifo_ready, Stepped};
pub use decimator::Decimator;
pub use frame_sink::{ByValue, FrameSink};
pub use framer::{Events, Framer, Outgoing};
pub use load::{Load, LoadCounters, LoadWindow, Task};
pub use sampler::{
    batch_frames_fit, sample_period_us, FifoStepped, Sampler, StepOutcome, FIFO_READ_MAX,
};
pub use sensor_health::{HealthTotals, SensorHealth, StallWatch};
pub use slot_queue::{SlotConsumer, SlotProducer, SlotQueue};
pub use startup::{start_calibration, CalibrationSource, StartUp};
pub use step_monitor::StepMonitor;
pub use storage::{CalibrationStore, StorageError};
